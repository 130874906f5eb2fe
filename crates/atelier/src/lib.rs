//! # atelier
//!
//! The facade (issue 7, in progress): a garment's gridded panels assembled into one cloth with
//! its seams ([`assemble`]), and dressing by sewing ([`sewing`], thesis §5.6): seam node pairs
//! drawn together with gravity off, each pair sewn once it is closer than a threshold; and
//! [`validate`], the checks behind `atelier validate FILE…`.

pub mod assemble;
pub mod chart;
pub mod convergence;
pub mod export;
pub mod fit;
pub mod picture;
pub mod pipeline;
pub mod place;
pub mod report;
pub mod run;
pub mod scenario;
pub mod scene;
pub mod sewing;
pub mod simulation;
pub mod strip;
pub mod tryon;
pub mod validate;
pub mod wet;

pub use assemble::{AssembleError, GarmentCloth};
pub use scene::{ClothSolver, Garment, GarmentSpec, Scene, SceneError, Settings};
pub use sewing::{Chain, Sewing, SewingParams};
pub use simulation::{Phase, Simulation, SimulationError, StepOutcome};
