//! Grey-level images of 8 or 16 bits per sample: binary PGM (`P5`) and grayscale PNG, read with
//! typed errors and written atomically.
//!
//! Decoding never panics: a bad header, a maxval out of range, a wrong colour type or bit depth,
//! or truncated data become a [`FileError`]. For PGM header errors the position is the line and
//! column in the (text) header; for data errors the position is absent and the message names the
//! byte offset.

use std::path::Path;

use atelier_files::files::write_atomic;
use atelier_files::{ErrorKind, FileError, Position};

/// A grey-level image, row by row from the top, values as read (0..=maxval).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GrayImage {
    /// Columns.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// Largest possible value (255 for 8-bit, up to 65535 for 16-bit).
    pub maxval: u16,
    /// `width · height` samples, row `r` at `r·width ..`.
    pub data: Vec<u16>,
}

impl GrayImage {
    /// The sample at column `c`, row `r`.
    pub fn get(&self, c: usize, r: usize) -> u16 {
        self.data[r * self.width + c]
    }
}

fn err(
    file: &Path,
    position: Option<Position>,
    field: &str,
    kind: ErrorKind,
    message: String,
) -> FileError {
    FileError {
        file: file.to_path_buf(),
        position,
        field: field.to_owned(),
        kind,
        message,
        source: None,
    }
}

fn io_err(file: &Path, e: std::io::Error) -> FileError {
    FileError {
        file: file.to_path_buf(),
        position: None,
        field: String::new(),
        kind: ErrorKind::Io,
        message: e.to_string(),
        source: Some(e),
    }
}

/// Read a PGM or PNG image, chosen by content (the magic bytes), not by extension.
pub fn read_image(path: &Path) -> Result<GrayImage, FileError> {
    let bytes = std::fs::read(path).map_err(|e| io_err(path, e))?;
    decode_image(&bytes, path)
}

/// Decode PGM (`P5`) or PNG bytes; `file` names the source in errors.
pub fn decode_image(bytes: &[u8], file: &Path) -> Result<GrayImage, FileError> {
    if bytes.starts_with(b"\x89PNG") {
        decode_png(bytes, file)
    } else {
        decode_pgm(bytes, file)
    }
}

/// The line and column (1-based) of byte `offset` in a text header.
fn position_of(bytes: &[u8], offset: usize) -> Position {
    let before = &bytes[..offset.min(bytes.len())];
    let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
    let column = offset
        - before
            .iter()
            .rposition(|&b| b == b'\n')
            .map_or(0, |p| p + 1)
        + 1;
    Position { line, column }
}

/// Decode a binary PGM (`P5`): 8-bit samples when maxval < 256, else 16-bit big-endian.
pub fn decode_pgm(bytes: &[u8], file: &Path) -> Result<GrayImage, FileError> {
    if !bytes.starts_with(b"P5") {
        return Err(err(
            file,
            Some(Position { line: 1, column: 1 }),
            "magic",
            ErrorKind::Syntax,
            "not a binary PGM (expected `P5`) nor a PNG".into(),
        ));
    }
    let mut pos = 2;
    let mut fields = [0u64; 3];
    for (k, name) in ["width", "height", "maxval"].iter().enumerate() {
        // Whitespace and comments.
        loop {
            match bytes.get(pos) {
                Some(b) if b.is_ascii_whitespace() => pos += 1,
                Some(b'#') => {
                    while pos < bytes.len() && bytes[pos] != b'\n' {
                        pos += 1;
                    }
                }
                _ => break,
            }
        }
        let start = pos;
        while pos < bytes.len() && bytes[pos].is_ascii_digit() {
            pos += 1;
        }
        let text = std::str::from_utf8(&bytes[start..pos]).unwrap_or("");
        let value = text.parse::<u64>().ok().filter(|&v| v <= u32::MAX as u64);
        let Some(value) = value else {
            return Err(err(
                file,
                Some(position_of(bytes, start)),
                &format!("header.{name}"),
                if start >= bytes.len() {
                    ErrorKind::TooShort
                } else {
                    ErrorKind::Syntax
                },
                format!("expected the {name} as a decimal number"),
            ));
        };
        fields[k] = value;
        if k < 2 && value == 0 {
            return Err(err(
                file,
                Some(position_of(bytes, start)),
                &format!("header.{name}"),
                ErrorKind::OutOfRange,
                format!("the {name} must be positive"),
            ));
        }
        if k == 2 && !(1..=65535).contains(&value) {
            return Err(err(
                file,
                Some(position_of(bytes, start)),
                "header.maxval",
                ErrorKind::OutOfRange,
                format!("maxval {value} must lie in 1..=65535"),
            ));
        }
    }
    // Exactly one whitespace byte separates the header from the data.
    match bytes.get(pos) {
        Some(b) if b.is_ascii_whitespace() => pos += 1,
        _ => {
            return Err(err(
                file,
                Some(position_of(bytes, pos)),
                "header",
                ErrorKind::Syntax,
                "expected one whitespace byte after maxval".into(),
            ));
        }
    }
    let (width, height, maxval) = (fields[0] as usize, fields[1] as usize, fields[2] as u16);
    let per = if maxval < 256 { 1 } else { 2 };
    let need = width
        .checked_mul(height)
        .and_then(|n| n.checked_mul(per))
        .filter(|&n| n <= 1 << 32)
        .ok_or_else(|| {
            err(
                file,
                None,
                "header",
                ErrorKind::OutOfRange,
                format!("image of {width} × {height} is too large"),
            )
        })?;
    let have = bytes.len() - pos;
    if have < need {
        return Err(err(
            file,
            None,
            "data",
            ErrorKind::TooShort,
            format!(
                "truncated at byte offset {}: {width} × {height} samples of {per} byte(s) need {need} bytes from offset {pos}, found {have}",
                bytes.len()
            ),
        ));
    }
    let raw = &bytes[pos..pos + need];
    let data: Vec<u16> = if per == 1 {
        raw.iter().map(|&b| u16::from(b)).collect()
    } else {
        raw.chunks_exact(2)
            .map(|c| u16::from_be_bytes([c[0], c[1]]))
            .collect()
    };
    if let Some(k) = data.iter().position(|&v| v > maxval) {
        return Err(err(
            file,
            None,
            "data",
            ErrorKind::OutOfRange,
            format!(
                "sample {} at byte offset {} exceeds maxval {maxval}",
                data[k],
                pos + k * per
            ),
        ));
    }
    Ok(GrayImage {
        width,
        height,
        maxval,
        data,
    })
}

