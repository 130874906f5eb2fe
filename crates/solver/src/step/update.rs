//! Stage 5: the position update, the divergence check, the commit of the step to the state
//! (hysteresis included) and the strain diagnostics.

use atelier_grid::NO_NODE;

use super::Solver;
use super::StepError;
use super::bending::regularised;
use super::par::fill;
use crate::cloth::Cloth;
use crate::params::{ConstraintKind, StepParams};
use crate::state::ClothState;

impl Solver {
    /// The positions at the end of the step, r + ṙΔt, into `pred`.
    pub(super) fn predict_positions(&mut self, state: &ClothState, dt: f64) {
        let positions = &state.positions;
        let vel = &self.s.vel;
        fill(&mut self.s.pred, |i| positions[i] + vel[i] * dt);
    }

    /// [`StepError::Diverged`] if an edge would end the step strained beyond
    /// `StepParams::divergence_strain` (`time`: simulated time at the start of the step).
    pub(super) fn check_divergence(
        &self,
        cloth: &Cloth,
        params: &StepParams,
        time: f64,
    ) -> Result<(), StepError> {
        let (edges, pred) = (cloth.topology().edges(), &self.s.pred);
        let worst = edges
            .iter()
            .enumerate()
            .map(|(e, edge)| {
                (
                    e,
                    ((pred[edge.b as usize] - pred[edge.a as usize]).norm() / edge.rest_length
                        - 1.0)
                        .abs(),
                )
            })
            .fold((0, 0.0), |a, b| if b.1 > a.1 { b } else { a });
        if worst.1 > params.divergence_strain {
            return Err(StepError::Diverged {
                edge: worst.0,
                strain: worst.1,
                limit: params.divergence_strain,
                time,
            });
        }
        Ok(())
    }

    /// Commit the step to the state: positions, velocities (plus the contacts' exit velocities),
    /// axial forces, shear angles, hysteresis states, time.
    pub(super) fn commit(&mut self, cloth: &Cloth, state: &mut ClothState, params: &StepParams) {
        std::mem::swap(&mut state.positions, &mut self.s.pred);
        for ((v, w), e) in state
            .velocities
            .iter_mut()
            .zip(&self.s.vel)
            .zip(&self.s.exit)
        {
            *v = w + e;
        }
        state.axial_force.copy_from_slice(&self.s.p);
        state.shear_angle.copy_from_slice(&self.s.shear);
        self.commit_hysteresis(cloth, state, params);
        state.time += params.dt;
    }

    /// Commit the hysteresis states at this step's forces and curvatures.
    fn commit_hysteresis(&mut self, cloth: &Cloth, state: &mut ClothState, params: &StepParams) {
        if !params.hysteresis {
            return;
        }
        let topo = cloth.topology();
        let (edges, mats, table) = (topo.edges(), cloth.edge_materials(), cloth.materials());
        if cloth.tensile_hysteretic() {
            let fpw = &self.s.force_per_width;
            for (e, st) in state.tensile.iter_mut().enumerate() {
                if edges[e].kind.is_axial() {
                    st.update(table.tensile(mats[e]), fpw[e]);
                }
            }
        }
        if cloth.bending_hysteretic() && !params.bending_off {
            let (axial, smats, eta) = (
                cloth.bending_neighbours(),
                cloth.slot_materials(),
                &self.s.eta,
            );
            for (i, slots) in state.bending.iter_mut().enumerate() {
                for (k, st) in slots.iter_mut().enumerate() {
                    if axial[i][k] != NO_NODE {
                        let spindle = regularised(
                            table.bending(smats[i][k]),
                            params.bending_stick_slope,
                            params.bending_deadband,
                        );
                        st.update(&spindle, eta[i][k]);
                    }
                }
            }
        }
    }

    /// Largest |ε − ε̄| after the update (stretch-only edges count only excess stretch).
    pub(super) fn max_strain_error(
        &self,
        cloth: &Cloth,
        state: &ClothState,
        params: &StepParams,
    ) -> f64 {
        let edges = cloth.topology().edges();
        let pos = &state.positions;
        edges
            .iter()
            .enumerate()
            .map(|(e, edge)| {
                let l = (pos[edge.b as usize] - pos[edge.a as usize]).norm();
                let err = (l - self.s.target[e]) / edge.rest_length;
                let kind = if edge.kind.is_axial() {
                    params.axial_constraint
                } else {
                    params.diagonal_constraint
                };
                match kind {
                    ConstraintKind::Equality => err.abs(),
                    ConstraintKind::StretchOnly => err.max(0.0),
                    // A spring: its stretch is the shear, not an error.
                    ConstraintKind::Compliant => 0.0,
                }
            })
            .fold(0.0, f64::max)
    }
}
