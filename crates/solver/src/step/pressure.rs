//! Stage 1c: the air pressure force of a wet cloth ([`Solver::pressure`]).

use super::Solver;
use super::par::fill;
use crate::cloth::Cloth;
use crate::params::StepParams;
use crate::state::ClothState;

impl Solver {
    /// The air pressure force of a wet cloth and the surface's support, added to F_sum (nothing
    /// when [`Solver::pressure`] is off); the support's reaction is kept in `reaction` for the
    /// internal-force stage.
    pub(super) fn pressure_force(
        &mut self,
        cloth: &Cloth,
        state: &ClothState,
        params: &StepParams,
        dt: f64,
    ) {
        let Some(p) = &mut self.pressure else {
            return;
        };
        // The pressure predicted for the end of the step (backward Euler) from the
        // velocities the other forces would give.
        let (mass, areas, f) = (cloth.masses(), cloth.topology().node_areas(), &self.s.f_sum);
        let vel0 = &state.velocities;
        fill(&mut self.s.pred, |i| {
            let c = params.damping * areas[i];
            (vel0[i] * mass[i] + f[i] * dt) / (mass[i] + c * dt)
        });
        for pin in cloth.pins() {
            let i = pin.node as usize;
            self.s.pred[i] = (pin.position(state.time + dt) - state.positions[i]) / dt;
        }
        p.add_forces_predicted(
            &state.positions,
            &self.s.pred,
            cloth.inverse_masses(),
            dt,
            &mut self.s.f_sum,
        );
        p.support(
            &state.velocities,
            cloth.inverse_masses(),
            dt,
            &mut self.s.f_sum,
            &mut self.s.reaction,
        );
    }
}