/// Decode a grayscale PNG of 8 or 16 bits.
pub fn decode_png(bytes: &[u8], file: &Path) -> Result<GrayImage, FileError> {
    let png_err = |e: png::DecodingError| {
        let kind = match &e {
            png::DecodingError::IoError(_) => ErrorKind::TooShort,
            png::DecodingError::LimitsExceeded => ErrorKind::OutOfRange,
            _ => ErrorKind::Syntax,
        };
        err(file, None, "data", kind, format!("PNG: {e}"))
    };
    let mut decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    decoder.set_transformations(png::Transformations::IDENTITY);
    let mut reader = decoder.read_info().map_err(png_err)?;
    let (color, depth) = {
        let info = reader.info();
        (info.color_type, info.bit_depth)
    };
    if color != png::ColorType::Grayscale {
        return Err(err(
            file,
            None,
            "header.color_type",
            ErrorKind::WrongType,
            format!("{color:?} PNG: a range image must be grayscale"),
        ));
    }
    let (per, maxval) = match depth {
        png::BitDepth::Eight => (1, 255),
        png::BitDepth::Sixteen => (2, 65535),
        other => {
            return Err(err(
                file,
                None,
                "header.bit_depth",
                ErrorKind::WrongType,
                format!("{other:?}-bit PNG: a range image must have 8 or 16 bits per sample"),
            ));
        }
    };
    let size = reader.output_buffer_size().ok_or_else(|| {
        err(
            file,
            None,
            "header",
            ErrorKind::OutOfRange,
            "PNG too large".into(),
        )
    })?;
    let mut buf = vec![0u8; size];
    let out = reader.next_frame(&mut buf).map_err(png_err)?;
    let (width, height) = (out.width as usize, out.height as usize);
    let mut data = Vec::with_capacity(width * height);
    for r in 0..height {
        let row = &buf[r * out.line_size..r * out.line_size + width * per];
        if per == 1 {
            data.extend(row.iter().map(|&b| u16::from(b)));
        } else {
            data.extend(
                row.chunks_exact(2)
                    .map(|c| u16::from_be_bytes([c[0], c[1]])),
            );
        }
    }
    Ok(GrayImage {
        width,
        height,
        maxval,
        data,
    })
}

/// Encode as a 16-bit binary PGM (maxval 65535).
pub fn encode_pgm16(image: &GrayImage) -> Vec<u8> {
    let mut out = format!("P5\n{} {}\n65535\n", image.width, image.height).into_bytes();
    out.reserve(image.data.len() * 2);
    for v in &image.data {
        out.extend_from_slice(&v.to_be_bytes());
    }
    out
}

/// Encode as a 16-bit grayscale PNG.
pub fn encode_png16(image: &GrayImage) -> Result<Vec<u8>, png::EncodingError> {
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, image.width as u32, image.height as u32);
        enc.set_color(png::ColorType::Grayscale);
        enc.set_depth(png::BitDepth::Sixteen);
        let mut writer = enc.write_header()?;
        let bytes: Vec<u8> = image.data.iter().flat_map(|v| v.to_be_bytes()).collect();
        writer.write_image_data(&bytes)?;
        writer.finish()?;
    }
    Ok(out)
}

