//! Building the mannequin's meshes from a [`BodyDescription`], scaling it to requested
//! [`Sizes`], and measuring the sizes back on the mesh.
//!
//! Each part is a tube swept along its axis: one ring of `around` vertices per cross-section
//! (the section's superellipse sampled at equal parameter steps), neighbouring rings joined by
//! two triangles per quad, and both end rings closed by a fan around a centre vertex. The mesh is
//! closed and its triangles turn outward (checked by the signed volume while building). Vertex
//! layout of a part: ring 0 (the proximal section) first, ring by ring, then the proximal and the
//! distal cap centres.
//!
//! Scaling (see `docs/body-model.md`): heights scale by `s = height / (crown − sole)` of the
//! drafted body, with the soles kept on `y = 0`. The torso parts (pelvis, abdomen, chest) are
//! scaled horizontally about the body's vertical axis by a factor `f(y)` that runs piecewise
//! linearly through `f_hip`, `f_waist`, `f_bust` at the three girth lines (constant below the hip
//! line and above the bust line); the factors are found by measuring the girths on the scaled mesh
//! and correcting them a few times (fixed point, converges to 1e-6 cm). Every other part keeps its
//! shape, scaled by `s` about its pivot, and its pivot follows its parent (the shoulders follow
//! the chest's width at their height, the hips the pelvis's).

use std::path::Path;
use std::sync::OnceLock;

use atelier_files::check::Validate;
use atelier_files::{ErrorKind, InvalidValue};

pub use crate::description::Sizes;
use crate::description::{BodyDescription, PartDescription};
use crate::model::{Mannequin, Part, PartMesh, V3};

/// The JIS 9AR description file, embedded.
const JIS_9AR_RON: &str = include_str!("../../../fixtures/bodies/jis_9ar.ron");

/// Building a mannequin failed.
#[derive(Debug, thiserror::Error)]
pub enum BodyError {
    /// The description is inconsistent (only possible for values built in code: a parsed
    /// description is already checked).
    #[error("invalid body description: {0}")]
    Description(InvalidValue),
    /// The requested sizes are not finite and positive, or lie too far from the drafted ones
    /// (each ratio must lie within [0.5, 2]).
    #[error("invalid sizes: {0}")]
    Sizes(InvalidValue),
}

/// Sizes measured on a mannequin's mesh, cm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeasuredSizes {
    /// Top of the head above the lowest vertex, cm.
    pub height_cm: f64,
    /// Bust girth: perimeter of the convex hull of the torso's horizontal section at the bust
    /// line, cm.
    pub bust_cm: f64,
    /// Waist girth (same, at the waist line), cm.
    pub waist_cm: f64,
    /// Hip girth (same, at the hip line), cm.
    pub hip_cm: f64,
}

/// Where the girth lines lie, as fractions of the height above the lowest vertex. Vertical
/// scaling keeps them, so a description's fractions measure every mannequin built from it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeasureLevels {
    /// Bust line.
    pub bust: f64,
    /// Waist line.
    pub waist: f64,
    /// Hip line.
    pub hip: f64,
}

/// The torso parts: sliced for the girths and scaled by the girth factors.
pub const TORSO: [Part; 3] = [Part::Chest, Part::Abdomen, Part::Pelvis];

/// One part as drawn (cm, description frame).
#[derive(Clone, Debug)]
struct RawPart {
    part: Part,
    vertices: Vec<V3>,
    triangles: Vec<[u32; 3]>,
    pivot: V3,
    limits: crate::model::JointLimits,
}

/// The local frame of a part: axis `a`, `u` (world x made perpendicular to the axis; world y
/// when the axis runs along x), `v` perpendicular to both, pointing forward (up when the axis
/// is horizontal and across x).
fn frame(axis: [f64; 3]) -> Option<(V3, V3, V3)> {
    let a = V3::from(axis);
    let a = a.try_normalize(1e-12)?;
    let mut u = V3::x() - a * a.x;
    if u.norm() < 1e-6 {
        u = V3::y() - a * a.y;
    }
    let u = u.try_normalize(1e-12)?;
    let mut v = a.cross(&u);
    if v.z < -1e-9 || (v.z.abs() <= 1e-9 && v.y < 0.0) {
        v = -v;
    }
    Some((a, u, v))
}

