//! Gridding a body from its range images (thesis §4.6.2): the silhouette split into 17 parts at
//! straight cuts between landmarks; each part gridded as a front and a back patch on the image
//! plane (Coons patch, then the improvement with the range image as the surface), the two joined
//! along the silhouette; cuts shared by the two parts they separate (matching node counts: the arm
//! root ring *is* the upper arm's top ring); the head, hands and feet closed as caps. Method and
//! deviations: `docs/grid-range.md`.

use std::collections::HashMap;
use std::time::Instant;

use atelier_grid::coons::arc_lengths;
use atelier_grid::improve::ImproveParams;

use super::body::RangeBody;
use super::field::{DepthField, Layer};
use super::side::View;
use crate::part::Part;

use builder::{Builder, Piece, cap, half_ring_nodes};

mod builder;

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
