//! # atelier-grid
//!
//! Boundary-fitted structured grids for cloth (thesis §4; `method.md` §4). This crate owns the
//! cooked cloth topology ([`ClothTopology`]) that the solver consumes. For now it builds it from
//! structured grids given directly — a rectangular sheet and an annulus (the drape disk); the
//! gridding of sewing patterns (Coons patches, improvement, seams, darts) comes with its issue and
//! produces the same type.

pub mod topology;

pub use topology::{
    Cell, ClothTopology, Edge, EdgeKind, NO_NODE, SLOTS, StructuredGrid, TopologyError,
};