/// Write an image atomically: PNG when the path ends in `.png`, else 16-bit PGM.
pub fn write_image(path: &Path, image: &GrayImage) -> std::io::Result<()> {
    let is_png = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    let bytes = if is_png {
        encode_png16(image).map_err(std::io::Error::other)?
    } else {
        encode_pgm16(image)
    };
    write_atomic(path, &bytes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(200))]
        /// Arbitrary bytes, and arbitrary bytes after a PGM or PNG signature, never panic.
        #[test]
        fn garbage_never_panics(
            body in prop::collection::vec(any::<u8>(), 0..300),
            prefix in 0usize..4,
        ) {
            let head: &[u8] = match prefix {
                0 => b"",
                1 => b"P5 ",
                2 => b"P5\n3 2\n65535\n",
                _ => b"\x89PNG\r\n\x1a\n",
            };
            let bytes: Vec<u8> = head.iter().chain(&body).copied().collect();
            let _ = decode_image(&bytes, Path::new("fuzz"));
        }
    }

    fn sample() -> GrayImage {
        GrayImage {
            width: 3,
            height: 2,
            maxval: 65535,
            data: vec![0, 1, 300, 65535, 4000, 7],
        }
    }

    #[test]
    fn pgm_and_png_round_trip() {
        let f = Path::new("mem");
        assert_eq!(decode_image(&encode_pgm16(&sample()), f).unwrap(), sample());
        assert_eq!(
            decode_image(&encode_png16(&sample()).unwrap(), f).unwrap(),
            sample()
        );
    }

    #[test]
    fn pgm_with_comments_and_8_bits() {
        let mut bytes = b"P5 # a comment\n2 # w\n1\n255\n".to_vec();
        bytes.extend_from_slice(&[9, 200]);
        let im = decode_pgm(&bytes, Path::new("c.pgm")).unwrap();
        assert_eq!(
            (im.width, im.height, im.maxval, im.data),
            (2, 1, 255, vec![9, 200])
        );
    }

    #[test]
    fn truncated_pgm_is_an_error_with_the_byte_offset() {
        let mut bytes = encode_pgm16(&sample());
        bytes.truncate(bytes.len() - 3);
        let e = decode_pgm(&bytes, Path::new("t.pgm")).unwrap_err();
        assert_eq!(e.kind, ErrorKind::TooShort);
        assert_eq!(e.field, "data");
        assert!(e.message.contains("byte offset"), "{e}");
    }

    #[test]
    fn bad_headers_are_positioned() {
        let e = decode_pgm(b"P2\n1 1\n255\n", Path::new("a.pgm")).unwrap_err();
        assert_eq!((e.kind, e.field.as_str()), (ErrorKind::Syntax, "magic"));
        let e = decode_pgm(b"P5\n4 x\n255\n", Path::new("a.pgm")).unwrap_err();
        assert_eq!(e.field, "header.height");
        assert_eq!(e.position, Some(Position { line: 2, column: 3 }));
        let e = decode_pgm(b"P5\n4 1\n70000\n", Path::new("a.pgm")).unwrap_err();
        assert_eq!(
            (e.kind, e.field.as_str()),
            (ErrorKind::OutOfRange, "header.maxval")
        );
        let e = decode_pgm(b"P5\n", Path::new("a.pgm")).unwrap_err();
        assert_eq!(e.kind, ErrorKind::TooShort);
        let e = decode_pgm(b"P5\n1 1\n9\n\x0a", Path::new("a.pgm")).unwrap_err();
        assert_eq!((e.kind, e.field.as_str()), (ErrorKind::OutOfRange, "data"));
    }

    #[test]
    fn broken_and_wrong_depth_png_are_errors() {
        let good = encode_png16(&sample()).unwrap();
        let e = decode_image(&good[..good.len() / 2], Path::new("b.png")).unwrap_err();
        assert_eq!(e.field, "data");
        // An RGB PNG.
        let mut out = Vec::new();
        {
            let mut enc = png::Encoder::new(&mut out, 1, 1);
            enc.set_color(png::ColorType::Rgb);
            enc.set_depth(png::BitDepth::Eight);
            let mut w = enc.write_header().unwrap();
            w.write_image_data(&[1, 2, 3]).unwrap();
            w.finish().unwrap();
        }
        let e = decode_image(&out, Path::new("rgb.png")).unwrap_err();
        assert_eq!(
            (e.kind, e.field.as_str()),
            (ErrorKind::WrongType, "header.color_type")
        );
    }
}
