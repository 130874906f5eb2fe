//! Stage 4a: the shape constraints' target lengths, from the tensile characteristics (axial
//! edges) and the shear characteristic (diagonals).

use atelier_fabric::Branch;

use super::Solver;
use super::par::fill;
use crate::cloth::Cloth;
use crate::params::{ConstraintKind, StepParams};
use crate::state::ClothState;

impl Solver {
    /// Target lengths: axial edges l⁰(1 + φ_θ(p/W)) through their hysteresis state (25); each
    /// cell's diagonals from the cell's axial targets and its shear angle γ(τ),
    /// τ = p₊/D₊ − p₋/D₋ (parallelogram geometry). Returns the number of extrapolated edges.
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
            cloth.materials(),
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
            let strain = if hysteresis {
                tensile[e].strain(l, fpw[e])
            } else {
                l.strain(Branch::Loading, fpw[e])
            };
            edge.rest_length * (1.0 + strain)
        });
        let extrapolated = (0..edges.len())
            .filter(|&e| edges[e].kind.is_axial() && !table.tensile(mats[e]).in_range(fpw[e]))
            .count();
        let shear_curve = cloth.shear_curve();
        let cells = topo.cells();
        let compliant = params.diagonal_constraint == ConstraintKind::Compliant;
        fill(&mut s.shear, |c| {
            if compliant {
                // The spring carries the shear; the targets keep the rest angle.
                return 0.0;
            }
            let cell = &cells[c];
            let [dp, dm] = cell
                .diagonals
                .map(|d| p[d as usize] / edges[d as usize].rest_length);
            shear_curve.angle(dp - dm)
        });
        for (c, cell) in cells.iter().enumerate() {
            let mean =
                |pair: [u32; 2], t: &[f64]| 0.5 * (t[pair[0] as usize] + t[pair[1] as usize]);
            let (a, b) = (mean(cell.u_edges, &s.target), mean(cell.v_edges, &s.target));
            let rest = |pair: [u32; 2]| {
                0.5 * (edges[pair[0] as usize].rest_length + edges[pair[1] as usize].rest_length)
            };
            let (a0, b0) = (rest(cell.u_edges), rest(cell.v_edges));
            let (alpha0, alpha) = (cell.rest_angle, cell.rest_angle - s.shear[c]);
            for (k, sign) in [(0, 1.0), (1, -1.0)] {
                let d = cell.diagonals[k] as usize;
                let now = a * a + b * b + sign * 2.0 * a * b * alpha.cos();
                let rest = a0 * a0 + b0 * b0 + sign * 2.0 * a0 * b0 * alpha0.cos();
                s.target[d] = edges[d].rest_length * (now.max(0.0) / rest).sqrt();
            }
        }
        extrapolated
    }
}
