//! What a step reports: its stages, the errors that stop it (and the checks that raise them),
//! its per-stage timings and its diagnostics.

use std::time::Duration;

use super::V3;
use super::projection::Constraint;
use crate::cloth::Cloth;
use crate::params::{ParamError, StepInput, StepParams};
use crate::state::ClothState;

/// The stages of a step, for timings and errors.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Stage {
    /// Positions and velocities handed to the step.
    Input,
    /// Normals, curvatures and bending forces.
    Bending,
    /// Internal axial forces.
    InternalForces,
    /// Unconstrained velocity.
    Velocity,
    /// The air pressure force of a wet cloth.
    Pressure,
    /// Shape-constraint targets and iterations.
    ShapeConstraints,
    /// A collision pass (the hook).
    Collision,
    /// Position and hysteresis update.
    Update,
}

/// A step that could not be completed; the state is as it was before the step.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum StepError {
    /// A parameter is outside its range.
    #[error(transparent)]
    Params(#[from] ParamError),
    /// The state does not match the cloth.
    #[error("the state has {found} {what}, the cloth {expected}")]
    Mismatch {
        /// What is counted.
        what: &'static str,
        /// The cloth's count.
        expected: usize,
        /// The state's count.
        found: usize,
    },
    /// The step would stretch an edge beyond `StepParams::divergence_strain`.
    #[error(
        "diverging: edge {edge} would reach strain {strain:.3} (limit {limit}) at time {time} s; Δt too large or tolerances too loose"
    )]
    Diverged {
        /// The edge.
        edge: usize,
        /// Its strain |l/l⁰ − 1| after the step.
        strain: f64,
        /// The limit.
        limit: f64,
        /// Simulated time at the start of the step.
        time: f64,
    },
    /// The shape stage's linear algebra failed (a factorization that cannot be made).
    #[error("the shape constraints cannot be solved at time {time} s: {message}")]
    Solve {
        /// What failed.
        message: String,
        /// Simulated time at the start of the step.
        time: f64,
    },
    /// A value became NaN or infinite.
    #[error("non-finite {quantity} at {location} {index} in stage {stage:?} (time {time} s)")]
    NonFinite {
        /// The stage that produced it.
        stage: Stage,
        /// What quantity.
        quantity: &'static str,
        /// "node" or "edge".
        location: &'static str,
        /// Its index.
        index: usize,
        /// Simulated time at the start of the step.
        time: f64,
    },
}

/// Per-stage wall time of one step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StageTimings {
    /// Normals, curvature, bending force.
    pub bending: Duration,
    /// Internal forces.
    pub internal: Duration,
    /// Unconstrained velocity.
    pub velocity: Duration,
    /// Targets and constraint iterations.
    pub shape: Duration,
    /// Collision hook: the passes between shape iterations.
    pub collision: Duration,
    /// Collision hook: the transfer of body motion before the shape constraints.
    pub transfer: Duration,
    /// Update and diagnostics.
    pub update: Duration,
    /// The air pressure force ([`Solver::pressure`](super::Solver::pressure); zero when off).
    pub pressure: Duration,
}

impl std::ops::AddAssign<&StageTimings> for StageTimings {
    /// Every stage's time added, the pressure force's included.
    fn add_assign(&mut self, o: &StageTimings) {
        self.bending += o.bending;
        self.internal += o.internal;
        self.velocity += o.velocity;
        self.shape += o.shape;
        self.collision += o.collision;
        self.transfer += o.transfer;
        self.update += o.update;
        self.pressure += o.pressure;
    }
}

impl StageTimings {
    /// Sum of all stages.
    pub fn total(&self) -> Duration {
        self.bending
            + self.internal
            + self.velocity
            + self.transfer
            + self.shape
            + self.collision
            + self.update
            + self.pressure
    }
}

