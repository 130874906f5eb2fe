//! Wet cloth held by trapped air (Yamada's thesis; `method.md` §5; `docs/wet.md`).
//!
//! A wet cloth seals the air between itself and the surface it lies on: lifting it lowers the
//! trapped air's pressure (Boyle), and the atmosphere presses it back — the sticking of a wet
//! cloth, and the tent it makes over a bubble of air.
//!
//! - [`volume`]: the bubble's volume (Y3.10) on a plane, and between the cloth and its footprint
//!   on any surface;
//! - [`pressure`]: the pressure force (Y3.7)–(Y3.9), one bubble (the thesis) or separate pockets,
//!   with an optional leak, and its backward-Euler pressure for large steps;
//! - [`stage`]: the force bound to a cloth, as a stage of either solver ([`crate::Solver::pressure`]
//!   in the PARTY step; [`YamadaExtras`] in the mass-spring step);
//! - [`contact`]: the plane, with Yamada's normal force and friction (Y3.4)–(Y3.5) or as the PARTY
//!   step's contact planes;
//! - [`scene`]: the thesis's experiment (a square on a plane, pinched and lifted) run on either
//!   solver, with its metrics.

pub mod contact;
pub mod pressure;
pub mod scene;
pub mod stage;
pub mod volume;

pub use contact::{PlaneContact, PlaneHook, YamadaExtras};
pub use pressure::{
    ATMOSPHERE, Bubble, Bubbles, PressureModel, PressureParams, PressureReport, Surface,
};
pub use stage::{NodeArea, PressureStage};
pub use volume::Plane;
