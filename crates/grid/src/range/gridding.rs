//! Gridding a body from its range images (thesis §4.6.2): the silhouette split into 17 parts at
//! straight cuts between landmarks; each part gridded as a front and a back patch on the image
//! plane (Coons patch, then the improvement with the range image as the surface), the two joined
//! along the silhouette; cuts shared by the two parts they separate (matching node counts: the arm
//! root ring *is* the upper arm's top ring); the head, hands and feet closed as caps. Method and
//! deviations: `docs/grid-range.md`.

use std::collections::HashMap;
use std::time::Instant;

use crate::coons::{arc_lengths, coons, resample};
use crate::improve::{ImproveParams, Surface, improve};
use crate::patch::Patch;

use super::body::RangeBody;
use super::field::{DepthField, Layer};
use super::part::Part;
use super::side::View;

/// How finely to grid a body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyGridParams {
    /// Target chord height (sagitta), mm, of the rings around each limb and the trunk: a ring
    /// of circumference `C` gets about `2π·√(R/(8·chord))` nodes, `R = C/2π`.
    pub chord_mm: f64,
    /// Target node spacing along the parts (and the sides of the caps), mm.
    pub axial_spacing_mm: f64,
    /// The improvement of every patch on its range image; `None` keeps the Coons grids.
    pub improve: Option<ImproveParams>,
}

impl Default for BodyGridParams {
    fn default() -> Self {
        Self {
            chord_mm: 0.8,
            axial_spacing_mm: 28.0,
            improve: Some(ImproveParams {
                relative_tolerance: 1e-5,
                max_iterations: 400,
                ..ImproveParams::default()
            }),
        }
    }
}

/// A ring of nodes shared by a part and its parent (a cut between two parts).
#[derive(Clone, Debug, PartialEq)]
pub struct BoundaryRing {
    /// The part nearer the pelvis.
    pub parent: Part,
    /// The other part.
    pub child: Part,
    /// The ring's vertices in order (closed loop, first not repeated): the front half from one
    /// silhouette end to the other, then the back half back.
    pub nodes: Vec<u32>,
}

/// The gridded body: one closed triangle mesh with a part label per triangle and vertex.
///
/// Frame: metres; x towards the body's left, y up (the range images' world y), z forward
/// (towards the front camera). Triangles are wound counter-clockwise seen from outside.
#[derive(Clone, Debug, PartialEq)]
pub struct BodyMesh {
    /// Vertex positions, m.
    pub positions: Vec<[f64; 3]>,
    /// Triangles (vertex indices), outward normals by the right-hand rule.
    pub triangles: Vec<[u32; 3]>,
    /// The part of each triangle.
    pub triangle_part: Vec<Part>,
    /// The part of each vertex (a ring shared by two parts belongs to the child).
    pub vertex_part: Vec<Part>,
    /// Joint pivots, m: for every part but the pelvis, the centre of the ring it shares with
    /// its parent.
    pub pivots: Vec<(Part, [f64; 3])>,
    /// The 16 rings between parts.
    pub rings: Vec<BoundaryRing>,
}

