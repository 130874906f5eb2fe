//! The trapped air under a wet cloth (Yamada's thesis; `method.md` §5; `docs/wet.md`): the
//! physics of the pressure force, apart from any solver, so that the PARTY step
//! ([`crate::step`]) can run it as a stage without depending on the wet scenes ([`crate::wet`]),
//! which re-export it.
//!
//! - [`volume`]: the bubble's volume (Y3.10) on a plane, and between the cloth and its footprint
//!   on any surface;
//! - [`pressure`]: the pressure force (Y3.7)–(Y3.9), one bubble (the thesis) or separate pockets,
//!   with an optional leak, and its backward-Euler pressure for large steps;
//! - [`stage`]: the force bound to a cloth, as a stage of either solver ([`crate::Solver::pressure`]
//!   in the PARTY step; `YamadaExtras` in the mass-spring step).

pub mod pressure;
pub mod stage;
pub mod volume;

pub use pressure::{
    ATMOSPHERE, Bubble, Bubbles, PressureModel, PressureParams, PressureReport, Surface,
};
pub use stage::{NodeArea, PressureStage};
pub use volume::Plane;
