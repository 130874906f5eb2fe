//! Typed errors: what is wrong ([`ErrorKind`]), with a value ([`InvalidValue`]) or in a file
//! ([`FileError`]: file, line, column, field).

use std::fmt;
use std::path::PathBuf;

/// The kind of a validation or parse failure. Tests match on it; messages add the detail.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum ErrorKind {
    /// The file could not be read.
    Io,
    /// Malformed RON (unbalanced brackets, bad literal, trailing characters…).
    Syntax,
    /// A field name the format does not know (typos are not ignored).
    UnknownField,
    /// A required field is absent (for example a fabric without weft data).
    MissingField,
    /// A field given twice.
    DuplicateField,
    /// An enum variant name the format does not know.
    UnknownVariant,
    /// A value of the wrong type (a string where a number belongs, …).
    WrongType,
    /// NaN or infinity.
    NotFinite,
    /// A negative value where only zero or positive values make sense.
    Negative,
    /// A value outside its valid range.
    OutOfRange,
    /// A curve whose force or strain does not increase.
    NonMonotone,
    /// A curve or data set with too few points.
    TooShort,
    /// Values that contradict each other (WT ≠ 2.5·LT·EMT, crossing branches…).
    Inconsistent,
}

impl ErrorKind {
    const ALL: [ErrorKind; 13] = [
        ErrorKind::Io,
        ErrorKind::Syntax,
        ErrorKind::UnknownField,
        ErrorKind::MissingField,
        ErrorKind::DuplicateField,
        ErrorKind::UnknownVariant,
        ErrorKind::WrongType,
        ErrorKind::NotFinite,
        ErrorKind::Negative,
        ErrorKind::OutOfRange,
        ErrorKind::NonMonotone,
        ErrorKind::TooShort,
        ErrorKind::Inconsistent,
    ];

    /// Short lower-case name used in messages.
    pub fn name(self) -> &'static str {
        match self {
            ErrorKind::Io => "cannot read",
            ErrorKind::Syntax => "syntax error",
            ErrorKind::UnknownField => "unknown field",
            ErrorKind::MissingField => "missing field",
            ErrorKind::DuplicateField => "duplicate field",
            ErrorKind::UnknownVariant => "unknown variant",
            ErrorKind::WrongType => "wrong type",
            ErrorKind::NotFinite => "not finite",
            ErrorKind::Negative => "negative",
            ErrorKind::OutOfRange => "out of range",
            ErrorKind::NonMonotone => "not monotone",
            ErrorKind::TooShort => "too short",
            ErrorKind::Inconsistent => "inconsistent",
        }
    }

    fn from_name(name: &str) -> Option<ErrorKind> {
        ErrorKind::ALL.into_iter().find(|k| k.name() == name)
    }
}

impl fmt::Display for ErrorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A value that failed validation, without a file position: the field path (relative to the
/// value validated, may be empty), what is wrong and the offending value in words.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("[{kind}] {field}: {message}")]
pub struct InvalidValue {
    /// What is wrong.
    pub kind: ErrorKind,
    /// Field path below the validated value (`loading[3]`, `lt`, …); empty for the value itself.
    pub field: String,
    /// Detail naming the value.
    pub message: String,
}

impl InvalidValue {
    /// A new validation error.
    pub fn new(kind: ErrorKind, field: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            kind,
            field: field.into(),
            message: message.into(),
        }
    }

    /// The same error seen from a containing value: `prefix` is prepended to the field path.
    #[must_use]
    pub fn within(mut self, prefix: &str) -> Self {
        self.field = join_path(prefix, &self.field);
        self
    }

    /// Decode an error that travelled through serde as a custom message (the `Display` form
    /// above). Returns `None` for messages that did not come from an `InvalidValue`.
    pub(crate) fn decode(message: &str) -> Option<Self> {
        let rest = message.strip_prefix('[')?;
        let (kind, rest) = rest.split_once("] ")?;
        let kind = ErrorKind::from_name(kind)?;
        let (field, message) = rest.split_once(": ")?;
        Some(Self::new(kind, field, message))
    }
}

/// Join two field paths with a dot, skipping empty parts.
pub(crate) fn join_path(a: &str, b: &str) -> String {
    match (a.is_empty(), b.is_empty()) {
        (true, _) => b.to_owned(),
        (_, true) => a.to_owned(),
        _ if b.starts_with('[') => format!("{a}{b}"),
        _ => format!("{a}.{b}"),
    }
}

/// A line and column in a text file (both 1-based).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Position {
    /// Line, from 1.
    pub line: usize,
    /// Column, from 1.
    pub column: usize,
}

/// An error in a file: which file, where, which field, what kind and why.
#[derive(Debug, thiserror::Error)]
pub struct FileError {
    /// The file (or the name given to a string source).
    pub file: PathBuf,
    /// Where the parser was when it failed; `None` for errors found after parsing.
    pub position: Option<Position>,
    /// Dotted field path (`tensile.warp.loading`), empty for the whole document.
    pub field: String,
    /// What is wrong.
    pub kind: ErrorKind,
    /// Detail naming the value.
    pub message: String,
    /// The underlying I/O error, for [`ErrorKind::Io`].
    #[source]
    pub source: Option<std::io::Error>,
}

impl fmt::Display for FileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file.display())?;
        if let Some(p) = self.position {
            write!(f, ":{}:{}", p.line, p.column)?;
        }
        if !self.field.is_empty() {
            write!(f, ": field `{}`", self.field)?;
        }
        write!(f, ": {}: {}", self.kind, self.message)
    }
}

impl FileError {
    /// A validation error found after parsing (no position known).
    pub fn from_invalid(file: impl Into<PathBuf>, err: InvalidValue) -> Self {
        Self {
            file: file.into(),
            position: None,
            field: err.field,
            kind: err.kind,
            message: err.message,
            source: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn invalid_value_survives_a_trip_through_a_message() {
        let e = InvalidValue::new(ErrorKind::NonMonotone, "loading[3]", "force 2 after 5");
        let decoded = InvalidValue::decode(&e.to_string()).expect("decodes");
        assert_eq!(decoded, e);
        let root = InvalidValue::new(ErrorKind::Negative, "", "mass -1");
        assert_eq!(InvalidValue::decode(&root.to_string()), Some(root));
        assert_eq!(InvalidValue::decode("invalid type: string"), None);
    }

    #[test]
    fn paths_join() {
        assert_eq!(join_path("tensile", "warp"), "tensile.warp");
        assert_eq!(join_path("loading", "[3]"), "loading[3]");
        assert_eq!(join_path("", "lt"), "lt");
        assert_eq!(join_path("bending", ""), "bending");
    }
}