impl BodyMesh {
    /// The enclosed volume, m³ (positive for outward normals).
    pub fn signed_volume(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| self.positions[i as usize]);
                (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                    + a[2] * (b[0] * c[1] - b[1] * c[0]))
                    / 6.0
            })
            .sum()
    }

    /// Edge check: `(edges not in exactly two triangles, edges used twice in the same
    /// direction)`; `(0, 0)` for a closed, consistently oriented mesh.
    pub fn edge_defects(&self) -> (usize, usize) {
        let mut count: HashMap<(u32, u32), (u32, u32)> = HashMap::new();
        for t in &self.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let e = count.entry((a.min(b), a.max(b))).or_default();
                if a < b {
                    e.0 += 1;
                } else {
                    e.1 += 1;
                }
            }
        }
        let open = count.values().filter(|(f, b)| f + b != 2).count();
        let flipped = count
            .values()
            .filter(|(f, b)| f + b == 2 && *f != 1)
            .count();
        (open, flipped)
    }

    /// The mesh as Wavefront OBJ text (metres; one group per part), for viewing.
    pub fn to_obj(&self) -> String {
        let mut s =
            String::from("# atelier body gridded from range images (m; x left, y up, z forward)\n");
        for p in &self.positions {
            s.push_str(&format!("v {} {} {}\n", p[0], p[1], p[2]));
        }
        for part in Part::ALL {
            s.push_str(&format!("g {}\n", part.name()));
            for (t, &tp) in self.triangles.iter().zip(&self.triangle_part) {
                if tp == part {
                    s.push_str(&format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1));
                }
            }
        }
        s
    }

    /// Vertices per part.
    pub fn part_vertex_counts(&self) -> [usize; 17] {
        let mut n = [0; 17];
        for p in &self.vertex_part {
            n[p.index()] += 1;
        }
        n
    }

    /// Triangles per part.
    pub fn part_triangle_counts(&self) -> [usize; 17] {
        let mut n = [0; 17];
        for p in &self.triangle_part {
            n[p.index()] += 1;
        }
        n
    }
}

/// What the gridding did to one patch.
#[derive(Clone, Debug, PartialEq)]
pub struct PatchReport {
    /// The part.
    pub part: Part,
    /// Front or back patch.
    pub view: View,
    /// Nodes along u (around the part).
    pub nu: usize,
    /// Nodes along v (along the part).
    pub nv: usize,
    /// The improvement energy before and after (equal without improvement).
    pub energy: (f64, f64),
    /// Accepted improvement steps.
    pub steps: usize,
}

/// Summary of a gridding.
#[derive(Clone, Debug, PartialEq)]
pub struct BodyGridReport {
    /// One entry per patch (34).
    pub patches: Vec<PatchReport>,
    /// Vertices.
    pub nodes: usize,
    /// Triangles.
    pub triangles: usize,
    /// Wall time, s.
    pub seconds: f64,
}

/// Why a body could not be gridded.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("gridding the body{}: {message}", part.map(|p| format!(" ({})", p.name())).unwrap_or_default())]
pub struct GridError {
    /// The part concerned, if one.
    pub part: Option<Part>,
    /// What went wrong.
    pub message: String,
}

fn gerr(part: Option<Part>, message: impl Into<String>) -> GridError {
    GridError {
        part,
        message: message.into(),
    }
}

/// The surface of one patch: free nodes lifted onto the front or back depth, fixed nodes at their
/// own depth.
struct PatchSurface<'a> {
    field: &'a DepthField,
    layer: Layer,
    fixed_z: Vec<Option<f64>>,
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
enum Piece {
    /// Nodes shared by the front and back patch (an outline arc), in side order.
    Shared(Vec<u32>),
    /// A cut's front or back half, forwards (from its first to its second end) or not.
    Cut(usize, bool),
}

struct Cut {
    a: usize,
    b: usize,
    parent: Part,
    child: Part,
    front: Vec<u32>,
    back: Vec<u32>,
}

