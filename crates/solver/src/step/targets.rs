//! Stage 4a: what the shape stage holds the cloth to in this step — the axial edges' target
//! lengths from the tensile characteristics (thesis (25)), and each cell's shear constraint
//! linearised about the start of the step from the fabric's shear loop (`method.md` §2b).

use atelier_grid::NO_NODE;

use super::Solver;
use super::bending::regularised;
use super::par::fill;
use super::projection::{CellShear, NodeBend, SpindleRow, edge_strain};
use crate::bend_angle::{turn_and_gradient, turn_axis};
use crate::cloth::Cloth;
use crate::params::{BendingModel, ShapeMethod, StepParams};
use crate::shear_angle::cell_angle;
use crate::state::ClothState;

impl Solver {
    /// Target lengths of the axial edges, l⁰(1 + φ_θ(p/W)) through their hysteresis state (25)
    /// (diagonals keep their rest length: they are not constrained); returns the number of
    /// edges whose force lies beyond the measured range.
    pub(super) fn targets(
        &mut self,
        cloth: &Cloth,
        state: &ClothState,
        params: &StepParams,
    ) -> usize {
        let topo = cloth.topology();
        let edges = topo.edges();
        let (widths, mats, table) = (
            cloth.edge_widths(),
            cloth.edge_materials(),
            cloth.yarn_materials(),
        );
        let hysteresis = params.hysteresis && cloth.tensile_hysteretic();
        let s = &mut self.s;
        let p = &s.p;
        fill(&mut s.force_per_width, |e| {
            if edges[e].kind.is_axial() {
                p[e] / widths[e]
            } else {
                0.0
            }
        });
        let fpw = &s.force_per_width;
        let tensile = &state.tensile;
        fill(&mut s.target, |e| {
            let edge = &edges[e];
            if !edge.kind.is_axial() {
                return edge.rest_length;
            }
            let l = table.tensile(mats[e]);
            let strain = edge_strain(l, hysteresis.then(|| &tensile[e]), fpw[e]).0;
            edge.rest_length * (1.0 + strain)
        });
        (0..edges.len())
            .filter(|&e| edges[e].kind.is_axial() && !table.tensile(mats[e]).in_range(fpw[e]))
            .count()
    }

    /// Each cell's shear constraint for this step: the shear angle γ₀ at the start of the step
    /// (by `params.shear.measure`), the loop's stress τ₀ and tangent k there (through the
    /// cell's hysteresis state; the loop's centre line Gγ without hysteresis), times
    /// `shear.scale`; the constraint γ − (γ₀ − τ₀/k) = 0 with compliance 1/(k·S). Nothing when
    /// `shear.scale` is 0 (no shear rows at all).
    pub(super) fn cell_shear(&mut self, cloth: &Cloth, state: &ClothState, params: &StepParams) {
        let cells = cloth.topology().cells();
        if params.shear.scale == 0.0 {
            self.s.cell_shear.clear();
            return;
        }
        self.s.cell_shear.resize(cells.len(), CellShear::default());
        let rest = cloth.cell_rest_angles(params.shear.measure);
        let (l, lock, scale) = (
            cloth.shear_loop(),
            cloth.locking_angle(),
            params.shear.scale,
        );
        let hysteresis = params.hysteresis && l.is_hysteretic();
        let l = l.clone().with_deadband(params.shear.deadband);
        let (pos, states, measure) = (&state.positions, &state.shear, params.shear.measure);
        fill(&mut self.s.cell_shear, |c| {
            let cell = &cells[c];
            let q = cell.nodes.map(|k| pos[k as usize]);
            let gamma = rest[c] - cell_angle(measure, &q);
            let (tau, k) = if hysteresis {
                (states[c].stress(&l, gamma), states[c].tangent(&l, gamma))
            } else {
                (l.stiffness() * gamma, l.stiffness())
            };
            let (tau, k) = (tau * scale, k * scale);
            CellShear {
                rest: rest[c],
                offset: gamma - tau / k,
                compliance: 1.0 / (k * cell.area),
                lock,
            }
        });
    }
}

