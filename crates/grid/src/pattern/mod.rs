//! Sewing patterns (thesis §4.6.1; `method.md` §4): pattern files, their gridding into panels,
//! and garments — panels joined by seams with matching node counts.

pub mod build;
pub mod counts;
pub mod garment;
pub mod geometry;
mod mirror;
pub mod spec;

pub use build::{NodePairs, Panel, Team, cook, grid_pattern};
pub use counts::{CountError, match_seam_counts, rescale_darts};
pub use garment::{
    Garment, GarmentSpec, PanelPattern, PanelRef, Seam, SeamSpec, drafted_pattern,
    grid_fitting_darts, load_garment, load_garment_with, load_pattern,
};
pub use geometry::{Point, Segment};
pub use spec::{DartSpec, ImproveSpec, Mountain, Outline, PatternSpec, PleatSpec, TeamSpec};
