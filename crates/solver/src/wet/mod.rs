//! Wet cloth held by trapped air (Yamada's thesis; `method.md` §5; `docs/wet.md`).
//!
//! A wet cloth seals the air between itself and the surface it lies on: lifting it lowers the
//! trapped air's pressure (Boyle), and the atmosphere presses it back — the sticking of a wet
//! cloth, and the tent it makes over a bubble of air.
//!
//! - [`volume`], [`pressure`], [`stage`]: the trapped air's physics, which lives in
//!   [`crate::air`] (the PARTY step runs it as a stage) and is re-exported here;
//! - [`contact`]: the plane, with Yamada's normal force and friction (Y3.4)–(Y3.5) or as the PARTY
//!   step's contact planes;
//! - [`scene`]: the thesis's experiment (a square on a plane, pinched and lifted) run on either
//!   solver, with its metrics.

pub mod contact;
pub mod scene;

pub use crate::air::{
    ATMOSPHERE, Bubble, Bubbles, NodeArea, Plane, PressureModel, PressureParams, PressureReport,
    PressureStage, Surface, pressure, stage, volume,
};
pub use contact::{PlaneContact, PlaneHook, YamadaExtras};
