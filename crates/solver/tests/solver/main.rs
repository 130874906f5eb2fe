//! Validation scenes of atelier-solver, one binary with a module per scene (run in release mode:
//! `cargo test --workspace --release`). Each asserts its reference with the tolerance stated.

mod baselines;
mod cantilever;
mod collision;
mod common;
mod drape;
mod hanging;
mod kes;
mod statics;
mod wet;