/// `sign(c)·|c|^e`.
fn spow(c: f64, e: f64) -> f64 {
    c.signum() * c.abs().powf(e)
}

/// The tube of one part, cm, outward.
fn raw_part(pd: &PartDescription, default_around: usize) -> Result<RawPart, InvalidValue> {
    let part = pd.part().ok_or_else(|| {
        InvalidValue::new(
            ErrorKind::UnknownVariant,
            "part",
            format!("unknown part `{}`", pd.part),
        )
    })?;
    let (a, u, v) = frame(pd.axis).ok_or_else(|| {
        InvalidValue::new(ErrorKind::OutOfRange, "axis", "the axis must not be zero")
    })?;
    let pivot = V3::from(pd.pivot);
    let m = pd.around.unwrap_or(default_around);
    let n = pd.sections.len();
    let mut vertices = Vec::with_capacity(n * m + 2);
    let mut centres = Vec::with_capacity(n);
    for s in &pd.sections {
        let c = pivot + a * s.at + u * s.centre.0 + v * s.centre.1;
        centres.push(c);
        let e = 2.0 / s.exponent;
        for j in 0..m {
            let t = std::f64::consts::TAU * j as f64 / m as f64;
            let (sn, cs) = t.sin_cos();
            vertices.push(c + u * (s.half_x * spow(cs, e)) + v * (s.half_z * spow(sn, e)));
        }
    }
    vertices.push(centres[0]);
    vertices.push(centres[n - 1]);
    let idx = |k: usize, j: usize| (k * m + j % m) as u32;
    let mut triangles = Vec::with_capacity(2 * n * m);
    for k in 0..n - 1 {
        for j in 0..m {
            triangles.push([idx(k, j), idx(k, j + 1), idx(k + 1, j)]);
            triangles.push([idx(k, j + 1), idx(k + 1, j + 1), idx(k + 1, j)]);
        }
    }
    let (c0, c1) = ((n * m) as u32, (n * m + 1) as u32);
    for j in 0..m {
        triangles.push([c0, idx(0, j + 1), idx(0, j)]);
        triangles.push([c1, idx(n - 1, j), idx(n - 1, j + 1)]);
    }
    if signed_volume(&vertices, &triangles) < 0.0 {
        for t in &mut triangles {
            t.swap(1, 2);
        }
    }
    Ok(RawPart {
        part,
        vertices,
        triangles,
        pivot,
        limits: pd.limits.joint_limits(),
    })
}

/// All 17 parts as drawn, in [`Part::ALL`] order.
fn raw_parts(d: &BodyDescription) -> Result<Vec<RawPart>, BodyError> {
    d.validate().map_err(BodyError::Description)?;
    let mut out = Vec::with_capacity(17);
    for p in Part::ALL {
        let (k, pd) = d
            .parts
            .iter()
            .enumerate()
            .find(|(_, pd)| pd.part() == Some(p))
            .ok_or_else(|| {
                BodyError::Description(InvalidValue::new(
                    ErrorKind::MissingField,
                    "parts",
                    format!("part `{}` is missing", p.name()),
                ))
            })?;
        out.push(
            raw_part(pd, d.resolution.around)
                .map_err(|e| BodyError::Description(e.within(&format!("parts[{k}]"))))?,
        );
    }
    Ok(out)
}

/// Lowest vertex and crown (the head's highest vertex) of parts in `Part::ALL` order.
fn sole_and_crown(parts: &[RawPart]) -> (f64, f64) {
    let sole = parts
        .iter()
        .flat_map(|p| p.vertices.iter().map(|q| q.y))
        .fold(f64::INFINITY, f64::min);
    let crown = parts[Part::Head.index()]
        .vertices
        .iter()
        .map(|q| q.y)
        .fold(f64::NEG_INFINITY, f64::max);
    (sole, crown)
}

/// The scaling of a built body: vertical factor, girth factors at the three lines.
#[derive(Clone, Copy, Debug)]
struct Scaling {
    sole: f64,
    s: f64,
    /// `(raw y, factor)` at the hip, waist and bust lines (increasing y).
    knots: [(f64, f64); 3],
}

