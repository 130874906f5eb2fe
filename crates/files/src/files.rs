//! Reading RON files with positioned, typed errors, and writing outputs atomically.
//!
//! Every atelier data file (fabrics here; patterns, bodies, motions and scenarios later) is RON with
//! string enum names and unknown fields rejected. [`parse_ron`] reports a failure as a
//! [`FileError`] naming the file, the line and column where the parser stopped, the dotted field
//! path (tracked with `serde_path_to_error`) and the [`ErrorKind`]. Values are validated while they
//! are parsed (see [`crate::check`]), so a NaN or a non-monotone curve is reported at its own
//! position, not after the fact.
//!
//! RON extensions enabled by default: `unwrap_variant_newtypes` (write `Kes(lt: 0.7, …)` instead of
//! `Kes((lt: 0.7, …))`) and `implicit_some` (write `bias45: Kes(…)` instead of `Some(Kes(…))`).

use std::io::Write;
use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;

use crate::error::{ErrorKind, FileError, InvalidValue, Position, join_path};

/// A check's error with the position of its field in the text: each segment of the field's path
/// (`kind.settings.sewing.threshold`, `expectations[1].metric`) found as `name:` after the
/// previous one, an index `[k]` as the `k`-th element of the list that follows; no position
/// when a segment is not found (a value left to its default).
pub fn located(file: &Path, text: &str, err: InvalidValue) -> FileError {
    let mut at = Some(0);
    for segment in err.field.split('.').filter(|s| !s.is_empty()) {
        let (name, index) = match segment.split_once('[') {
            Some((n, i)) => (n, i.trim_end_matches(']').parse::<usize>().ok()),
            None => (segment, None),
        };
        at = at.and_then(|from| find_key(text, from, name));
        if let Some(k) = index {
            at = at.and_then(|from| list_element(text, from, k));
        }
    }
    let mut e = FileError::from_invalid(file, err);
    if let Some(at) = at.filter(|_| !e.field.is_empty()) {
        let before = &text[..at];
        let line = before.matches('\n').count() + 1;
        let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        e.position = Some(Position { line, column });
    }
    e
}

/// The byte offset of the `k`-th element of the first list (`[…]`) at or after `from`.
fn list_element(text: &str, from: usize, k: usize) -> Option<usize> {
    let open = from + text.get(from..)?.find('[')?;
    let (mut depth, mut seen, mut expecting) = (0usize, 0usize, true);
    for (offset, c) in text[open + 1..].char_indices() {
        let at = open + 1 + offset;
        match c {
            '(' | '[' | '{' => {
                if depth == 0 && expecting {
                    if seen == k {
                        return Some(at);
                    }
                    seen += 1;
                    expecting = false;
                }
                depth += 1;
            }
            ')' | ']' | '}' if depth == 0 => return None,
            ')' | ']' | '}' => depth -= 1,
            ',' if depth == 0 => expecting = true,
            c if c.is_whitespace() => {}
            _ if depth == 0 && expecting => {
                if seen == k {
                    return Some(at);
                }
                seen += 1;
                expecting = false;
            }
            _ => {}
        }
    }
    None
}

/// The byte offset of the next `name` at or after `from` used as a key (`name:` or `name(`,
/// not part of a longer word).
fn find_key(text: &str, from: usize, name: &str) -> Option<usize> {
    let mut start = from;
    while let Some(k) = text.get(start..)?.find(name) {
        let at = start + k;
        let before = text[..at].chars().next_back();
        let after = text[at + name.len()..].trim_start().chars().next();
        let word = |c: char| c.is_alphanumeric() || c == '_';
        if before.is_none_or(|c| !word(c)) && matches!(after, Some(':' | '(')) {
            return Some(at);
        }
        start = at + name.len();
    }
    None
}

/// Read a text file, an I/O failure as a [`FileError`] naming it.
pub fn read_text(path: &Path) -> Result<String, FileError> {
    std::fs::read_to_string(path).map_err(|e| io_error(path, e))
}

/// Read a file's bytes, an I/O failure as a [`FileError`] naming it.
pub fn read_bytes(path: &Path) -> Result<Vec<u8>, FileError> {
    std::fs::read(path).map_err(|e| io_error(path, e))
}

fn io_error(path: &Path, e: std::io::Error) -> FileError {
    FileError {
        file: path.to_path_buf(),
        position: None,
        field: String::new(),
        kind: ErrorKind::Io,
        message: e.to_string(),
        source: Some(e),
    }
}

/// Read and parse a RON file.
pub fn load_ron<T: DeserializeOwned>(path: &Path) -> Result<T, FileError> {
    let text = read_text(path)?;
    parse_ron(&text, path)
}