impl Solver {
    /// Each node's bending constraints for this step ([`BendingModel::Implicit`]): per grid
    /// direction with both neighbours, the turn C₀ of the line at the start of the step about
    /// its axis t̄ × n (n the node normal of stage 1; [`crate::bend_angle`]), the curvature
    /// η₀ = C₀/l̄, the spindle's moment per width m₀ and
    /// local slope k there (through the hysteresis state of the direction's `+` slot; Bη and B
    /// without hysteresis); the constraint C − (C₀ − m₀ l̄/k) = 0 with compliance l̄²/(k·S).
    /// Nothing with the thesis's bending model or `bending.off`.
    pub(super) fn node_bend(&mut self, cloth: &Cloth, state: &ClothState, params: &StepParams) {
        if params.bending.model != BendingModel::Implicit || params.bending.off {
            self.s.node_bend.clear();
            return;
        }
        let topo = cloth.topology();
        let n = topo.node_count();
        self.s.node_bend.resize(2 * n, NodeBend::default());
        let (axial, axial_edges, areas, mats, table, edges) = (
            cloth.bending_neighbours(),
            topo.axial_edges(),
            topo.node_areas(),
            cloth.slot_materials(),
            cloth.materials(),
            topo.edges(),
        );
        let hysteresis = params.hysteresis && cloth.bending_hysteretic();
        let (stick, band) = (params.bending.stick_slope, params.bending.deadband);
        // The exact spindle (`stick_slope` ∞, or ≤ 1, which `Spindle::with_stick_slope` reads as
        // ∞) has no steepest slope: its rows keep the local one.
        let steepest = params.bending.steepest_slope && stick.is_finite() && stick > 1.0;
        let spindle_rows =
            params.bending.spindle_rows && params.shape.method == ShapeMethod::Newton;
        let (pos, states, normal) = (&state.positions, &state.bending, &self.s.normal);
        fill(&mut self.s.node_bend, |k| {
            let (i, dir) = (k / 2, k % 2);
            let (after, before) = (axial[i][2 * dir], axial[i][2 * dir + 1]);
            if after == NO_NODE || before == NO_NODE {
                return NodeBend::default();
            }
            let l = 0.5
                * (edges[axial_edges[i][2 * dir] as usize].rest_length
                    + edges[axial_edges[i][2 * dir + 1] as usize].rest_length);
            let (xb, xa) = (&pos[before as usize], &pos[after as usize]);
            let axis = turn_axis(xb, &pos[i], xa, &normal[i]);
            let c0 = turn_and_gradient(&axis, xb, &pos[i], xa).0;
            let eta = c0 / l;
            let spindle = regularised(table.bending(mats[i][2 * dir]), stick, band);
            let b = spindle.rigidity();
            let spindle_row =
                (spindle_rows && hysteresis && spindle.is_hysteretic()).then(|| SpindleRow {
                    spindle,
                    state: states[i][2 * dir],
                    length: l,
                    area: areas[i],
                });
            let (m, slope) = if hysteresis && spindle.is_hysteretic() {
                let st = &states[i][2 * dir];
                let slope = if steepest {
                    stick * b
                } else {
                    // The local slope, by a central difference over a small part of the
                    // spindle's reversal width, within the spindle's own bounds [B, stick·B].
                    let h = 1e-3 * spindle.residual_moment() / b;
                    let local =
                        (st.moment(&spindle, eta + h) - st.moment(&spindle, eta - h)) / (2.0 * h);
                    local.clamp(b, stick.max(1.0) * b)
                };
                (st.moment(&spindle, eta), slope)
            } else {
                (b * eta, b)
            };
            NodeBend {
                axis,
                offset: c0 - m * l / slope,
                compliance: l * l / (slope * areas[i]),
                spindle_row,
            }
        });
    }
}
