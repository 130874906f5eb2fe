//! Sewing patterns (thesis §4.6.1; `method.md` §4): pattern files, their gridding into panels,
//! and garments — panels joined by seams with matching node counts.

pub mod build;
pub mod garment;
pub mod geometry;
pub mod spec;

pub use build::{NodePairs, Panel, Team, cook, grid_pattern};
pub use garment::{Garment, GarmentSpec, PanelRef, Seam, SeamSpec, load_garment, load_pattern};
pub use geometry::{Point, Segment};
pub use spec::{DartSpec, ImproveSpec, Mountain, Outline, PatternSpec, PleatSpec, TeamSpec};