impl Scaling {
    fn f(&self, y: f64) -> f64 {
        let k = &self.knots;
        if y <= k[0].0 {
            return k[0].1;
        }
        for w in k.windows(2) {
            if y <= w[1].0 {
                let t = (y - w[0].0) / (w[1].0 - w[0].0);
                return w[0].1 + t * (w[1].1 - w[0].1);
            }
        }
        k[2].1
    }

    fn torso(&self, p: &V3) -> V3 {
        let f = self.f(p.y);
        V3::new(f * p.x, self.s * (p.y - self.sole), f * p.z)
    }

    /// Where the raw point `p` of `part` goes.
    fn map(&self, parts: &[RawPart], part: Part, p: &V3) -> V3 {
        match part.parent() {
            _ if TORSO.contains(&part) => self.torso(p),
            None => self.torso(p),
            Some(parent) => {
                let pivot = parts[part.index()].pivot;
                self.map(parts, parent, &pivot) + (p - pivot) * self.s
            }
        }
    }
}

fn scaled(parts: &[RawPart], sc: &Scaling, which: &[Part]) -> Vec<PartMesh> {
    which
        .iter()
        .map(|&p| {
            let raw = &parts[p.index()];
            PartMesh {
                part: p,
                vertices: raw.vertices.iter().map(|q| sc.map(parts, p, q)).collect(),
                triangles: raw.triangles.clone(),
                pivot: sc.map(parts, p, &raw.pivot),
                limits: raw.limits,
            }
        })
        .collect()
}

impl Mannequin {
    /// Build the mannequin of a description scaled to `sizes` (see the module docs for how).
    /// Building at the description's own sizes keeps its shape except for the small girth
    /// corrections that make the measured girths exact.
    pub fn from_description(d: &BodyDescription, sizes: &Sizes) -> Result<Mannequin, BodyError> {
        sizes.check().map_err(BodyError::Sizes)?;
        for (name, want, drafted) in [
            ("height_cm", sizes.height_cm, d.sizes.height_cm),
            ("bust_cm", sizes.bust_cm, d.sizes.bust_cm),
            ("waist_cm", sizes.waist_cm, d.sizes.waist_cm),
            ("hip_cm", sizes.hip_cm, d.sizes.hip_cm),
        ] {
            let r = want / drafted;
            if !(0.5..=2.0).contains(&r) {
                return Err(BodyError::Sizes(InvalidValue::new(
                    ErrorKind::OutOfRange,
                    name,
                    format!(
                        "{want} cm is {r:.2} times the drafted {drafted} cm (0.5 to 2 allowed)"
                    ),
                )));
            }
        }
        let parts = raw_parts(d)?;
        let (sole, crown) = sole_and_crown(&parts);
        let s = sizes.height_cm / (crown - sole);
        let lv = &d.levels;
        let lines = [lv.hip_cm, lv.waist_cm, lv.bust_cm];
        let want = [sizes.hip_cm, sizes.waist_cm, sizes.bust_cm];
        let mut sc = Scaling {
            sole,
            s,
            knots: [(lines[0], 1.0), (lines[1], 1.0), (lines[2], 1.0)],
        };
        // Fixed point on the girth factors: the girths scale almost linearly with them.
        for _ in 0..8 {
            let torso = scaled(&parts, &sc, &TORSO);
            let mut worst: f64 = 0.0;
            for k in 0..3 {
                let y = s * (lines[k] - sole);
                let g = hull_girth(&torso, y);
                if g.is_nan() || g <= 0.0 {
                    let name = ["hip_cm", "waist_cm", "bust_cm"][k];
                    return Err(BodyError::Description(InvalidValue::new(
                        ErrorKind::Inconsistent,
                        format!("levels.{name}"),
                        format!("the line at y = {} cm cuts no torso part", lines[k]),
                    )));
                }
                sc.knots[k].1 *= want[k] / g;
                worst = worst.max((want[k] - g).abs());
            }
            if worst < 1e-7 {
                break;
            }
        }
        let mut meshes = scaled(&parts, &sc, &Part::ALL);
        for p in &mut meshes {
            for q in &mut p.vertices {
                *q *= 0.01;
            }
            p.pivot *= 0.01;
        }
        Ok(Mannequin {
            name: d.name.clone(),
            parts: meshes,
        })
    }

