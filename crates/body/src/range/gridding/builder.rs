//! The body mesh built piece by piece: a part's front and back patches gridded on the image
//! plane and joined along the silhouette, cuts shared between neighbouring parts, and the caps that
//! close the head, hands and feet.

use std::collections::HashMap;

use atelier_grid::coons::{arc_lengths, coons, resample};
use atelier_grid::improve::{Surface, improve};
use atelier_grid::patch::Patch;

use crate::part::Part;
use crate::range::field::{DepthField, Layer};
use crate::range::side::View;

use super::{BodyGridParams, GridError, PatchReport, gerr};

/// The surface of one patch: free nodes lifted onto the front or back depth, fixed nodes at their
/// own depth.
pub(super) struct PatchSurface<'a> {
    pub(super) field: &'a DepthField,
    pub(super) layer: Layer,
    pub(super) fixed_z: Vec<Option<f64>>,
}

impl Surface for PatchSurface<'_> {
    fn lift(&self, node: usize, p: [f64; 2]) -> ([f64; 3], [[f64; 3]; 2]) {
        if let Some(z) = self.fixed_z[node] {
            return ([p[0], p[1], z], [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        }
        let (z, g) = self.field.sample(self.layer, p);
        ([p[0], p[1], z], [[1.0, 0.0, g[0]], [0.0, 1.0, g[1]]])
    }
}

/// A piece of a patch side.
#[derive(Clone, Debug)]
pub(super) enum Piece {
    /// Nodes shared by the front and back patch (an outline arc), in side order.
    Shared(Vec<u32>),
    /// A cut's front or back half, forwards (from its first to its second end) or not.
    Cut(usize, bool),
}

pub(super) struct Cut {
    pub(super) a: usize,
    pub(super) b: usize,
    pub(super) parent: Part,
    pub(super) child: Part,
    pub(super) front: Vec<u32>,
    pub(super) back: Vec<u32>,
}

pub(super) struct Builder<'a> {
    pub(super) field: &'a DepthField,
    pub(super) outline: Vec<[f64; 2]>,
    pub(super) nodes: Vec<[f64; 3]>,
    pub(super) vertex_part: Vec<Part>,
    pub(super) point_nodes: HashMap<usize, u32>,
    pub(super) cuts: Vec<Cut>,
    pub(super) triangles: Vec<[u32; 3]>,
    pub(super) triangle_part: Vec<Part>,
    pub(super) patches: Vec<PatchReport>,
    pub(super) params: BodyGridParams,
}

