//! # atelier-solver
//!
//! The PARTY cloth model (Sakaguchi's thesis §3.5 and §3.8; `method.md` §2): a constraint-
//! satisfaction step in which measured tensile characteristics fix the lengths of the grid's
//! edges at the forces they carry, and measured bending characteristics give forces along the
//! surface normal. See `docs/solver.md` for the stages, their equations and every choice made
//! where the thesis is silent.
//!
//! - [`Cloth`]: topology + fabric + masses + pins (static);
//! - [`ClothState`]: positions, velocities, warm-start forces, hysteresis states;
//! - [`Solver::step`]: one step, with [`StepParams`] and a [`StepReport`] of diagnostics.

pub mod air;
pub mod baselines;
pub mod bend_angle;
pub mod cloth;
pub mod contact;
pub mod dual;
pub mod integrator;
pub mod kes;
pub mod kkt;
pub mod leg;
pub mod long_range;
pub mod metrics;
pub mod params;
pub mod scenes;
pub mod shear_angle;
pub mod show_through;
pub mod state;
pub mod step;
pub mod wet;

pub use cloth::{Cloth, ClothError, ClothOptions, Incidence, Pin, PinMotion};
pub use contact::BodyContact;
pub use params::{
    BendingModel, BendingParams, ConstraintKind, InternalMethod, InternalParams, ParamError,
    ShapeMethod, ShapeParams, ShearParams, StepInput, StepParams, Tension, TolerancePolicy,
};
pub use shear_angle::ShearMeasure;
pub use state::ClothState;
pub use step::{
    CollisionHook, EXTRA_PASSES, HookContext, NoCollision, SolveStats, Solver, Stage, StageTimings,
    StepError, StepReport, Tie,
};