/// Diagnostics of one step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepReport {
    /// Whether the step met every tolerance: the shape constraints (`shape_converged`), the
    /// internal forces (`internal_converged`) and the implicit bending solve.
    pub converged: bool,
    /// Whether the largest relative violation the step ends with (after the last collision
    /// pass), `violation`, is at most `shape.tolerance` (× the tolerance policy's factor).
    pub shape_converged: bool,
    /// The largest relative violation of the shape constraints the step ends with: |l − l̄|/l⁰
    /// of the axial edges, the cells' compliant residual (rad), ties' excess and depth behind
    /// contact planes over the node spacing.
    pub violation: f64,
    /// The constraint with that violation.
    pub worst: Option<Constraint>,
    /// The violation at the end of the last pass's iterations (before its collision pass).
    pub shape_pass_violation: f64,
    /// Collision passes made: `StepParams::collision_passes`, or up to
    /// [`EXTRA_PASSES`](crate::EXTRA_PASSES) more when the last one left a converged shape
    /// above its tolerance.
    pub collision_passes: usize,
    /// Shape iterations over all passes.
    pub shape_iterations: usize,
    /// Numeric factorizations of the shape stage's system (direct method).
    pub factorizations: usize,
    /// Conjugate-gradient iterations of the shape stage (global methods).
    pub linear_iterations: usize,
    /// Internal-force iterations (axial edges).
    pub internal_iterations: usize,
    /// Final E over its value at p = 0 (1 = nothing balanced, 0 = all external load carried).
    pub internal_residual: f64,
    /// Whether the internal forces' projected gradient met `internal.tolerance`.
    pub internal_converged: bool,
    /// Iterations of the implicit bending solve.
    pub bending_iterations: usize,
    /// Its final residual relative to its initial one.
    pub bending_residual: f64,
    /// Largest |ε − ε̄| over the axial edges after the update (stretch-only edges: excess only).
    pub max_strain_error: f64,
    /// Kinetic energy after the step, J.
    pub kinetic_energy: f64,
    /// Fastest node after the step, m/s.
    pub max_speed: f64,
    /// Edges whose force per width lay above the measured range (strain extrapolated).
    pub extrapolated_edges: usize,
    /// The tolerance factor the policy applied (1 = tight).
    pub tolerance_factor: f64,
    /// Wall time per stage.
    pub timings: StageTimings,
}

/// Counts a run's steps as they are taken: how many, how many did not converge, and the
/// largest violation one ended with (the runners that keep their steps' reports to themselves
/// hand this out: the virtual KES instruments, `crate::kes`; the PARTY runs of wet scenes,
/// `crate::wet::scene::run`). A step that failed is not counted.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SolveStats {
    /// Steps taken.
    pub steps: usize,
    /// Steps that did not meet every tolerance ([`StepReport::converged`] false: the shape
    /// stage's, the internal forces' or the implicit bending solve's).
    pub unconverged: usize,
    /// Of those, steps whose shape stage stopped above its tolerance
    /// ([`StepReport::shape_converged`] false).
    pub shape_unconverged: usize,
    /// The largest violation a step ended with (relative strain, rad; NaN once a step ended
    /// with NaN).
    pub worst_violation: f64,
    /// The constraint that had it.
    pub worst: Option<Constraint>,
    /// Simulated time at the start of that step, s.
    pub worst_time: f64,
    /// The shape tolerance the steps were held to (`StepParams::shape_tolerance` of the last
    /// step counted).
    pub tolerance: f64,
}

impl SolveStats {
    /// Count one step's `report`, taken with `params` from simulated time `start_time`.
    pub fn add(&mut self, report: &StepReport, params: &StepParams, start_time: f64) {
        self.steps += 1;
        self.unconverged += usize::from(!report.converged);
        self.shape_unconverged += usize::from(!report.shape_converged);
        self.tolerance = params.shape.tolerance;
        // A NaN violation becomes the worst (and stays: nothing compares above it).
        if report.violation.is_nan() || report.violation > self.worst_violation {
            self.worst_violation = report.violation;
            self.worst = report.worst;
            self.worst_time = start_time;
        }
    }
}

