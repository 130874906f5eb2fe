//! Stage 5: the position update, the divergence check, the commit of the step to the state
//! (hysteresis included) and the strain diagnostics.

use atelier_grid::NO_NODE;

use super::Solver;
use super::StepError;
use super::bending::regularised;
use super::par::fill;
use crate::bend_angle::turn_and_gradient;
use crate::cloth::Cloth;
use crate::params::{BendingModel, ConstraintKind, StepParams, Tension};
use crate::shear_angle::cell_angle;
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
        let topo = cloth.topology();
        let (edges, pred) = (topo.edges(), &self.s.pred);
        // A diagonal is not a constraint (the cell's shear row is): its change is measured
        // against its cell's size, the longest of the diagonal and the cell's sides. Against
        // its own rest length, the 2.6 mm diagonal of a sliver cell at the dress's bust-dart
        // apex (sides ~2 cm) read as torn when the cell sheared by a few millimetres.
        let reference = |e: usize, edge: &atelier_grid::Edge| {
            let cell = topo.edge_cells().get(e).map_or(NO_NODE, |c| c[0]);
            if edge.kind.is_axial() || cell == NO_NODE {
                return edge.rest_length;
            }
            let c = &topo.cells()[cell as usize];
            c.u_edges
                .iter()
                .chain(&c.v_edges)
                .map(|&k| edges[k as usize].rest_length)
                .fold(edge.rest_length, f64::max)
        };
        let worst = edges
            .iter()
            .enumerate()
            .map(|(e, edge)| {
                let l = (pred[edge.b as usize] - pred[edge.a as usize]).norm();
                (e, ((l - edge.rest_length) / reference(e, edge)).abs())
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
    pub(super) fn commit(
        &mut self,
        cloth: &Cloth,
        state: &mut ClothState,
        params: &StepParams,
        dt: f64,
    ) {
        std::mem::swap(&mut state.positions, &mut self.s.pred);
        for ((v, w), e) in state
            .velocities
            .iter_mut()
            .zip(&self.s.vel)
            .zip(&self.s.exit)
        {
            *v = w + e;
        }
        if params.internal.tension == Tension::Constraint {
            // This step's constraint forces: what the next step's targets read, and the force
            // at which the tensile hysteresis is committed.
            self.projection.edge_forces(dt, &mut self.s.p);
            let (widths, edges, p) = (cloth.edge_widths(), cloth.topology().edges(), &self.s.p);
            fill(&mut self.s.force_per_width, |e| {
                if edges[e].kind.is_axial() {
                    p[e] / widths[e]
                } else {
                    0.0
                }
            });
            // The targets the solve ended with (for the strain diagnostics).
            self.targets(cloth, state, params);
        }
        state.axial_force.copy_from_slice(&self.s.p);
        // The cells' shear angles at the end of the step, by the step's measure.
        let (cells, rest, pos) = (
            cloth.topology().cells(),
            cloth.cell_rest_angles(params.shear.measure),
            &state.positions,
        );
        fill(&mut self.s.shear, |c| {
            let q = cells[c].nodes.map(|k| pos[k as usize]);
            rest[c] - cell_angle(params.shear.measure, &q)
        });
        state.shear_angle.copy_from_slice(&self.s.shear);
        self.commit_hysteresis(cloth, state, params);
        state.time += dt;
    }

    /// Commit the hysteresis states at this step's forces, curvatures and shear angles.
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
                    st.update(cloth.yarn_materials().tensile(mats[e]), fpw[e]);
                }
            }
        }
        let shear = cloth.shear_loop();
        if shear.is_hysteretic() && params.shear.scale > 0.0 {
            let l = shear.clone().with_deadband(params.shear.deadband);
            for (st, &gamma) in state.shear.iter_mut().zip(&self.s.shear) {
                st.update(&l, gamma);
            }
        }
        if cloth.bending_hysteretic() && !self.s.node_bend.is_empty() {
            // The implicit model: each direction's curvature at the end of the step, the turn of
            // its grid line about the step's node normal over the mean rest length.
            let (axial, axial_edges, smats, edges, pos) = (
                cloth.bending_neighbours(),
                topo.axial_edges(),
                cloth.slot_materials(),
                topo.edges(),
                &state.positions,
            );
            for (i, slots) in state.bending.iter_mut().enumerate() {
                for dir in 0..2 {
                    let (after, before) = (axial[i][2 * dir], axial[i][2 * dir + 1]);
                    if after == NO_NODE || before == NO_NODE {
                        continue;
                    }
                    let l = 0.5
                        * (edges[axial_edges[i][2 * dir] as usize].rest_length
                            + edges[axial_edges[i][2 * dir + 1] as usize].rest_length);
                    let axis = self.s.node_bend[2 * i + dir].axis;
                    let eta = turn_and_gradient(
                        &axis,
                        &pos[before as usize],
                        &pos[i],
                        &pos[after as usize],
                    )
                    .0 / l;
                    let spindle = regularised(
                        table.bending(smats[i][2 * dir]),
                        params.bending.stick_slope,
                        params.bending.deadband,
                    );
                    slots[2 * dir].update(&spindle, eta);
                }
            }
        } else if cloth.bending_hysteretic()
            && !params.bending.off
            && params.bending.model == BendingModel::Thesis
        {
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
                            params.bending.stick_slope,
                            params.bending.deadband,
                        );
                        st.update(&spindle, eta[i][k]);
                    }
                }
            }
        }
    }

    /// Largest |ε − ε̄| of the axial edges after the update (stretch-only edges count only
    /// excess stretch).
    pub(super) fn max_strain_error(
        &self,
        cloth: &Cloth,
        state: &ClothState,
        params: &StepParams,
    ) -> f64 {
        self.axial_strain_errors(cloth, state, params)
            .map(|(_, err)| err)
            .fold(0.0, f64::max)
    }

    /// Each axial edge with its strain error |ε − ε̄| against the target length ε̄ of the last
    /// step (stretch-only edges: excess stretch only); before the first step, against the rest
    /// length.
    fn axial_strain_errors<'a>(
        &'a self,
        cloth: &'a Cloth,
        state: &'a ClothState,
        params: &'a StepParams,
    ) -> impl Iterator<Item = (u32, f64)> + 'a {
        let edges = cloth.topology().edges();
        let pos = &state.positions;
        let stepped = self.s.target.len() == edges.len();
        cloth.axial_edge_list().iter().map(move |&e| {
            let edge = &edges[e as usize];
            let l = (pos[edge.b as usize] - pos[edge.a as usize]).norm();
            let target = if stepped {
                self.s.target[e as usize]
            } else {
                edge.rest_length
            };
            let err = (l - target) / edge.rest_length;
            let err = match params.shape.axial_constraint {
                ConstraintKind::Equality => err.abs(),
                ConstraintKind::StretchOnly => err.max(0.0),
            };
            (e, err)
        })
    }

    /// Per node, the largest strain error of its axial edges (as [`StepReport`]'s
    /// `max_strain_error`, whose largest value this is): what a viewer colours the cloth by.
    ///
    /// [`StepReport`]: crate::StepReport
    pub fn node_strain_errors(
        &self,
        cloth: &Cloth,
        state: &ClothState,
        params: &StepParams,
    ) -> Vec<f32> {
        let edges = cloth.topology().edges();
        let mut out = vec![0.0_f32; state.positions.len()];
        for (e, err) in self.axial_strain_errors(cloth, state, params) {
            let edge = &edges[e as usize];
            for n in [edge.a, edge.b] {
                let v = &mut out[n as usize];
                *v = v.max(err as f32);
            }
        }
        out
    }
}
