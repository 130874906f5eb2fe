//! Body-vertex planes: the body's vertices against the cloth's triangles (an addition; the
//! thesis's contact is node against body triangle only).
//!
//! Node contact keeps the cloth's nodes outside the body, not the faces between them. Where the
//! body is convex with a radius near the cell size (a shoulder point, a knee) a body vertex
//! pokes through the triangle between three nodes that are all outside, and a picture shows the
//! body there: 18 vertices up to 3.7 mm deep on the sewn silk dress (`docs/collision.md` §4c).
//!
//! Once per step, after the nodes' own planes are set (the transfer), every cloth triangle with
//! a node that has a plane is tested against the body vertices near it (the body's broad phase
//! around the triangle): where the line through a body vertex along its normal (end of step)
//! meets the triangle (the nodes at the start of the step) less than `plane_reach` in front of
//! the vertex — or behind it, by less than half the triangle's longest edge — the triangle is
//! `short` of the skin there (negative when it is farther). Its height at that point, Σ wₖ hₖ
//! (barycentric weights), grows by `short` when each node moves wₖ·short/Σw² along the
//! vertex's normal, the least such motion; each node's own plane is moved to lie that far
//! (divided by the cosine between the two normals) beyond where the node is, when that is in
//! front of the plane: the shape solve lifts a node short of it, and holds one with slack from
//! sagging further than its share. A node keeps its own normal: a plane per node, never two,
//! and no node loses the contact that holds it. Nodes whose own normal
//! differs from the vertex's by more than 60°, and nodes without a plane, are left alone; a
//! node met again in a collision pass takes that contact's plane (unlifted).
//!
//! Tried and not kept (the sewn silk dress to 0.4 s; the numbers in `docs/validation.md`):
//! giving the nodes the vertex's plane in place of their own, or lifting their planes after
//! every collision pass from their predicted end positions. Both left steps unconverged (plane
//! rows at up to 0.4) and multiplied the shape iterations; the once-per-step lift from the
//! start positions kept every step converged. Lifting only where the face is already short
//! (no hold) kicked the face up every few steps: the sewn silk skirt did not come to rest.
//!
//! Off by default (`ContactParams::vertex_planes`): with it the sewn skirt in cotton broad does
//! not come to rest either (`docs/validation.md`, "The body through the cloth's faces").

use crate::geom::{V3, line_triangle};
use crate::narrow::barycentric;

use super::{Collider, ContactPlane};

/// Least cosine between a body vertex's normal and a cloth triangle's (either side), and
/// between the vertex's normal and the own plane normal of a node it lifts.
const AGREE: f64 = 0.5;

impl Collider {
    /// Lift the contact planes of the cloth's nodes at `positions` (start of step) where a body
    /// vertex pokes through one of the cloth `triangles` (see the module documentation).
    /// Does nothing without a body, without planes, with one-sided contact (the garment passes
    /// through the body) or with `vertex_planes` off. Returns the nodes whose plane it lifted.
    pub fn vertex_planes(
        &mut self,
        positions: &[V3],
        inverse_masses: &[f64],
        triangles: &[[u32; 3]],
        planes: &mut [ContactPlane],
    ) -> usize {
        let p = self.params;
        let Some(body) = self.body.as_ref() else {
            return 0;
        };
        if !p.vertex_planes || p.one_sided || planes.len() != positions.len() {
            return 0;
        }
        let mut given = 0;
        let mut verts: Vec<u32> = Vec::new();
        let mut lift = vec![0.0f64; positions.len()];
        for t in triangles {
            if t.iter().all(|&k| planes[k as usize].normal == V3::zeros()) {
                continue;
            }
            let x = t.map(|k| positions[k as usize]);
            let centre = (x[0] + x[1] + x[2]) / 3.0;
            let radius = x.iter().map(|y| (y - centre).norm()).fold(0.0, f64::max);
            self.candidates.clear();
            body.broad.query(
                &centre,
                &centre,
                radius + p.plane_reach,
                &mut self.candidates,
            );
            if self.candidates.is_empty() {
                continue;
            }
            verts.clear();
            verts.extend(
                self.candidates
                    .iter()
                    .flat_map(|&b| body.triangles[b as usize]),
            );
            verts.sort_unstable();
            verts.dedup();
            let Some(nt) = (x[1] - x[0]).cross(&(x[2] - x[0])).try_normalize(0.0) else {
                continue;
            };
            let longest = (0..3)
                .map(|k| (x[(k + 1) % 3] - x[k]).norm())
                .fold(0.0, f64::max);
            for &v in &verts {
                let n = body.end_normals[v as usize];
                if n.dot(&nt).abs() < AGREE {
                    continue;
                }
                let q = body.end[v as usize];
                let Some(s) = line_triangle(&q, &n, [&x[0], &x[1], &x[2]]) else {
                    continue;
                };
                if s >= p.plane_reach || s < -0.5 * longest {
                    continue;
                }
                // Negative where the face is more than the skin in front of the vertex: then
                // the lifted plane lies behind the node and holds it from sagging further
                // than its share of that slack.
                let short = p.thickness - s;
                let h = q + n * s;
                let w = barycentric(&h, [&x[0], &x[1], &x[2]]);
                let w2: f64 = w.iter().map(|a| a * a).sum();
                for (&k, wk) in t.iter().zip(w) {
                    let k = k as usize;
                    let own = planes[k];
                    if inverse_masses[k] == 0.0 || wk <= 0.0 || own.normal.dot(&n) < AGREE {
                        continue;
                    }
                    let need = (positions[k] - own.point).dot(&own.normal)
                        + wk * short / w2 / own.normal.dot(&n);
                    lift[k] = lift[k].max(need);
                }
            }
        }
        for (k, l) in lift.iter().enumerate() {
            if *l > 0.0 {
                planes[k].point += planes[k].normal * *l;
                given += 1;
            }
        }
        self.stats.vertex_planes += given;
        given
    }
}
