//! # atelier
//!
//! The facade of the atelier workspace: it composes the fabric, grid, body, collision, solver
//! and fit crates into scenes and runs, and computes nothing of its own physics.
//!
//! - A garment: gridded panels assembled into one cloth with its seams ([`assemble`]), placed
//!   round the body ([`place`]), dressed by sewing ([`sewing`], thesis §5.6) or by one-sided
//!   contact, then walked; [`Scene`] and [`Simulation`] run it step by step ([`pipeline`] holds
//!   the phases).
//! - Scenario files ([`scenario`]) and their runs ([`run`]): the report ([`report`], with
//!   [`convergence`]), exports ([`export`]: OBJ, PLY, glTF) and pictures ([`picture`], the one
//!   rasteriser; [`camera`]; [`chart`], drawn only with the `charts` feature).
//! - Patterns from pattern software and apparel CAD ([`patterns`]: DXF-AAMA read by
//!   `atelier-import`, each piece made a pattern and gridded, written as RON and OBJ).
//! - Virtual tests and the other scene kinds run through the same runner: wet cloth ([`wet`]),
//!   string identification and the writing of a fabric's bending fit ([`fit`]; the fits
//!   themselves, and the turned strip, are `atelier-fit`'s).
//!
//! The command-line program is the `atelier-cli` crate; the try-on from a photograph is
//! `atelier-tryon`. A library user depends on this crate alone and pulls neither clap,
//! indicatif nor plotters (unless the `charts` feature is turned on).

pub mod assemble;
pub mod camera;
pub mod chart;
pub mod convergence;
pub mod export;
pub mod fit;
pub mod outcome;
pub mod patterns;
pub mod picture;
pub mod pipeline;
pub mod place;
pub mod report;
pub mod run;
pub mod scenario;
pub mod scene;
pub mod sewing;
pub mod simulation;
pub mod wet;

pub use assemble::{AssembleError, GarmentCloth};
pub use scene::{
    BodyScanSpec, ClothSolver, Garment, GarmentSpec, LengthUnit, Scene, SceneError, Settings,
};
pub use sewing::{Chain, Sewing, SewingParams};
pub use simulation::{Phase, Simulation, SimulationError, StepOutcome};
