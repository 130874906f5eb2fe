//! The photograph and the person's mask: PNG reading with typed errors, the checks a mask must
//! pass, and the plain-background segmentation used when no mask is given.

use std::path::Path;

use atelier_fabric::{ErrorKind, FileError, error::Position};

/// An 8-bit photograph: RGB, or RGBA when the file has transparency (row 0 at the top).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Photo {
    /// Width, pixels.
    pub width: usize,
    /// Height, pixels.
    pub height: usize,
    /// 3 (RGB) or 4 (RGBA).
    pub channels: usize,
    /// Samples, row by row.
    pub data: Vec<u8>,
}

impl Photo {
    /// The RGB of pixel `k` (row-major index).
    pub fn rgb(&self, k: usize) -> [u8; 3] {
        let s = &self.data[k * self.channels..];
        [s[0], s[1], s[2]]
    }
}

/// A person's mask: true where the person is (row 0 at the top).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Mask {
    /// Width, pixels.
    pub width: usize,
    /// Height, pixels.
    pub height: usize,
    /// One flag per pixel, row by row.
    pub data: Vec<bool>,
}

impl Mask {
    /// The mask as coverage (1 inside, 0 outside).
    pub fn coverage(&self) -> Vec<f64> {
        self.data.iter().map(|&b| f64::from(u8::from(b))).collect()
    }

    /// Pixels inside.
    pub fn count(&self) -> usize {
        self.data.iter().filter(|&&b| b).count()
    }

    /// The box of the pixels inside: (first column, first row, last column, last row).
    pub fn bounds(&self) -> Option<[usize; 4]> {
        let mut b: Option<[usize; 4]> = None;
        for (k, _) in self.data.iter().enumerate().filter(|(_, v)| **v) {
            let (x, y) = (k % self.width, k / self.width);
            b = Some(match b {
                None => [x, y, x, y],
                Some([x0, y0, x1, y1]) => [x0.min(x), y0.min(y), x1.max(x), y1.max(y)],
            });
        }
        b
    }
}

fn error(
    file: &Path,
    pixel: Option<(usize, usize)>,
    field: &str,
    kind: ErrorKind,
    message: String,
) -> FileError {
    FileError {
        file: file.to_path_buf(),
        // A pixel's position: line = row + 1, column = column + 1.
        position: pixel.map(|(x, y)| Position {
            line: y + 1,
            column: x + 1,
        }),
        field: field.to_owned(),
        kind,
        message,
        source: None,
    }
}

/// Decoded 8-bit samples: (width, height, channels, samples), palettes and low bit depths
/// expanded. 16-bit files are refused (the composite keeps the photograph's pixels bit for bit,
/// which it could not do through an 8-bit reduction).
fn decode(path: &Path) -> Result<(usize, usize, usize, Vec<u8>), FileError> {
    let bytes = atelier_files::files::read_bytes(path)?;
    let png_err = |e: png::DecodingError| {
        error(
            path,
            None,
            "data",
            ErrorKind::Syntax,
            format!("not a readable PNG: {e}"),
        )
    };
    let mut decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    decoder.set_transformations(png::Transformations::EXPAND);
    let mut reader = decoder.read_info().map_err(png_err)?;
    let size = reader.output_buffer_size().ok_or_else(|| {
        error(
            path,
            None,
            "header",
            ErrorKind::OutOfRange,
            "PNG too large".into(),
        )
    })?;
    let mut buf = vec![0u8; size];
    let info = reader.next_frame(&mut buf).map_err(png_err)?;
    if info.bit_depth != png::BitDepth::Eight {
        return Err(error(
            path,
            None,
            "header.bit_depth",
            ErrorKind::WrongType,
            format!(
                "{:?}-bit samples: only 8-bit PNG pictures are read",
                info.bit_depth
            ),
        ));
    }
    let channels = info.color_type.samples();
    let (w, h) = (info.width as usize, info.height as usize);
    if w == 0 || h == 0 {
        return Err(error(
            path,
            None,
            "header",
            ErrorKind::TooShort,
            "an empty picture".into(),
        ));
    }
    let mut data = Vec::with_capacity(w * h * channels);
    for r in 0..h {
        data.extend_from_slice(&buf[r * info.line_size..r * info.line_size + w * channels]);
    }
    Ok((w, h, channels, data))
}

