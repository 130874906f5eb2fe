//! Stage 1a: edge directions and lengths, triangle and node normals.

use super::par::fill;
use super::{Solver, V3};
use crate::cloth::Cloth;
use crate::state::ClothState;

impl Solver {
    /// Edge directions and lengths, triangle and node normals (area-weighted) at the start of
    /// the step.
    pub(super) fn geometry(&mut self, cloth: &Cloth, state: &ClothState) {
        let topo = cloth.topology();
        let (edges, pos) = (topo.edges(), &state.positions);
        let s = &mut self.s;
        fill(&mut s.len, |e| {
            (pos[edges[e].b as usize] - pos[edges[e].a as usize]).norm()
        });
        let len = &s.len;
        fill(&mut s.dir, |e| {
            let d = pos[edges[e].b as usize] - pos[edges[e].a as usize];
            if len[e] > 0.0 {
                d / len[e]
            } else {
                V3::zeros()
            }
        });
        let tris = topo.triangles();
        fill(&mut s.tri_normal, |t| {
            let [a, b, c] = tris[t].map(|k| pos[k as usize]);
            (b - a).cross(&(c - a))
        });
        let tn = &s.tri_normal;
        // A pinned node takes the normal of the clamp it belongs to (its triangles whose nodes
        // are all pinned), so a clamp imposes its tangent plane on the bending at its edge;
        // with the free triangles mixed in, the clamp would act half as stiff and the
        // cantilever converge at first order only (docs/solver.md).
        let clamped = |t: u32| {
            tris[t as usize]
                .iter()
                .all(|&k| cloth.is_pinned(k as usize))
        };
        fill(&mut s.normal, |i| {
            let incident = topo.incident_triangles(i);
            let mut sum: V3 = V3::zeros();
            if cloth.is_pinned(i) {
                sum = incident
                    .iter()
                    .filter(|&&t| clamped(t))
                    .map(|&t| tn[t as usize])
                    .sum();
            }
            if sum == V3::zeros() {
                sum = incident.iter().map(|&t| tn[t as usize]).sum();
            }
            let norm = sum.norm();
            if norm > 0.0 { sum / norm } else { V3::zeros() }
        });
    }
}
