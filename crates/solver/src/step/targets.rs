//! Stage 4a: what the shape stage holds the cloth to in this step — the axial edges' target
//! lengths from the tensile characteristics (thesis (25)), and each cell's shear constraint
//! linearised about the start of the step from the fabric's shear loop (`method.md` §2b).

use atelier_fabric::Branch;

use super::Solver;
use super::par::fill;
use super::projection::CellShear;
use crate::cloth::Cloth;
use crate::params::StepParams;
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
        (0..edges.len())
            .filter(|&e| edges[e].kind.is_axial() && !table.tensile(mats[e]).in_range(fpw[e]))
            .count()
    }

    /// Each cell's shear constraint for this step: the shear angle γ₀ at the start of the step
    /// (by `params.shear_measure`), the loop's stress τ₀ and tangent k there (through the
    /// cell's hysteresis state; the loop's centre line Gγ without hysteresis), times
    /// `shear_scale`; the constraint γ − (γ₀ − τ₀/k) = 0 with compliance 1/(k·S). Nothing when
    /// `shear_scale` is 0 (no shear rows at all).
    pub(super) fn cell_shear(&mut self, cloth: &Cloth, state: &ClothState, params: &StepParams) {
        let cells = cloth.topology().cells();
        if params.shear_scale == 0.0 {
            self.s.cell_shear.clear();
            return;
        }
        self.s
            .cell_shear
            .resize(cells.len(), CellShear::default());
        let rest = cloth.cell_rest_angles(params.shear_measure);
        let (l, lock, scale) = (
            cloth.shear_loop(),
            cloth.locking_angle(),
            params.shear_scale,
        );
        let hysteresis = params.hysteresis && l.is_hysteretic();
        let l = l.clone().with_deadband(params.shear_deadband);
        let (pos, states, measure) = (&state.positions, &state.shear, params.shear_measure);
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
