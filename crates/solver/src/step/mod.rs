//! The PARTY cloth step (thesis §3.5, §3.8; `method.md` §2) as an ordered list of stages, each a
//! function of its own, each timed, each in a file of its own:
//!
//! 1. geometry (`geometry.rs`) and bending force (28)–(32) (`bending.rs`), plus gravity and the
//!    external forces; the air pressure force of a wet cloth (`pressure.rs`) when
//!    [`Solver::pressure`] is on;
//! 2. internal axial forces p ≥ 0 of the axial edges by projected descent (43)–(47), to a
//!    relative tolerance (`internal.rs`);
//! 3. unconstrained velocity (18) with implicit bending along the normals (`velocity.rs`), then
//!    the collision hook's transfer of body motion (`hook.rs`);
//! 4. the axial edges' target lengths from the tensile characteristics and the cells' shear
//!    constraints from the shear loop (`targets.rs`), then the shape stage (49)–(51): the
//!    constraints solved to a relative tolerance (`projection.rs`: rows, Newton on the
//!    constraint-space system of [`crate::dual`], or local iterations) before each collision
//!    pass (`shape.rs`);
//! 5. position update, hysteresis update (tensile, bending, shear), diagnostics (`update.rs`).
//!
//! Nothing in the state changes until every stage has succeeded: a non-finite value stops the
//! step with the stage and node (or edge), and the state from before the step is kept.
//! `report.rs` holds the report and the errors, `scratch.rs` the buffers the stages share (sized
//! once), `par.rs` the parallel loops and deterministic sums.

mod bending;
mod geometry;
mod hook;
mod internal;
mod par;
mod pressure;
pub(crate) mod projection;
mod report;
mod scratch;
mod shape;
mod targets;
mod update;
mod velocity;

use std::time::Instant;

use atelier_grid::SLOTS;
use nalgebra::Vector3;

use crate::cloth::Cloth;
use crate::params::{StepInput, StepParams};
use crate::state::ClothState;

pub(crate) use hook::plane_push;
pub use hook::{CollisionHook, HookContext, NoCollision, Tie};
pub use projection::Constraint;
pub use report::{SolveStats, Stage, StageTimings, StepError, StepReport};
pub use shape::EXTRA_PASSES;

use par::PAR_MIN;
use report::{guard_edges, guard_nodes};
use scratch::Scratch;

type V3 = Vector3<f64>;

/// The PARTY solver: stateless between steps apart from scratch buffers and cached step-size
/// estimates; the simulation state is passed in explicitly.
#[derive(Default)]
pub struct Solver {
    s: Scratch,
    /// λ_max(AᵀA) of the axial and diagonal phases, estimated on the first step.
    lambda: Option<[f64; 2]>,
    /// The shape stage's rows, system and multipliers (kept between steps).
    projection: projection::ShapeSolver,
    /// External forces per node (N) added in the next steps; empty for none.
    pub external_forces: Vec<V3>,
    /// The air pressure of a wet cloth ([`crate::wet`]): its force at the start of the step joins
    /// the external forces, and the shape iterations take the air's pressure at the end of the
    /// step as a compliant volume constraint (`wet::pressure`, "Large steps"). None (the
    /// default): no pressure, and nothing of it runs.
    pub pressure: Option<crate::air::PressureStage>,
}

impl Solver {
    /// A solver with empty scratch.
    pub fn new() -> Self {
        Self::default()
    }

    /// Target length of every edge in the last step, m (diagnostics).
    pub fn last_targets(&self) -> &[f64] {
        &self.s.target
    }

    /// Node bending moment M of the last step (thesis (31)), N·m (diagnostics and virtual tests).
    pub fn last_node_moments(&self) -> &[f64] {
        &self.s.node_moment
    }

    /// Curvature of each node's axial slots in the last step, m⁻¹ (diagnostics).
    pub fn last_curvatures(&self) -> &[[f64; SLOTS]] {
        &self.s.eta
    }

    /// Forget cached estimates (call when switching to a different cloth or changing pins).
    pub fn reset(&mut self) {
        self.lambda = None;
        self.projection = projection::ShapeSolver::default();
    }

    /// The force the last step's constraints (edges, cells, bending, ties) exerted on each
    /// node, N: at a pinned node, minus the reaction its pin supplied — what a clamp measures
    /// (the virtual KES instruments). Zero before the first step.
    pub fn constraint_forces(&self, dt: f64) -> Vec<V3> {
        let mut out = vec![V3::zeros(); self.s.vel.len()];
        self.projection.node_forces(dt, &mut out);
        out
    }

    /// Rows of the shape stage's system, and the non-zeros of its lower triangle and of its
    /// factor (0 before the first step; diagnostics and benches).
    pub fn shape_system_size(&self) -> (usize, usize, usize) {
        let (a, l) = self.projection.sizes();
        (self.projection.rows(), a, l)
    }