    /// The mannequin exactly as the description draws it (no scaling or girth correction;
    /// soles moved to `y = 0`); for checking a draft against its sizes.
    pub fn from_description_as_drawn(d: &BodyDescription) -> Result<Mannequin, BodyError> {
        let parts = raw_parts(d)?;
        let (sole, _) = sole_and_crown(&parts);
        Ok(Mannequin {
            name: d.name.clone(),
            parts: parts
                .into_iter()
                .map(|r| {
                    let m = |q: &V3| V3::new(q.x, q.y - sole, q.z) * 0.01;
                    PartMesh {
                        part: r.part,
                        vertices: r.vertices.iter().map(m).collect(),
                        triangles: r.triangles,
                        pivot: m(&r.pivot),
                        limits: r.limits,
                    }
                })
                .collect(),
        })
    }
}

impl BodyDescription {
    /// The girth lines of this description as fractions of its height (as drawn).
    pub fn measure_levels(&self) -> Result<MeasureLevels, BodyError> {
        let parts = raw_parts(self)?;
        let (sole, crown) = sole_and_crown(&parts);
        let f = |y: f64| (y - sole) / (crown - sole);
        Ok(MeasureLevels {
            bust: f(self.levels.bust_cm),
            waist: f(self.levels.waist_cm),
            hip: f(self.levels.hip_cm),
        })
    }
}

/// The JIS 9AR description (`fixtures/bodies/jis_9ar.ron`, embedded).
pub fn jis_9ar_description() -> BodyDescription {
    BodyDescription::parse(JIS_9AR_RON, Path::new("fixtures/bodies/jis_9ar.ron"))
        .expect("the embedded JIS 9AR description is valid (tested)")
}

/// The default mannequin: JIS L 4005 female 9AR (height 158, bust 83, waist 64, hip 91 cm),
/// built from the embedded description at its own sizes.
pub fn jis_9ar() -> Mannequin {
    static M: OnceLock<Mannequin> = OnceLock::new();
    M.get_or_init(|| {
        let d = jis_9ar_description();
        Mannequin::from_description(&d, &d.sizes)
            .expect("the embedded JIS 9AR description builds (tested)")
    })
    .clone()
}

/// The girth lines of the JIS 9AR description (used by [`measure`]).
pub fn jis_9ar_levels() -> MeasureLevels {
    static L: OnceLock<MeasureLevels> = OnceLock::new();
    *L.get_or_init(|| {
        jis_9ar_description()
            .measure_levels()
            .expect("the embedded JIS 9AR description builds (tested)")
    })
}

/// The sizes of a mannequin measured on its mesh, with the girth lines of the JIS 9AR
/// description (right for every mannequin built from it; use [`measure_at`] for others).
pub fn measure(m: &Mannequin) -> MeasuredSizes {
    measure_at(m, &jis_9ar_levels())
}

/// The sizes of a mannequin measured on its mesh: height = top of the head − lowest vertex;
/// girths = perimeter of the convex hull of the torso's (chest, abdomen, pelvis; arms excluded)
/// horizontal section at the lines `levels` (fractions of the height above the lowest vertex).
pub fn measure_at(m: &Mannequin, levels: &MeasureLevels) -> MeasuredSizes {
    let sole = m
        .parts
        .iter()
        .flat_map(|p| p.vertices.iter().map(|q| q.y))
        .fold(f64::INFINITY, f64::min);
    let crown = m
        .part(Part::Head)
        .vertices
        .iter()
        .map(|q| q.y)
        .fold(f64::NEG_INFINITY, f64::max);
    let height = crown - sole;
    let torso: Vec<PartMesh> = TORSO.iter().map(|&p| m.part(p).clone()).collect();
    let g = |f: f64| 100.0 * hull_girth(&torso, sole + f * height);
    MeasuredSizes {
        height_cm: 100.0 * height,
        bust_cm: g(levels.bust),
        waist_cm: g(levels.waist),
        hip_cm: g(levels.hip),
    }
}

