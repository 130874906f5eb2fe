//! # atelier-files
//!
//! The plumbing every atelier file format shares, so that the fabric, grid, body and fit crates
//! depend on it rather than on each other:
//!
//! - [`files`]: RON loading with errors that name the file, line:column and field path, text
//!   and byte reads with typed errors, and atomic writes (a temporary file beside the target,
//!   renamed when complete);
//! - [`error`]: [`FileError`] (file, position, field, kind, message) and [`InvalidValue`] (a
//!   value's check failing while it is parsed);
//! - [`check`]: checks run while parsing (`deserialize_with` helpers, the [`Validate`] trait and
//!   the [`validated!`] macro for cross-field checks);
//! - [`noise`]: the small seeded random number generator of the synthetic experiments.
//!
//! ```
//! use atelier_files::files::parse_ron;
//! use std::path::Path;
//!
//! #[derive(Debug, serde::Deserialize)]
//! struct Sizes { bust: f64 }
//! let e = parse_ron::<Sizes>("(bust: \"ninety\")", Path::new("sizes.ron")).unwrap_err();
//! assert!(e.to_string().starts_with("sizes.ron:1:"), "{e}");
//! assert_eq!(e.field, "bust");
//! ```

pub mod check;
pub mod error;
pub mod files;
pub mod noise;

pub use check::Validate;
pub use error::{ErrorKind, FileError, InvalidValue, Position};
