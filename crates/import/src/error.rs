//! What can go wrong reading a pattern file: every error names the file, and where it is about a
//! piece, the piece and the entity (its type, handle and layer).

use std::fmt;
use std::path::PathBuf;

/// An error reading a pattern file.
#[derive(Debug, thiserror::Error)]
pub enum ImportError {
    /// The file could not be read or is not DXF.
    #[error("{}: cannot read: {message}", file.display())]
    Read {
        /// The file.
        file: PathBuf,
        /// What the reader said.
        message: String,
    },
    /// Neither `$INSUNITS` nor a `Units:` style text says what a coordinate is.
    #[error(
        "{}: no units: the header's $INSUNITS is unset (unitless) and no `Units:` text says METRIC or ENGLISH; a pattern's size cannot be guessed",
        file.display()
    )]
    NoUnits {
        /// The file.
        file: PathBuf,
    },
    /// Units the reader does not take for a garment (a unit absurd for a pattern piece).
    #[error("{}: unsupported units {units}", file.display())]
    Units {
        /// The file.
        file: PathBuf,
        /// The header's unit.
        units: String,
    },
    /// No block holds a boundary (layer 1) or sew line (layer 14).
    #[error("{}: no pattern pieces: no block has a boundary (layer 1) or sew line (layer 14){}", file.display(), if skipped.is_empty() { String::new() } else { format!("; skipped: {}", skipped.join("; ")) })]
    NoPieces {
        /// The file.
        file: PathBuf,
        /// What was skipped on the way (the warnings).
        skipped: Vec<String>,
    },
    /// Two pieces with the same name (seams refer to pieces by name).
    #[error("{}: two pieces are named {name:?} (blocks {first} and {second})", file.display())]
    DuplicateName {
        /// The file.
        file: PathBuf,
        /// The name.
        name: String,
        /// The first block.
        first: String,
        /// The second block.
        second: String,
    },
    /// A piece that cannot be a panel.
    #[error("{}: piece {piece:?}, {entity}: {problem}", file.display())]
    Piece {
        /// The file.
        file: PathBuf,
        /// The piece (its name, or its block's when it has none).
        piece: String,
        /// The entity: type, handle and layer (`LWPOLYLINE 2F on layer 14`).
        entity: String,
        /// What is wrong.
        problem: PieceProblem,
    },
}

/// What is wrong with a piece's outline.
#[derive(Clone, Debug, PartialEq)]
pub enum PieceProblem {
    /// Fewer than three distinct points.
    TooFewPoints(usize),
    /// A coordinate is NaN or infinite.
    NotFinite,
    /// The outline is not closed: neither flagged closed nor ending at its start.
    NotClosed {
        /// Distance from the last point to the first, cm.
        gap_cm: f64,
    },
    /// Two edges of the outline cross.
    SelfIntersecting {
        /// Where (a point of the first edge), cm.
        at: [f64; 2],
        /// The two edges (indices of their first vertices).
        edges: (usize, usize),
    },
    /// The outline encloses (almost) no area.
    ZeroArea {
        /// The area, cm².
        area_cm2: f64,
    },
    /// The piece cannot be split into the four sides of a grid.
    Sides(String),
}

impl fmt::Display for PieceProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PieceProblem::TooFewPoints(n) => {
                write!(f, "the outline has {n} distinct points (at least 3)")
            }
            PieceProblem::NotFinite => write!(f, "a coordinate is not finite"),
            PieceProblem::NotClosed { gap_cm } => write!(
                f,
                "the outline does not close: it ends {gap_cm:.3} cm from its start and is not flagged closed"
            ),
            PieceProblem::SelfIntersecting { at, edges } => write!(
                f,
                "the outline crosses itself near ({:.2}, {:.2}) cm (edges {} and {})",
                at[0], at[1], edges.0, edges.1
            ),
            PieceProblem::ZeroArea { area_cm2 } => {
                write!(f, "the outline encloses {area_cm2:.2e} cm² (no area)")
            }
            PieceProblem::Sides(why) => write!(f, "{why}"),
        }
    }
}