impl Builder<'_> {
    fn add_node(&mut self, p: [f64; 2], z: f64, part: Part) -> u32 {
        self.nodes.push([p[0], p[1], z]);
        self.vertex_part.push(part);
        (self.nodes.len() - 1) as u32
    }

    fn point(&mut self, idx: usize, part: Part) -> u32 {
        if let Some(&n) = self.point_nodes.get(&idx) {
            return n;
        }
        let p = self.outline[idx];
        let z = self.field.sample(Layer::Mid, p).0;
        let n = self.add_node(p, z, part);
        self.point_nodes.insert(idx, n);
        n
    }

    /// The outline from loop index `a` to `b` the short way round.
    pub(super) fn arc_poly(&self, a: usize, b: usize) -> Vec<[f64; 2]> {
        let n = self.outline.len();
        let fwd = (b + n - a) % n;
        let bwd = (a + n - b) % n;
        if fwd <= bwd {
            (0..=fwd).map(|k| self.outline[(a + k) % n]).collect()
        } else {
            (0..=bwd).map(|k| self.outline[(a + n - k) % n]).collect()
        }
    }

    pub(super) fn arc_indices(&self, a: usize, b: usize) -> Vec<usize> {
        let n = self.outline.len();
        let fwd = (b + n - a) % n;
        let bwd = (a + n - b) % n;
        if fwd <= bwd {
            (0..=fwd).map(|k| (a + k) % n).collect()
        } else {
            (0..=bwd).map(|k| (a + n - k) % n).collect()
        }
    }

    /// The polyline densified to a quarter pixel and lifted onto `layer`.
    fn lifted(&self, poly: &[[f64; 2]], layer: Layer) -> Vec<[f64; 3]> {
        let step = 0.25 * self.field.pixel;
        let mut out = Vec::new();
        for w in poly.windows(2) {
            let len = (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]);
            let k = ((len / step).ceil() as usize).max(1);
            for i in 0..k {
                let t = i as f64 / k as f64;
                let p = [
                    w[0][0] + t * (w[1][0] - w[0][0]),
                    w[0][1] + t * (w[1][1] - w[0][1]),
                ];
                out.push([p[0], p[1], self.field.sample(layer, p).0]);
            }
        }
        if let Some(&p) = poly.last() {
            out.push([p[0], p[1], self.field.sample(layer, p).0]);
        }
        out
    }

    pub(super) fn length(&self, poly: &[[f64; 2]], layer: Layer) -> f64 {
        *arc_lengths(&self.lifted(poly, layer))
            .last()
            .unwrap_or(&0.0)
    }

    /// `n` plane points evenly spaced by lifted (3D) arc length along `poly`.
    fn resample_lifted(&self, poly: &[[f64; 2]], n: usize, layer: Layer) -> Vec<[f64; 2]> {
        let pts = resample(&self.lifted(poly, layer), n);
        let mut out: Vec<[f64; 2]> = pts.iter().map(|p| [p[0], p[1]]).collect();
        out[0] = poly[0];
        out[n - 1] = poly[poly.len() - 1];
        out
    }

    /// Shared outline nodes from loop index `a` to `b`, `n` nodes with both ends.
    pub(super) fn arc(&mut self, a: usize, b: usize, n: usize, part: Part) -> Vec<u32> {
        let poly = self.arc_poly(a, b);
        let pts = self.resample_lifted(&poly, n, Layer::Mid);
        let mut ids = vec![self.point(a, part)];
        for &p in &pts[1..n - 1] {
            let z = self.field.sample(Layer::Mid, p).0;
            ids.push(self.add_node(p, z, part));
        }
        ids.push(self.point(b, part));
        ids
    }

    pub(super) fn make_cut(
        &mut self,
        a: usize,
        b: usize,
        n: usize,
        parent: Part,
        child: Part,
    ) -> usize {
        let seg = [self.outline[a], self.outline[b]];
        let ea = self.point(a, child);
        let eb = self.point(b, child);
        let mut halves = Vec::new();
        for layer in [Layer::Front, Layer::Back] {
            let pts = self.resample_lifted(&seg, n, layer);
            let mut ids = vec![ea];
            for &p in &pts[1..n - 1] {
                let z = self.field.sample(layer, p).0;
                ids.push(self.add_node(p, z, child));
            }
            ids.push(eb);
            halves.push(ids);
        }
        let back = halves.pop().unwrap_or_default();
        let front = halves.pop().unwrap_or_default();
        self.cuts.push(Cut {
            a,
            b,
            parent,
            child,
            front,
            back,
        });
        self.cuts.len() - 1
    }

    /// The longer of the front- and back-lifted lengths of the segment between the middles of
    /// two cuts (the part's centre line).
    pub(super) fn centre_length(&self, c1: usize, c2: usize) -> f64 {
        let mid = |c: &Cut| {
            let (p, q) = (self.outline[c.a], self.outline[c.b]);
            [0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])]
        };
        let seg = [mid(&self.cuts[c1]), mid(&self.cuts[c2])];
        self.length(&seg, Layer::Front)
            .max(self.length(&seg, Layer::Back))
    }

    fn resolve(&self, side: &[Piece], view: View) -> Vec<u32> {
        let mut out: Vec<u32> = Vec::new();
        for piece in side {
            let ids: Vec<u32> = match piece {
                Piece::Shared(ids) => ids.clone(),
                Piece::Cut(c, fwd) => {
                    let cut = &self.cuts[*c];
                    let mut v = if view == View::Front {
                        cut.front.clone()
                    } else {
                        cut.back.clone()
                    };
                    if !fwd {
                        v.reverse();
                    }
                    v
                }
            };
            if out.last().is_some() && out.last() == ids.first() {
                out.extend_from_slice(&ids[1..]);
            } else {
                out.extend_from_slice(&ids);
            }
        }
        out
    }

    /// Grid one part: front and back patch from the four sides (bottom and top left to right,
    /// left and right bottom to top).
    pub(super) fn part(&mut self, part: Part, sides: [Vec<Piece>; 4]) -> Result<(), GridError> {
        for view in [View::Front, View::Back] {
            let [b, t, l, r] = [0, 1, 2, 3].map(|k| self.resolve(&sides[k], view));
            let (nu, nv) = (b.len(), l.len());
            if t.len() != nu || r.len() != nv || nu < 2 || nv < 2 {
                return Err(gerr(
                    Some(part),
                    format!(
                        "opposite sides differ: bottom {nu}, top {}, left {nv}, right {} nodes",
                        t.len(),
                        r.len()
                    ),
                ));
            }
            if b[0] != l[0] || b[nu - 1] != r[0] || t[0] != l[nv - 1] || t[nu - 1] != r[nv - 1] {
                return Err(gerr(Some(part), "the sides do not meet at the corners"));
            }
            let p2 = |ids: &[u32]| -> Vec<[f64; 2]> {
                ids.iter()
                    .map(|&i| {
                        let p = self.nodes[i as usize];
                        [p[0], p[1]]
                    })
                    .collect()
            };
            let positions = coons(&p2(&b), &p2(&t), &p2(&l), &p2(&r));
            let mut ids = vec![u32::MAX; nu * nv];
            for i in 0..nu {
                ids[i] = b[i];
                ids[(nv - 1) * nu + i] = t[i];
            }
            for j in 0..nv {
                ids[j * nu] = l[j];
                ids[j * nu + nu - 1] = r[j];
            }
            let mut patch = Patch::full(nu, nv, false, positions);
            let layer = if view == View::Front {
                Layer::Front
            } else {
                Layer::Back
            };
            let fixed_z: Vec<Option<f64>> = ids
                .iter()
                .map(|&i| (i != u32::MAX).then(|| self.nodes[i as usize][2]))
                .collect();
            let surface = PatchSurface {
                field: self.field,
                layer,
                fixed_z,
            };
            let (energy, steps) = match self.params.improve {
                Some(ip) if nu > 2 && nv > 2 => {
                    let rep = improve(&mut patch, &surface, ip);
                    let first = rep.energy.first().copied().unwrap_or(0.0);
                    let last = rep.energy.last().copied().unwrap_or(first);
                    ((first, last), rep.energy.len() - 1)
                }
                _ => ((0.0, 0.0), 0),
            };
            for (id, &p) in ids.iter_mut().zip(&patch.positions) {
                if *id == u32::MAX {
                    let z = self.field.sample(layer, p).0;
                    *id = self.add_node(p, z, part);
                }
            }
            // Orientation: the patch's signed area in the image plane.
            let mut area = 0.0;
            for j in 0..nv - 1 {
                for i in 0..nu - 1 {
                    let q = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)]
                        .map(|(a, c)| patch.positions[c * nu + a]);
                    let d1 = [q[2][0] - q[0][0], q[2][1] - q[0][1]];
                    let d2 = [q[3][0] - q[1][0], q[3][1] - q[1][1]];
                    area += d1[0] * d2[1] - d1[1] * d2[0];
                }
            }
            let flip = (area > 0.0) != (view == View::Front);
            for j in 0..nv - 1 {
                for i in 0..nu - 1 {
                    let [a, b2, c, d] = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)]
                        .map(|(x, y)| ids[y * nu + x]);
                    let dist = |u: u32, v: u32| {
                        let (p, q) = (self.nodes[u as usize], self.nodes[v as usize]);
                        (0..3).map(|k| (p[k] - q[k]).powi(2)).sum::<f64>()
                    };
                    // At the patch corners the diagonal runs through the corner, so two shared
                    // outline sides never form a triangle of their own (the front and back patch
                    // would both hold it).
                    let (last_i, last_j) = (i + 2 == nu, j + 2 == nv);
                    let corner_ac = (i == 0 && j == 0) || (last_i && last_j);
                    let corner_bd = (last_i && j == 0) || (i == 0 && last_j);
                    let use_ac = if corner_ac != corner_bd {
                        corner_ac
                    } else {
                        dist(a, c) <= dist(b2, d)
                    };
                    let tris = if use_ac {
                        [[a, b2, c], [a, c, d]]
                    } else {
                        [[a, b2, d], [b2, c, d]]
                    };
                    for tri in tris {
                        let tri = if flip { [tri[0], tri[2], tri[1]] } else { tri };
                        self.triangles.push(tri);
                        self.triangle_part.push(part);
                    }
                }
            }
            self.patches.push(PatchReport {
                part,
                view,
                nu,
                nv,
                energy,
                steps,
            });
        }
        Ok(())
    }
}