/// Parse RON text; `file` names the source in errors.
pub fn parse_ron<T: DeserializeOwned>(text: &str, file: &Path) -> Result<T, FileError> {
    let options = ron::Options::default().with_default_extension(
        ron::extensions::Extensions::UNWRAP_VARIANT_NEWTYPES
            | ron::extensions::Extensions::IMPLICIT_SOME,
    );
    let mut de = ron::Deserializer::from_str_with_options(text, &options)
        .map_err(|e| spanned(file, "", e))?;
    let mut track = serde_path_to_error::Track::new();
    let result = T::deserialize(serde_path_to_error::Deserializer::new(&mut de, &mut track));
    match result {
        Ok(value) => {
            de.end().map_err(|e| spanned(file, "", de.span_error(e)))?;
            Ok(value)
        }
        Err(e) => Err(spanned(file, &field_path(&track.path()), de.span_error(e))),
    }
}

/// The dotted field path of a serde path: struct fields and map keys joined by dots, sequence
/// indices in brackets; enum variant names and unknown segments left out (a path names fields).
fn field_path(path: &serde_path_to_error::Path) -> String {
    use serde_path_to_error::Segment;
    let mut out = String::new();
    for seg in path.iter() {
        match seg {
            Segment::Seq { index } => out.push_str(&format!("[{index}]")),
            Segment::Map { key } => out = join_path(&out, key),
            Segment::Enum { .. } | Segment::Unknown => {}
        }
    }
    out
}

fn spanned(file: &Path, path: &str, err: ron::error::SpannedError) -> FileError {
    use ron::Error as E;
    let position = Some(Position {
        line: err.span.start.line,
        column: err.span.start.col,
    });
    let mut field = path.to_owned();
    let (kind, message) = match &err.code {
        E::Message(m) => match InvalidValue::decode(m) {
            Some(inv) => {
                field = join_path(path, &inv.field);
                (inv.kind, inv.message)
            }
            None => (ErrorKind::WrongType, m.clone()),
        },
        // The tracked path already ends at the unknown key.
        E::NoSuchStructField { .. } => (ErrorKind::UnknownField, err.code.to_string()),
        E::MissingStructField { field: missing, .. } => {
            field = join_path(path, missing);
            (ErrorKind::MissingField, err.code.to_string())
        }
        E::DuplicateStructField { .. } => (ErrorKind::DuplicateField, err.code.to_string()),
        E::NoSuchEnumVariant { .. } => (ErrorKind::UnknownVariant, err.code.to_string()),
        E::InvalidValueForType { .. }
        | E::ExpectedDifferentLength { .. }
        | E::ExpectedDifferentStructName { .. }
        | E::ExpectedFloat
        | E::ExpectedInteger
        | E::ExpectedBoolean
        | E::ExpectedString
        | E::ExpectedChar
        | E::ExpectedArray
        | E::ExpectedMap
        | E::ExpectedOption
        | E::ExpectedUnit
        | E::ExpectedStructLike
        | E::ExpectedNamedStructLike(_)
        | E::IntegerOutOfBounds => (ErrorKind::WrongType, err.code.to_string()),
        other => (ErrorKind::Syntax, other.to_string()),
    };
    FileError {
        file: file.to_path_buf(),
        position,
        field,
        kind,
        message,
        source: None,
    }
}

/// Write `bytes` to `path` atomically: write a temporary file beside it, flush, then rename over
/// the target, so a failed run never leaves a half-written file in place of an earlier result.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let tmp = temporary_sibling(path);
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// A temporary name beside `path` that keeps its extension (`figure.png` → `.figure.tmp-<pid>.png`),
/// for writers that infer the format from the extension. Rename it over `path` when done.
pub fn temporary_sibling(path: &Path) -> PathBuf {
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("out");
    let name = match path.extension().and_then(|e| e.to_str()) {
        Some(ext) => format!(".{stem}.tmp-{}.{ext}", std::process::id()),
        None => format!(".{stem}.tmp-{}", std::process::id()),
    };
    path.with_file_name(name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atomic_write_replaces_and_leaves_no_temporary() {
        let dir = std::env::temp_dir().join(format!("atelier-files-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let target = dir.join("out.txt");
        write_atomic(&target, b"first").expect("write");
        write_atomic(&target, b"second").expect("write");
        assert_eq!(std::fs::read(&target).expect("read"), b"second");
        let leftovers: Vec<_> = std::fs::read_dir(&dir)
            .expect("list")
            .filter_map(Result::ok)
            .filter(|e| e.file_name().to_string_lossy().contains(".tmp-"))
            .collect();
        assert!(leftovers.is_empty());
        // A write into a missing directory fails and leaves nothing behind.
        assert!(write_atomic(&dir.join("missing/out.txt"), b"x").is_err());
        std::fs::remove_dir_all(&dir).expect("cleanup");
    }

    #[test]
    fn temporary_name_keeps_the_extension() {
        let t = temporary_sibling(Path::new("/a/b/fig.png"));
        assert_eq!(t.extension().and_then(|e| e.to_str()), Some("png"));
        assert_eq!(t.parent(), Some(Path::new("/a/b")));
    }
}