/// Perimeter of the convex hull of the meshes' section by the plane at height `y` (units of the
/// meshes); 0 when the plane misses them.
pub fn hull_girth(parts: &[PartMesh], y: f64) -> f64 {
    let mut pts: Vec<(f64, f64)> = Vec::new();
    for p in parts {
        for t in &p.triangles {
            for e in 0..3 {
                let (a, b) = (
                    p.vertices[t[e] as usize],
                    p.vertices[t[(e + 1) % 3] as usize],
                );
                let (da, db) = (a.y - y, b.y - y);
                if da == 0.0 {
                    pts.push((a.x, a.z));
                } else if da * db < 0.0 {
                    let w = da / (da - db);
                    pts.push((a.x + w * (b.x - a.x), a.z + w * (b.z - a.z)));
                }
            }
        }
    }
    let hull = convex_hull(pts);
    if hull.len() < 2 {
        return 0.0;
    }
    (0..hull.len())
        .map(|k| {
            let (a, b) = (hull[k], hull[(k + 1) % hull.len()]);
            (b.0 - a.0).hypot(b.1 - a.1)
        })
        .sum()
}

/// Convex hull (Andrew's monotone chain), counter-clockwise, no repeated points.
pub(crate) fn convex_hull(mut pts: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    pts.retain(|p| p.0.is_finite() && p.1.is_finite());
    pts.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    pts.dedup();
    if pts.len() < 3 {
        return pts;
    }
    let cross = |o: (f64, f64), a: (f64, f64), b: (f64, f64)| {
        (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
    };
    let mut h: Vec<(f64, f64)> = Vec::with_capacity(2 * pts.len());
    for pass in 0..2 {
        let start = h.len();
        let it: Box<dyn Iterator<Item = &(f64, f64)>> = if pass == 0 {
            Box::new(pts.iter())
        } else {
            Box::new(pts.iter().rev())
        };
        for &p in it {
            while h.len() >= start + 2 && cross(h[h.len() - 2], h[h.len() - 1], p) <= 0.0 {
                h.pop();
            }
            h.push(p);
        }
        h.pop();
    }
    h
}

/// Signed volume of a triangle mesh (positive for a closed mesh with outward triangles).
pub fn signed_volume(vertices: &[V3], triangles: &[[u32; 3]]) -> f64 {
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|k| vertices[k as usize]);
            a.dot(&b.cross(&c))
        })
        .sum::<f64>()
        / 6.0
}

/// The first edge (as the directed pair of vertex indices found first, in triangle order)
/// that is not shared by exactly two triangles running it in opposite directions; `None` when
/// the mesh is closed and consistently oriented.
pub fn first_open_edge(triangles: &[[u32; 3]]) -> Option<(usize, [u32; 2])> {
    use std::collections::HashMap;
    let mut directed: HashMap<(u32, u32), usize> = HashMap::with_capacity(3 * triangles.len());
    for t in triangles {
        for e in 0..3 {
            *directed.entry((t[e], t[(e + 1) % 3])).or_insert(0) += 1;
        }
    }
    for (k, t) in triangles.iter().enumerate() {
        for e in 0..3 {
            let (a, b) = (t[e], t[(e + 1) % 3]);
            let fwd = directed.get(&(a, b)).copied().unwrap_or(0);
            let back = directed.get(&(b, a)).copied().unwrap_or(0);
            if a == b || fwd != 1 || back != 1 {
                return Some((k, [a, b]));
            }
        }
    }
    None
}

/// Generalised winding number of a closed mesh around `p` (1 inside an outward mesh, 0 outside).
pub fn winding_number(vertices: &[V3], triangles: &[[u32; 3]], p: &V3) -> f64 {
    let mut sum = 0.0;
    for t in triangles {
        let [a, b, c] = t.map(|k| vertices[k as usize] - p);
        let (la, lb, lc) = (a.norm(), b.norm(), c.norm());
        let num = a.dot(&b.cross(&c));
        let den = la * lb * lc + a.dot(&b) * lc + a.dot(&c) * lb + b.dot(&c) * la;
        sum += 2.0 * num.atan2(den);
    }
    sum / (4.0 * std::f64::consts::PI)
}

/// Whether `p` lies inside the closed, outward mesh.
pub fn contains(vertices: &[V3], triangles: &[[u32; 3]], p: &V3) -> bool {
    winding_number(vertices, triangles, p) > 0.5
}

#[cfg(test)]
mod tests;
