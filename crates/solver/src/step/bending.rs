//! Stage 1b: the bending force (28)–(32) and its linearisation for the implicit solve, with the
//! step's regularisation of the bending characteristics; then gravity and the external forces.

use atelier_grid::{NO_NODE, SLOTS};

use super::par::fill;
use super::{Solver, V3};
use crate::cloth::Cloth;
use crate::params::{BendingModel, StepParams};
use crate::state::ClothState;

/// A bending characteristic with the step's regularisation: stick slope and reversal dead band
/// (a fraction of M₀/B).
pub(super) fn regularised(
    s: &atelier_fabric::Spindle,
    stick: f64,
    band: f64,
) -> atelier_fabric::Spindle {
    s.with_stick_slope(stick)
        .with_deadband(band * s.residual_moment() / s.rigidity())
}

impl Solver {
    /// Bending (28)–(32): curvature η = −2 n·(r_a − r_i)/l² per axial slot, moment per width
    /// from the spindle (peeked through the hysteresis state), node moment
    /// M = Σ_dir ½ Σ W_a m_a over directions with both neighbours (a free edge carries no moment),
    /// force F = n Σ (M_a − M)/l_a. Also the diagonal bending stiffness for the implicit term.
    /// With `bending.off`, or the implicit bending model (bending is then a constraint of the
    /// shape stage, `targets.rs`): no force and no stiffness.
    pub(super) fn bending(&mut self, cloth: &Cloth, state: &ClothState, params: &StepParams) {
        if params.bending.off || params.bending.model == BendingModel::Implicit {
            self.s.f_sum.iter_mut().for_each(|f| *f = V3::zeros());
            self.s.slot_coef.iter_mut().for_each(|k| *k = [0.0; SLOTS]);
            return;
        }
        let topo = cloth.topology();
        let (axial, areas, mats, table) = (
            cloth.bending_neighbours(),
            topo.node_areas(),
            cloth.slot_materials(),
            cloth.materials(),
        );
        let pos = &state.positions;
        let hysteresis = params.hysteresis && cloth.bending_hysteretic();
        let (stick, band) = (params.bending.stick_slope, params.bending.deadband);
        let s = &mut self.s;
        let normal = &s.normal;
        fill(&mut s.eta, |i| {
            let mut eta = [0.0; SLOTS];
            for k in 0..SLOTS {
                let a = axial[i][k];
                if a != NO_NODE {
                    let d = pos[a as usize] - pos[i];
                    eta[k] = -2.0 * normal[i].dot(&d) / d.norm_squared();
                }
            }
            eta
        });
        let eta = &s.eta;
        let bending_states = &state.bending;
        fill(&mut s.node_moment, |i| {
            let mut m = 0.0;
            for dir in 0..2 {
                let (k0, k1) = (2 * dir, 2 * dir + 1);
                if axial[i][k0] == NO_NODE || axial[i][k1] == NO_NODE {
                    continue;
                }
                for k in [k0, k1] {
                    let spindle = regularised(table.bending(mats[i][k]), stick, band);
                    let l = (pos[axial[i][k] as usize] - pos[i]).norm();
                    let per_width = if hysteresis {
                        bending_states[i][k].moment(&spindle, eta[i][k])
                    } else {
                        spindle.rigidity() * eta[i][k]
                    };
                    m += 0.5 * (areas[i] / l) * per_width;
                }
            }
            m
        });
        let moment = &s.node_moment;
        fill(&mut s.f_sum, |i| {
            let f: f64 = axial[i]
                .iter()
                .filter(|&&a| a != NO_NODE)
                .map(|&a| (moment[a as usize] - moment[i]) / (pos[a as usize] - pos[i]).norm())
                .sum();
            normal[i] * f
        });
        // Linearised bending for the implicit solve: per slot W·B/2 where the direction has both
        // neighbours (the node moment counts only those), and the slot length.
        // With hysteresis the curve after a turning point is steeper than B (up to the stick
        // slope): linearising with B alone leaves (stick − 1)·B explicit, which alternates
        // step by step on fine grids (`bending.implicit_stick_slope`).
        let steepest = |sp: &atelier_fabric::Spindle| {
            if params.bending.implicit_stick_slope
                && hysteresis
                && sp.is_hysteretic()
                && stick.is_finite()
            {
                stick
            } else {
                1.0
            }
        };
        fill(&mut s.slot_coef, |i| {
            let mut coef = [0.0; SLOTS];
            for dir in 0..2 {
                let (k0, k1) = (2 * dir, 2 * dir + 1);
                if axial[i][k0] == NO_NODE || axial[i][k1] == NO_NODE {
                    continue;
                }
                for k in [k0, k1] {
                    let l = (pos[axial[i][k] as usize] - pos[i]).norm();
                    let spindle = table.bending(mats[i][k]);
                    coef[k] = 0.5 * (areas[i] / l) * spindle.rigidity() * steepest(spindle);
                }
            }
            coef
        });
        fill(&mut s.slot_len, |i| {
            let mut len = [0.0; SLOTS];
            for k in 0..SLOTS {
                if axial[i][k] != NO_NODE {
                    len[k] = (pos[axial[i][k] as usize] - pos[i]).norm();
                }
            }
            len
        });
    }

    /// F_sum += μ g + external forces.
    pub(super) fn add_external(&mut self, cloth: &Cloth, g: V3) {
        let masses = cloth.masses();
        let ext = &self.external_forces;
        for (i, f) in self.s.f_sum.iter_mut().enumerate() {
            *f += g * masses[i];
            if let Some(x) = ext.get(i) {
                *f += x;
            }
        }
    }
}