/// The checks before a step: parameters in range, a state that matches the cloth, finite
/// positions and velocities.
pub(super) fn check_input(
    cloth: &Cloth,
    state: &ClothState,
    params: &StepParams,
    input: StepInput,
) -> Result<(), StepError> {
    params.validate()?;
    input.validate()?;
    let topo = cloth.topology();
    let (n, ne) = (topo.node_count(), topo.edges().len());
    for (what, expected, found) in [
        ("positions", n, state.positions.len()),
        ("velocities", n, state.velocities.len()),
        ("edge forces", ne, state.axial_force.len()),
        ("tensile states", ne, state.tensile.len()),
        ("bending states", n, state.bending.len()),
        (
            "cell shear angles",
            topo.cells().len(),
            state.shear_angle.len(),
        ),
        ("cell shear states", topo.cells().len(), state.shear.len()),
    ] {
        if expected != found {
            return Err(StepError::Mismatch {
                what,
                expected,
                found,
            });
        }
    }
    guard_nodes(Stage::Input, "position", &state.positions, state.time)?;
    guard_nodes(Stage::Input, "velocity", &state.velocities, state.time)
}

/// Stop the step (stage `stage`, simulated time `time` at its start) at the first node whose
/// `quantity` in `values` is NaN or infinite.
pub(super) fn guard_nodes(
    stage: Stage,
    quantity: &'static str,
    values: &[V3],
    time: f64,
) -> Result<(), StepError> {
    let first = values
        .iter()
        .position(|x| !(x.x.is_finite() && x.y.is_finite() && x.z.is_finite()));
    non_finite(stage, quantity, "node", first, time)
}

/// Stop the step (stage `stage`, simulated time `time` at its start) at the first edge whose
/// `quantity` in `values` is NaN or infinite.
pub(super) fn guard_edges(
    stage: Stage,
    quantity: &'static str,
    values: &[f64],
    time: f64,
) -> Result<(), StepError> {
    let first = values.iter().position(|x| !x.is_finite());
    non_finite(stage, quantity, "edge", first, time)
}

/// [`StepError::NonFinite`] at `first`, if any.
fn non_finite(
    stage: Stage,
    quantity: &'static str,
    location: &'static str,
    first: Option<usize>,
    time: f64,
) -> Result<(), StepError> {
    match first {
        Some(index) => Err(StepError::NonFinite {
            stage,
            quantity,
            location,
            index,
            time,
        }),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solve_stats_count_unconverged_steps_and_keep_the_worst() {
        let params = StepParams {
            shape: crate::params::ShapeParams {
                tolerance: 1e-6,
                ..crate::params::ShapeParams::default()
            },
            ..StepParams::default()
        };
        let report = |converged, shape_converged, violation, worst| StepReport {
            converged,
            shape_converged,
            violation,
            worst,
            ..StepReport::default()
        };
        let mut s = SolveStats::default();
        s.add(
            &report(true, true, 1e-7, Some(Constraint::Edge(1))),
            &params,
            0.0,
        );
        s.add(
            &report(false, false, 3e-5, Some(Constraint::Cell(4))),
            &params,
            0.01,
        );
        s.add(
            &report(false, true, 2e-7, Some(Constraint::Edge(2))),
            &params,
            0.02,
        );
        assert_eq!((s.steps, s.unconverged, s.shape_unconverged), (3, 2, 1));
        assert_eq!(s.worst_violation.to_bits(), 3e-5_f64.to_bits());
        assert_eq!(s.worst, Some(Constraint::Cell(4)));
        assert_eq!(s.worst_time.to_bits(), 0.01_f64.to_bits());
        assert_eq!(s.tolerance.to_bits(), 1e-6_f64.to_bits());
        s.add(&report(false, false, f64::NAN, None), &params, 0.03);
        s.add(
            &report(true, true, 1.0, Some(Constraint::Edge(3))),
            &params,
            0.04,
        );
        assert!(s.worst_violation.is_nan() && s.worst.is_none());
        assert_eq!(s.worst_time.to_bits(), 0.03_f64.to_bits());
    }
}