struct Builder<'a> {
    field: &'a DepthField,
    outline: Vec<[f64; 2]>,
    nodes: Vec<[f64; 3]>,
    vertex_part: Vec<Part>,
    point_nodes: HashMap<usize, u32>,
    cuts: Vec<Cut>,
    triangles: Vec<[u32; 3]>,
    triangle_part: Vec<Part>,
    patches: Vec<PatchReport>,
    params: BodyGridParams,
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
    fn arc_poly(&self, a: usize, b: usize) -> Vec<[f64; 2]> {
        let n = self.outline.len();
        let fwd = (b + n - a) % n;
        let bwd = (a + n - b) % n;
        if fwd <= bwd {
            (0..=fwd).map(|k| self.outline[(a + k) % n]).collect()
        } else {
            (0..=bwd).map(|k| self.outline[(a + n - k) % n]).collect()
        }
    }

    fn arc_indices(&self, a: usize, b: usize) -> Vec<usize> {
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

    fn length(&self, poly: &[[f64; 2]], layer: Layer) -> f64 {
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
    fn arc(&mut self, a: usize, b: usize, n: usize, part: Part) -> Vec<u32> {
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

    fn make_cut(&mut self, a: usize, b: usize, n: usize, parent: Part, child: Part) -> usize {
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
    fn centre_length(&self, c1: usize, c2: usize) -> f64 {
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
    fn part(&mut self, part: Part, sides: [Vec<Piece>; 4]) -> Result<(), GridError> {
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
fn half_ring_nodes(c: f64, chord: f64) -> usize {
    let r = c / (2.0 * std::f64::consts::PI);
    let n = (2.0 * std::f64::consts::PI * (r / (8.0 * chord)).sqrt()).ceil() as usize;
    n.max(6).div_ceil(2) + 1
}

/// Grid a body (see the module documentation).
pub fn grid_body(
    body: &RangeBody,
    params: &BodyGridParams,
) -> Result<(BodyMesh, BodyGridReport), GridError> {
    let start = Instant::now();
    if !(params.chord_mm > 0.0 && params.axial_spacing_mm > 0.0) {
        return Err(gerr(None, "chord_mm and axial_spacing_mm must be positive"));
    }
    let n = body.width * body.height;
    if body.front.len() != n || body.back.len() != n || body.width < 2 || body.height < 2 {
        return Err(gerr(None, "the depth maps do not match the image size"));
    }
    if !(body.pixel_size > 0.0 && body.pixel_size.is_finite()) {
        return Err(gerr(None, "the pixel size must be positive"));
    }
    let field = DepthField::new(body);
    let outline = field.outline();
    if outline.len() < 16 {
        return Err(gerr(None, "the silhouette is too small to grid"));
    }
    let mut b = Builder {
        field: &field,
        outline,
        nodes: Vec::new(),
        vertex_part: Vec::new(),
        point_nodes: HashMap::new(),
        cuts: Vec::new(),
        triangles: Vec::new(),
        triangle_part: Vec::new(),
        patches: Vec::new(),
        params: *params,
    };
    // Landmarks snapped to the outline.
    let mut lm: HashMap<&str, usize> = HashMap::new();
    let max_snap = 4.0 * body.pixel_size;
    for name in super::body::LANDMARKS {
        let p = body
            .landmark(name)
            .ok_or_else(|| gerr(None, format!("missing landmark `{name}`")))?;
        let (idx, d) = b
            .outline
            .iter()
            .enumerate()
            .map(|(i, q)| (i, (q[0] - p[0]).hypot(q[1] - p[1])))
            .fold(
                (0, f64::INFINITY),
                |acc, x| if x.1 < acc.1 { x } else { acc },
            );
        if d > max_snap {
            return Err(gerr(
                None,
                format!("landmark `{name}` lies {:.1} mm from the silhouette", d),
            ));
        }
        if let Some((other, _)) = lm.iter().find(|&(_, &i)| i == idx) {
            return Err(gerr(
                None,
                format!("landmarks `{other}` and `{name}` fall on the same silhouette point"),
            ));
        }
        lm.insert(name, idx);
    }
    let l = |name: &str| lm[name];
    let h = params.axial_spacing_mm;
    let chord = params.chord_mm;
    let circ = |b: &Builder, a: &str, c: &str| {
        let seg = [b.outline[l(a)], b.outline[l(c)]];
        b.length(&seg, Layer::Front) + b.length(&seg, Layer::Back)
    };
    let along = |b: &Builder, a: &str, c: &str| b.length(&b.arc_poly(l(a), l(c)), Layer::Mid);
    let count = |len: f64| ((len / h).round() as usize).max(1) + 1;

    // Node counts per half ring: limbs share theirs along the chain (arm root = arm).
    let mut n_arm = 3;
    let mut n_leg = 3;
    for s in ["l", "r"] {
        for (a, c) in [
            ("armpit", "shoulder"),
            ("elbow_in", "elbow_out"),
            ("wrist_in", "wrist_out"),
        ] {
            let cc = circ(&b, &format!("{a}_{s}"), &format!("{c}_{s}"));
            n_arm = n_arm.max(half_ring_nodes(cc, chord));
        }
        for (a, c) in [
            ("crotch", "thigh"),
            ("knee_in", "knee_out"),
            ("ankle_in", "ankle_out"),
        ] {
            let a = if a == "crotch" {
                "crotch".to_owned()
            } else {
                format!("{a}_{s}")
            };
            let cc = circ(&b, &a, &format!("{c}_{s}"));
            n_leg = n_leg.max(half_ring_nodes(cc, chord));
        }
    }
    // The caps' widest rings (across the outline at a quarter and three quarters of the way
    // round the extremity) need as many nodes as their cut provides.
    let cap_ring = |b: &Builder, a: &str, c: &str| {
        let idx = b.arc_indices(l(a), l(c));
        let poly: Vec<[f64; 2]> = idx.iter().map(|&i| b.outline[i]).collect();
        let lifted: Vec<[f64; 3]> = poly
            .iter()
            .map(|&p| [p[0], p[1], b.field.sample(Layer::Mid, p).0])
            .collect();
        let s = arc_lengths(&lifted);
        let total = *s.last().unwrap_or(&0.0);
        let at = |f: f64| poly[s.partition_point(|&v| v < f * total).min(poly.len() - 1)];
        let seg = [at(0.25), at(0.75)];
        b.length(&seg, Layer::Front) + b.length(&seg, Layer::Back)
    };
    for s in ["l", "r"] {
        let f = |x: &str| format!("{x}_{s}");
        n_arm = n_arm.max(half_ring_nodes(
            cap_ring(&b, &f("wrist_in"), &f("wrist_out")),
            chord,
        ));
        n_leg = n_leg.max(half_ring_nodes(
            cap_ring(&b, &f("ankle_in"), &f("ankle_out")),
            chord,
        ));
    }
    let n_head = half_ring_nodes(cap_ring(&b, "chin_r", "chin_l"), chord);
    let n_trunk = half_ring_nodes(
        circ(&b, "waist_r", "waist_l").max(circ(&b, "hip_r", "hip_l")),
        chord,
    );
    n_leg = n_leg.max((n_trunk - 1).div_ceil(2) + 1);
    let n_waist = 2 * (n_leg - 1) + 1;
    let mut n_neck = half_ring_nodes(
        circ(&b, "neck_r", "neck_l").max(circ(&b, "chin_r", "chin_l")),
        chord,
    )
    .max(n_head);
    if n_neck < n_waist && (n_waist - n_neck) % 2 == 1 {
        n_neck += 1;
    }
    // Each shoulder arc keeps two nodes at least; the parity of the waist count is kept.
    n_neck = n_neck.min(n_waist - 2);
    let n_shoulder = (n_waist - n_neck) / 2 + 1;

    // The cuts.
    use Part::*;
    let cut = |b: &mut Builder, a: &str, c: &str, n, parent, child| {
        b.make_cut(l(a), l(c), n, parent, child)
    };
    let c_chin = cut(&mut b, "chin_r", "chin_l", n_neck, Neck, Head);
    let c_neck = cut(&mut b, "neck_r", "neck_l", n_neck, Chest, Neck);
    let c_waist = cut(&mut b, "waist_r", "waist_l", n_waist, Abdomen, Chest);
    let c_hip = cut(&mut b, "hip_r", "hip_l", n_waist, Pelvis, Abdomen);
    struct Limb {
        root: usize,
        mid: usize,
        end: usize,
    }
    let mut arms = Vec::new();
    let mut legs = Vec::new();
    for (s, ua, fa, ha, th, sh, ft) in [
        (
            "l",
            UpperArmLeft,
            ForearmLeft,
            HandLeft,
            ThighLeft,
            ShinLeft,
            FootLeft,
        ),
        (
            "r",
            UpperArmRight,
            ForearmRight,
            HandRight,
            ThighRight,
            ShinRight,
            FootRight,
        ),
    ] {
        let f = |x: &str| format!("{x}_{s}");
        arms.push(Limb {
            root: cut(&mut b, &f("armpit"), &f("shoulder"), n_arm, Chest, ua),
            mid: cut(&mut b, &f("elbow_in"), &f("elbow_out"), n_arm, ua, fa),
            end: cut(&mut b, &f("wrist_in"), &f("wrist_out"), n_arm, fa, ha),
        });
        legs.push(Limb {
            root: cut(&mut b, "crotch", &f("thigh"), n_leg, Pelvis, th),
            mid: cut(&mut b, &f("knee_in"), &f("knee_out"), n_leg, th, sh),
            end: cut(&mut b, &f("ankle_in"), &f("ankle_out"), n_leg, sh, ft),
        });
    }

    // Pelvis: bottom = right thigh cut (outer → crotch) + left thigh cut (crotch → outer).
    {
        let nv = count(
            (0.5 * (along(&b, "thigh_r", "hip_r") + along(&b, "thigh_l", "hip_l")))
                .max(b.centre_length(c_hip, legs[0].root))
                .max(b.centre_length(c_hip, legs[1].root)),
        );
        let left = b.arc(l("thigh_r"), l("hip_r"), nv, Pelvis);
        let right = b.arc(l("thigh_l"), l("hip_l"), nv, Pelvis);
        b.part(
            Pelvis,
            [
                vec![
                    Piece::Cut(legs[1].root, false),
                    Piece::Cut(legs[0].root, true),
                ],
                vec![Piece::Cut(c_hip, true)],
                vec![Piece::Shared(left)],
                vec![Piece::Shared(right)],
            ],
        )?;
    }
    // Tubes between two cuts: bottom and top cuts run from the `left` outline to the `right`.
    let tube = |b: &mut Builder,
                part: Part,
                bottom: usize,
                top: usize,
                left: (&str, &str),
                right: (&str, &str)|
     -> Result<(), GridError> {
        let nv = count(
            (0.5 * (along(b, left.0, left.1) + along(b, right.0, right.1)))
                .max(b.centre_length(bottom, top)),
        );
        let ls = b.arc(l(left.0), l(left.1), nv, part);
        let rs = b.arc(l(right.0), l(right.1), nv, part);
        b.part(
            part,
            [
                vec![Piece::Cut(bottom, true)],
                vec![Piece::Cut(top, true)],
                vec![Piece::Shared(ls)],
                vec![Piece::Shared(rs)],
            ],
        )
    };
    tube(
        &mut b,
        Abdomen,
        c_hip,
        c_waist,
        ("hip_r", "waist_r"),
        ("hip_l", "waist_l"),
    )?;
    tube(
        &mut b,
        Neck,
        c_neck,
        c_chin,
        ("neck_r", "chin_r"),
        ("neck_l", "chin_l"),
    )?;
    // Chest: sides = torso side up to the armpit, then the arm root cut to the shoulder point;
    // top = shoulder, neck cut, shoulder.
    {
        let n_side =
            count(0.5 * (along(&b, "waist_r", "armpit_r") + along(&b, "waist_l", "armpit_l")))
                .max((count(b.centre_length(c_waist, c_neck)) + 1).saturating_sub(n_arm))
                .max(2);
        let side_r = b.arc(l("waist_r"), l("armpit_r"), n_side, Chest);
        let side_l = b.arc(l("waist_l"), l("armpit_l"), n_side, Chest);
        let sh_r = b.arc(l("shoulder_r"), l("neck_r"), n_shoulder, Chest);
        let sh_l = b.arc(l("neck_l"), l("shoulder_l"), n_shoulder, Chest);
        b.part(
            Chest,
            [
                vec![Piece::Cut(c_waist, true)],
                vec![
                    Piece::Shared(sh_r),
                    Piece::Cut(c_neck, true),
                    Piece::Shared(sh_l),
                ],
                vec![Piece::Shared(side_r), Piece::Cut(arms[1].root, true)],
                vec![Piece::Shared(side_l), Piece::Cut(arms[0].root, true)],
            ],
        )?;
    }
    for (k, s) in ["l", "r"].iter().enumerate() {
        let f = |x: &str| format!("{x}_{s}");
        let (ua, fa, ha) = if k == 0 {
            (UpperArmLeft, ForearmLeft, HandLeft)
        } else {
            (UpperArmRight, ForearmRight, HandRight)
        };
        let (th, sh, ft) = if k == 0 {
            (ThighLeft, ShinLeft, FootLeft)
        } else {
            (ThighRight, ShinRight, FootRight)
        };
        tube(
            &mut b,
            ua,
            arms[k].root,
            arms[k].mid,
            (&f("armpit"), &f("elbow_in")),
            (&f("shoulder"), &f("elbow_out")),
        )?;
        tube(
            &mut b,
            fa,
            arms[k].mid,
            arms[k].end,
            (&f("elbow_in"), &f("wrist_in")),
            (&f("elbow_out"), &f("wrist_out")),
        )?;
        tube(
            &mut b,
            th,
            legs[k].root,
            legs[k].mid,
            ("crotch", &f("knee_in")),
            (&f("thigh"), &f("knee_out")),
        )?;
        tube(
            &mut b,
            sh,
            legs[k].mid,
            legs[k].end,
            (&f("knee_in"), &f("ankle_in")),
            (&f("knee_out"), &f("ankle_out")),
        )?;
        cap(&mut b, ha, arms[k].end, n_arm)?;
        cap(&mut b, ft, legs[k].end, n_leg)?;
    }
    cap(&mut b, Head, c_chin, n_neck)?;

    // Rings, pivots, output in metres.
    let mut rings = Vec::new();
    let mut pivots = Vec::new();
    for c in &b.cuts {
        let mut nodes = c.front.clone();
        nodes.extend(c.back[1..c.back.len() - 1].iter().rev());
        let mut centre = [0.0; 3];
        for &n in &nodes {
            for (c, v) in centre.iter_mut().zip(b.nodes[n as usize]) {
                *c += v / nodes.len() as f64;
            }
        }
        pivots.push((c.child, centre.map(|v| v * 1e-3)));
        rings.push(BoundaryRing {
            parent: c.parent,
            child: c.child,
            nodes,
        });
    }
    pivots.sort_by_key(|p| p.0);
    let mesh = BodyMesh {
        positions: b.nodes.iter().map(|p| p.map(|v| v * 1e-3)).collect(),
        triangles: b.triangles,
        triangle_part: b.triangle_part,
        vertex_part: b.vertex_part,
        pivots,
        rings,
    };
    let report = BodyGridReport {
        patches: b.patches,
        nodes: mesh.positions.len(),
        triangles: mesh.triangles.len(),
        seconds: start.elapsed().as_secs_f64(),
    };
    Ok((mesh, report))
}

/// A cap (head, hand, foot): the cut from `a` to `c` at the bottom, the outline around the
/// extremity from `a` to `c` split in thirds (by lifted length) into the left side, the top and
/// the right side.
fn cap(b: &mut Builder, part: Part, bottom: usize, n_cut: usize) -> Result<(), GridError> {
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
