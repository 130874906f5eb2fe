//! Stage 4b: the shape stage — [`ShapeSolver`] run before each collision pass, with the air's
//! pressure (a wet cloth) and the long-range attachments (local methods) after every
//! iteration, and the step's convergence measured after the last collision pass.

use std::time::{Duration, Instant};

use super::projection::{EdgeTension, ShapeProblem, ShapeReport};
use super::report::{Stage, StepError, StepReport, guard_nodes};
use super::{CollisionHook, Solver};
use crate::cloth::Cloth;
use crate::params::{StepParams, Tension};
use crate::state::ClothState;

/// Collision passes a step may add to `StepParams::collision_passes` when the last one leaves
/// a converged shape above its tolerance (`docs/solver.md`, "Extra collision passes").
pub const EXTRA_PASSES: usize = 4;

impl Solver {
    /// The shape stage of one step: for each collision pass, the constraints solved to
    /// `shape_tolerance × factor` (or `shape.max_iterations`), then the hook's pass; afterwards
    /// the violation the step ends with. Fills the shape fields of `report` and the collision
    /// and pressure timings.
    pub(super) fn shape_stage(
        &mut self,
        cloth: &Cloth,
        state: &ClothState,
        params: &StepParams,
        dt: f64,
        factor: f64,
        hook: &mut dyn CollisionHook,
        report: &mut StepReport,
    ) -> Result<(), StepError> {
        let time = state.time;
        let tol = params.shape.tolerance * factor;
        let local = !params.shape.method.is_global();
        self.prepare_long_range(cloth, params, local);
        let mut collision = Duration::ZERO;
        let mut pressure = Duration::ZERO;
        let mut last: ShapeReport;
        let tension = (params.internal.tension == Tension::Constraint).then(|| EdgeTension {
            table: cloth.yarn_materials(),
            materials: cloth.edge_materials(),
            widths: cloth.edge_widths(),
            states: &state.tensile,
            hysteresis: params.hysteresis && cloth.tensile_hysteretic(),
        });
        // The thesis's passes, then up to `EXTRA_PASSES` more while the last pass's shape solve
        // met the tolerance and its collision pass left the shape above it (a contact found or
        // a seam drawn in that pass), each ending with its collision pass. A shape solve that
        // did not converge is not given more passes: the caller halves the step instead.
        // The problem over the scratch's fields (a macro: the solve borrows other fields of the
        // same scratch mutably beside it).
        macro_rules! problem {
            ($s:expr) => {
                ShapeProblem {
                    cloth,
                    positions: &state.positions,
                    dt,
                    time,
                    damping: params.damping,
                    targets: &$s.target,
                    tension,
                    axial: params.shape.axial_constraint,
                    measure: params.shear.measure,
                    shear: &$s.cell_shear,
                    bends: &$s.node_bend,
                    ties: &$s.ties,
                    planes: &$s.planes,
                }
            };
        }
        let mut pass = 0;
        let (violation, worst) = loop {
            let s = &mut self.s;
            let problem = problem!(s);
            let (air, long_range) = (&mut self.pressure, &mut s.long_range);
            let (lr_on, slack) = (s.long_range_on, s.long_range_slack);
            let mut after = |vel: &mut [super::V3]| {
                if let Some(air) = air.as_mut() {
                    let t0 = Instant::now();
                    air.project(&state.positions, cloth.inverse_masses(), dt, vel);
                    pressure += t0.elapsed();
                }
                if lr_on && let Some(lr) = long_range.as_mut() {
                    lr.project(cloth, &state.positions, vel, time + dt, dt, slack);
                }
            };
            last = self
                .projection
                .solve(
                    &problem,
                    &mut s.vel,
                    params.shape.method,
                    params.shape.step,
                    tol,
                    params.shape.max_iterations,
                    pass == 0,
                    &mut after,
                )
                .map_err(|e| StepError::Solve {
                    message: e.to_string(),
                    time,
                })?;
            report.shape_iterations += last.iterations;
            report.factorizations += last.factorizations;
            report.linear_iterations += last.linear_iterations;
            guard_nodes(Stage::ShapeConstraints, "velocity", &self.s.vel, time)?;
            let tc = Instant::now();
            self.collision_pass(cloth, state, dt, pass, hook);
            collision += tc.elapsed();
            guard_nodes(Stage::Collision, "velocity", &self.s.vel, time)?;
            pass += 1;
            if pass < params.shape.collision_passes {
                continue;
            }
            // What the step ends with, after the last collision pass.
            let s = &mut self.s;
            let problem = problem!(s);
            let (violation, worst) = self.projection.measure(&problem, &s.vel);
            if violation <= tol
                || !last.converged
                || pass >= params.shape.collision_passes + EXTRA_PASSES
            {
                break (violation, worst);
            }
        };
        report.collision_passes = pass;
        report.violation = violation;
        report.worst = worst;
        report.shape_converged = violation <= tol;
        report.shape_pass_violation = last.violation;
        report.timings.collision = collision;
        report.timings.pressure += pressure;
        Ok(())
    }

    /// Switch the long-range attachments on for this step when asked for, the method is local
    /// and the cloth has pins (building them when the pins changed), with the step's largest
    /// target strain as slack.
    fn prepare_long_range(&mut self, cloth: &Cloth, params: &StepParams, local: bool) {
        let s = &mut self.s;
        s.long_range_on = params.shape.long_range_attachments && local && !cloth.pins().is_empty();
        if !s.long_range_on {
            return;
        }
        if !s.long_range.as_ref().is_some_and(|lr| lr.matches(cloth)) {
            s.long_range = Some(crate::long_range::LongRange::build(cloth));
        }
        let edges = cloth.topology().edges();
        s.long_range_slack = s
            .target
            .iter()
            .zip(edges)
            .filter(|(_, e)| e.kind.is_axial())
            .map(|(t, e)| t / e.rest_length - 1.0)
            .fold(0.0, f64::max);
    }
}
