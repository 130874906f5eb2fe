//! Integration tests of atelier-fabric, one binary with a module per topic. Every test asserts
//! values against an analytic answer, a published number or an exact identity, with the
//! tolerance stated beside it.

mod anisotropy;
mod bending;
mod common;
mod files;
mod shear;
mod tensile;
