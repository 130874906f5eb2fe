//! # atelier-grid
//!
//! Boundary-fitted structured grids for cloth and bodies (thesis §4; `method.md` §4): the initial
//! grid by arc-length spacing and Coons patches ([`coons`]), its improvement by smoothness, shear
//! and spacing energies on a plane, a height field or a range image ([`improve`](fn@improve)), sewing patterns
//! with teams, darts, pleats and seams ([`pattern`]), grid quality ([`quality`]), and the cooked
//! cloth topology the solver consumes ([`ClothTopology`]). Bodies gridded from range images use
//! these patches and the improvement from `atelier_body::range`.

pub mod coons;
pub mod improve;
pub mod patch;
pub mod pattern;
pub mod quality;
pub mod topology;

pub use improve::{HeightField, ImproveParams, ImproveReport, Plane, Surface, improve};
pub use patch::Patch;
pub use quality::{GridQuality, Stats};
pub use topology::{
    Cell, ClothTopology, Edge, EdgeKind, NO_NODE, Quad, SLOTS, StructuredGrid, TopologyError,
};
