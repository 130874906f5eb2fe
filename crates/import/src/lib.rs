//! Sewing patterns from pattern software and apparel CAD, as atelier pattern panels
//! (`docs/patterns-import.md`).
//!
//! A file is read into [`Piece`]s ([`dxf::read`] for DXF-AAMA / ASTM D6673, the format CLO,
//! Gerber, Lectra, Optitex and Seamly2D export; [`svg::read`] for FreeSewing's SVG output): each piece's closed seam line, its turn points,
//! notches, grain line, darts and internal lines, in centimetres. [`panel::plan`] then makes an
//! atelier pattern of a piece (a `Quad` outline split into teams at its corners, notches and dart
//! ends), which `atelier_grid` grids like a hand-written pattern file.
//!
//! Bad input is an [`ImportError`] naming the file, the piece and the entity; what is read but
//! not used is listed in the import's warnings, never dropped silently.

pub mod dxf;
pub mod error;
pub mod panel;
pub mod piece;
pub mod svg;

pub use error::{ImportError, PieceProblem};
pub use panel::{PanelOptions, Plan, plan, plan_and_grid};
pub use piece::{Dart, Piece};

/// Read a pattern file by its extension: `.dxf` (DXF-AAMA) or `.svg` (FreeSewing).
pub fn read(path: &std::path::Path) -> Result<dxf::Import, ImportError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    match ext.as_str() {
        "svg" => svg::read(path),
        _ => dxf::read(path),
    }
}