    /// One step without collisions.
    pub fn step(
        &mut self,
        cloth: &Cloth,
        state: &mut ClothState,
        params: &StepParams,
        input: StepInput,
    ) -> Result<StepReport, StepError> {
        self.step_with(cloth, state, params, input, &mut NoCollision)
    }

    /// One step with a collision hook between shape-constraint iterations.
    pub fn step_with(
        &mut self,
        cloth: &Cloth,
        state: &mut ClothState,
        params: &StepParams,
        input: StepInput,
        hook: &mut dyn CollisionHook,
    ) -> Result<StepReport, StepError> {
        if cloth.topology().edges().len() >= PAR_MIN {
            // Run the whole step on a pool thread: the parallel loops inside then split work
            // by stealing instead of each injecting a job from outside the pool (measured:
            // ~20 % of a 1 681-node step went to thread hand-offs).
            rayon::scope(|_| self.step_inner(cloth, state, params, input, hook))
        } else {
            self.step_inner(cloth, state, params, input, hook)
        }
    }

    /// The stages in order (see the module doc); the state changes only in the last, once every
    /// stage before it has succeeded.
    fn step_inner(
        &mut self,
        cloth: &Cloth,
        state: &mut ClothState,
        params: &StepParams,
        input: StepInput,
        hook: &mut dyn CollisionHook,
    ) -> Result<StepReport, StepError> {
        report::check_input(cloth, state, params, input)?;
        self.size(cloth);
        let mut report = StepReport::default();
        let (dt, time) = (input.dt, state.time);

        // 1. Geometry and bending.
        let t0 = Instant::now();
        self.geometry(cloth, state);
        self.bending(cloth, state, params);
        self.add_external(cloth, input.gravity_vector());
        guard_nodes(Stage::Bending, "bending force", &self.s.f_sum, time)?;
        report.timings.bending = t0.elapsed();

        // 1b. The air pressure force (a wet cloth only).
        if self.pressure.is_some() {
            let t0 = Instant::now();
            self.pressure_force(cloth, state, params, dt);
            guard_nodes(Stage::Pressure, "pressure force", &self.s.f_sum, time)?;
            report.timings.pressure = t0.elapsed();
        }

        // 2. Internal forces.
        let t0 = Instant::now();
        report.tolerance_factor = params.tolerance_factor(max_speed(&state.velocities));
        (
            report.internal_iterations,
            report.internal_residual,
            report.internal_converged,
        ) = self.internal_forces(cloth, state, params, report.tolerance_factor);
        guard_edges(Stage::InternalForces, "axial force", &self.s.p, time)?;
        report.timings.internal = t0.elapsed();

        // 3. Unconstrained velocity.
        let t0 = Instant::now();
        (report.bending_iterations, report.bending_residual) =
            self.unconstrained_velocity(cloth, state, params, dt);
        guard_nodes(Stage::Velocity, "velocity", &self.s.vel, time)?;
        report.timings.velocity = t0.elapsed();

        // 3b. Transfer of body motion (staged collision model).
        let t0 = Instant::now();
        self.transfer_body_motion(cloth, state, dt, hook);
        guard_nodes(Stage::Collision, "velocity", &self.s.vel, time)?;
        report.timings.transfer = t0.elapsed();

        // 4. Shape constraints, interleaved with collision passes.
        let t0 = Instant::now();
        report.extrapolated_edges = self.targets(cloth, state, params);
        guard_edges(
            Stage::ShapeConstraints,
            "target length",
            &self.s.target,
            time,
        )?;
        self.cell_shear(cloth, state, params);
        self.node_bend(cloth, state, params);
        let pressure_before = report.timings.pressure;
        self.shape_stage(
            cloth,
            state,
            params,
            dt,
            report.tolerance_factor,
            hook,
            &mut report,
        )?;
        report.timings.shape =
            t0.elapsed() - report.timings.collision - (report.timings.pressure - pressure_before);
        report.converged = report.shape_converged
            && report.internal_converged
            && report.bending_residual <= params.bending.tolerance;

        // 5. Update and commit.
        let t0 = Instant::now();
        self.predict_positions(state, dt);
        guard_nodes(Stage::Update, "position", &self.s.pred, time)?;
        self.check_divergence(cloth, params, time)?;
        self.commit(cloth, state, params, dt);
        report.max_strain_error = self.max_strain_error(cloth, state, params);
        report.kinetic_energy = state.kinetic_energy(cloth);
        report.max_speed = max_speed(&state.velocities);
        report.timings.update = t0.elapsed();
        Ok(report)
    }
}

/// The fastest node's speed, m/s.
fn max_speed(velocities: &[V3]) -> f64 {
    velocities.iter().map(|v| v.norm()).fold(0.0, f64::max)
}