/// Read a photograph (PNG, 8 bits per sample; grey pictures become RGB).
pub fn load_photo(path: &Path) -> Result<Photo, FileError> {
    let (width, height, channels, data) = decode(path)?;
    let (channels, data) = match channels {
        1 => (3, data.iter().flat_map(|&g| [g, g, g]).collect()),
        2 => (
            4,
            data.chunks_exact(2)
                .flat_map(|c| [c[0], c[0], c[0], c[1]])
                .collect(),
        ),
        n => (n, data),
    };
    Ok(Photo {
        width,
        height,
        channels,
        data,
    })
}

/// Read a mask (PNG): a pixel belongs to the person when its grey level (the mean of its colour
/// samples) is at least half of white and, if the file has transparency, it is at least half
/// opaque. Refused with the reason: a mask of another size than the photograph (`size`), a
/// picture that is not black and white (more than 2 % of its pixels between 10 % and 90 %
/// grey; the first one named), a mask with nobody in it, or one the person fills.
pub fn load_mask(path: &Path, size: (usize, usize)) -> Result<Mask, FileError> {
    let (width, height, channels, data) = decode(path)?;
    if (width, height) != size {
        return Err(error(
            path,
            None,
            "header",
            ErrorKind::Inconsistent,
            format!(
                "the mask is {width} × {height} pixels, the photograph {} × {}: they must be the same picture's",
                size.0, size.1
            ),
        ));
    }
    let colour = if channels == 2 || channels == 4 {
        channels - 1
    } else {
        channels
    };
    let mut grey_pixels = 0usize;
    let mut first_grey = None;
    let mut mask = Vec::with_capacity(width * height);
    for (k, px) in data.chunks_exact(channels).enumerate() {
        let g = px[..colour].iter().map(|&v| f64::from(v)).sum::<f64>() / (255.0 * colour as f64);
        let a = if colour < channels {
            f64::from(px[colour]) / 255.0
        } else {
            1.0
        };
        let v = g * a;
        if v > 0.1 && v < 0.9 {
            grey_pixels += 1;
            first_grey.get_or_insert((k % width, k / width, v));
        }
        mask.push(g >= 0.5 && a >= 0.5);
    }
    if grey_pixels * 50 > width * height {
        let (x, y, v) = first_grey.unwrap_or_default();
        return Err(error(
            path,
            Some((x, y)),
            "data",
            ErrorKind::OutOfRange,
            format!(
                "not a mask: {grey_pixels} of {} pixels are neither black nor white (the first, at column {}, row {}, is {:.0} % grey); give a black-and-white picture with the person white",
                width * height,
                x + 1,
                y + 1,
                v * 100.0
            ),
        ));
    }
    let mask = Mask {
        width,
        height,
        data: mask,
    };
    check_mask(&mask).map_err(|m| error(path, None, "data", ErrorKind::OutOfRange, m))?;
    Ok(mask)
}

/// A mask a person could be fitted to: someone in it, and background round them.
pub fn check_mask(mask: &Mask) -> Result<(), String> {
    let n = mask.count();
    let total = mask.width * mask.height;
    if n < 64 {
        return Err(format!(
            "the mask holds {n} person pixels: nobody to fit (the person must be white, at least 64 pixels)"
        ));
    }
    if n * 10 > total * 9 {
        return Err(format!(
            "the person fills {:.0} % of the mask: no background to fit a silhouette against",
            100.0 * n as f64 / total as f64
        ));
    }
    Ok(())
}