/// Nodes per half ring (both silhouette ends included) for a ring of circumference `c` mm.
pub(super) fn half_ring_nodes(c: f64, chord: f64) -> usize {
    let r = c / (2.0 * std::f64::consts::PI);
    let n = (2.0 * std::f64::consts::PI * (r / (8.0 * chord)).sqrt()).ceil() as usize;
    n.max(6).div_ceil(2) + 1
}

/// A cap (head, hand, foot): the cut from `a` to `c` at the bottom, the outline around the
/// extremity from `a` to `c` split in thirds (by lifted length) into the left side, the top and
/// the right side.
pub(super) fn cap(
    b: &mut Builder,
    part: Part,
    bottom: usize,
    n_cut: usize,
) -> Result<(), GridError> {
    let (ia, ic) = (b.cuts[bottom].a, b.cuts[bottom].b);
    let idx = b.arc_indices(ia, ic);
    if idx.len() < 7 {
        return Err(gerr(
            Some(part),
            "the outline around the extremity is too short",
        ));
    }
    let poly: Vec<[f64; 2]> = idx.iter().map(|&i| b.outline[i]).collect();
    let lifted: Vec<[f64; 3]> = poly
        .iter()
        .map(|&p| [p[0], p[1], b.field.sample(Layer::Mid, p).0])
        .collect();
    let s = arc_lengths(&lifted);
    let total = *s.last().unwrap_or(&0.0);
    let at = |f: f64| {
        let k = s.partition_point(|&v| v < f * total);
        idx[k.clamp(1, idx.len() - 2)]
    };
    let (p1, p2) = (at(1.0 / 3.0), at(2.0 / 3.0));
    if p1 == p2 {
        return Err(gerr(
            Some(part),
            "the outline around the extremity is too short",
        ));
    }
    // Rows: enough for the sides and for the surface across the cap, from the cut's middle to
    // the extremity, lifted on the front and on the back (a toe or a face is much longer lifted
    // than its outline).
    let (qa, qc) = (b.outline[ia], b.outline[ic]);
    let across = [
        [0.5 * (qa[0] + qc[0]), 0.5 * (qa[1] + qc[1])],
        b.outline[at(0.5)],
    ];
    let len = (total / 3.0)
        .max(b.length(&across, Layer::Front))
        .max(b.length(&across, Layer::Back));
    let nv = ((len / b.params.axial_spacing_mm).round() as usize).max(1) + 1;
    let left = b.arc(ia, p1, nv, part);
    let top = b.arc(p1, p2, n_cut, part);
    let right = b.arc(ic, p2, nv, part);
    b.part(
        part,
        [
            vec![Piece::Cut(bottom, true)],
            vec![Piece::Shared(top)],
            vec![Piece::Shared(left)],
            vec![Piece::Shared(right)],
        ],
    )
}