/// The documented segmentation of a photograph taken against a plain background: the
/// background's colour is the median, per channel, of the picture's border pixels; a pixel is
/// the person's when some channel differs from it by more than `threshold` (0–255); of those,
/// only the largest 4-connected region is kept, with the holes in it (regions of background
/// that do not reach the border) filled.
pub fn segment_plain_background(photo: &Photo, threshold: u8) -> Mask {
    let (w, h) = (photo.width, photo.height);
    let mut border: [Vec<u8>; 3] = Default::default();
    for y in 0..h {
        for x in 0..w {
            if x == 0 || y == 0 || x + 1 == w || y + 1 == h {
                let c = photo.rgb(y * w + x);
                for k in 0..3 {
                    border[k].push(c[k]);
                }
            }
        }
    }
    let background: Vec<u8> = border
        .iter_mut()
        .map(|v| {
            v.sort_unstable();
            v[v.len() / 2]
        })
        .collect();
    let fore: Vec<bool> = (0..w * h)
        .map(|k| {
            let c = photo.rgb(k);
            (0..3).any(|i| c[i].abs_diff(background[i]) > threshold)
        })
        .collect();
    // The largest region of the person's pixels.
    let label = regions(&fore, w, h, true);
    let mut sizes = vec![0usize; label.iter().flatten().max().map_or(0, |m| m + 1)];
    for l in label.iter().flatten() {
        sizes[*l] += 1;
    }
    let largest = sizes
        .iter()
        .enumerate()
        .max_by_key(|(_, n)| **n)
        .map(|(i, _)| i);
    let person: Vec<bool> = label.iter().map(|l| l.is_some() && *l == largest).collect();
    // Fill holes: background regions that do not touch the border.
    let back = regions(&person, w, h, false);
    let mut reaches = vec![false; back.iter().flatten().max().map_or(0, |m| m + 1)];
    for y in 0..h {
        for x in 0..w {
            if (x == 0 || y == 0 || x + 1 == w || y + 1 == h)
                && let Some(l) = back[y * w + x]
            {
                reaches[l] = true;
            }
        }
    }
    let data = (0..w * h)
        .map(|k| person[k] || back[k].is_some_and(|l| !reaches[l]))
        .collect();
    Mask {
        width: w,
        height: h,
        data,
    }
}

/// 4-connected regions of the pixels equal to `value`: a label per pixel (`None` elsewhere).
fn regions(image: &[bool], w: usize, h: usize, value: bool) -> Vec<Option<usize>> {
    let mut label = vec![None; w * h];
    let mut next = 0;
    let mut stack = Vec::new();
    for start in 0..w * h {
        if image[start] != value || label[start].is_some() {
            continue;
        }
        label[start] = Some(next);
        stack.push(start);
        while let Some(k) = stack.pop() {
            let (x, y) = (k % w, k / w);
            let mut visit = |j: usize| {
                if image[j] == value && label[j].is_none() {
                    label[j] = Some(next);
                    stack.push(j);
                }
            };
            if x > 0 {
                visit(k - 1);
            }
            if x + 1 < w {
                visit(k + 1);
            }
            if y > 0 {
                visit(k - w);
            }
            if y + 1 < h {
                visit(k + w);
            }
        }
        next += 1;
    }
    label
}

/// Encode an 8-bit picture (`channels` 3 or 4) as PNG bytes.
pub fn encode(
    width: usize,
    height: usize,
    channels: usize,
    data: &[u8],
) -> std::io::Result<Vec<u8>> {
    let mut bytes = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut bytes, width as u32, height as u32);
        enc.set_color(if channels == 4 {
            png::ColorType::Rgba
        } else {
            png::ColorType::Rgb
        });
        enc.set_depth(png::BitDepth::Eight);
        let mut writer = enc.write_header().map_err(std::io::Error::other)?;
        writer
            .write_image_data(data)
            .map_err(std::io::Error::other)?;
    }
    Ok(bytes)
}
