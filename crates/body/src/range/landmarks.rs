//! The 31 landmarks of [`super::LANDMARKS`] on the front silhouette of a rendered
//! body, found from the posed mesh and its part labels, the way `super::synthetic`
//! finds them on its analytic mannequin:
//!
//! - a **cut** between a parent part P and a child part C (chin, neck, waist, hip, elbow, wrist,
//!   knee, ankle) is the line through the *joint point* — the mean of the front-view pixel
//!   pairs where the labels P and C touch — perpendicular to the *axis* from P's to C's
//!   area-weighted centroid (for the ankle: the shin's principal axis), marched both ways to the
//!   silhouette; `_l` / `_r` on the trunk by x, `in` / `out` on the limbs by the side of the
//!   armpit (arms) or the crotch (legs);
//! - the **armpit** is the top of the gap between the trunk and the upper arm, scanning lines
//!   perpendicular to the trunk axis (pelvis → chest centroids) from the elbow's height up; the
//!   **shoulder** is the silhouette point across the arm from the armpit, perpendicular to the
//!   upper arm's principal axis;
//! - the **crotch** is the lowest point of the trunk's midline (marched down the trunk axis from
//!   the abdomen–pelvis joint point); the **thigh** point is the outer silhouette point on the
//!   line 20 mm above the crotch, perpendicular to the trunk axis.
//!
//! Every landmark is then checked to lie within 2 pixels of the background connected to the
//! image border (the outer outline `grid_body` traces), so a pose that closes the gap between an
//! arm and the trunk is a typed error rather than a failed gridding.

use std::collections::BTreeMap;

use super::{LANDMARKS, Part, View};

use super::{NO_PART, RangeError, Views};
use crate::model::LabelledMesh;

type P2 = [f64; 2];

fn add(a: P2, b: P2) -> P2 {
    [a[0] + b[0], a[1] + b[1]]
}
fn sub(a: P2, b: P2) -> P2 {
    [a[0] - b[0], a[1] - b[1]]
}
fn mul(a: P2, s: f64) -> P2 {
    [a[0] * s, a[1] * s]
}
fn dot(a: P2, b: P2) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}
fn cross(a: P2, b: P2) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}
fn perp(a: P2) -> P2 {
    [-a[1], a[0]]
}
fn unit(a: P2) -> Option<P2> {
    let n = a[0].hypot(a[1]);
    (n > 1e-12 && n.is_finite()).then(|| [a[0] / n, a[1] / n])
}

fn lerr(name: &str, message: impl Into<String>) -> RangeError {
    RangeError::Landmark {
        name: name.to_owned(),
        message: message.into(),
    }
}

/// Area-weighted centroid and principal axis (unit) of one part's surface, projected on the
/// image plane (mm).
#[derive(Clone, Copy, Debug)]
struct PartShape {
    centroid: P2,
    axis: P2,
}

fn part_shapes(mesh: &LabelledMesh) -> [Option<PartShape>; 17] {
    let mut acc = [[0.0f64; 6]; 17]; // area, Σ a·x, Σ a·y, Σ a·xx, Σ a·xy, Σ a·yy
    for (tri, part) in mesh.triangles.iter().zip(&mesh.triangle_part) {
        let [a, b, c] = tri.map(|i| mesh.vertices[i as usize] * 1e3);
        let area = 0.5 * (b - a).cross(&(c - a)).norm();
        let g = (a + b + c) / 3.0;
        let s = &mut acc[part.index()];
        s[0] += area;
        s[1] += area * g.x;
        s[2] += area * g.y;
        s[3] += area * g.x * g.x;
        s[4] += area * g.x * g.y;
        s[5] += area * g.y * g.y;
    }
    acc.map(|s| {
        if s[0] <= 0.0 {
            return None;
        }
        let (mx, my) = (s[1] / s[0], s[2] / s[0]);
        let (cxx, cxy, cyy) = (
            s[3] / s[0] - mx * mx,
            s[4] / s[0] - mx * my,
            s[5] / s[0] - my * my,
        );
        // Dominant eigenvector of the 2 × 2 covariance.
        let theta = 0.5 * (2.0 * cxy).atan2(cxx - cyy);
        Some(PartShape {
            centroid: [mx, my],
            axis: [theta.cos(), theta.sin()],
        })
    })
}

/// The front silhouette: mask valid in both views, the front part labels, and the background
/// connected to the border, on the front pixel grid.
struct Silhouette {
    w: usize,
    h: usize,
    px: f64,
    origin: P2,
    mask: Vec<bool>,
    label: Vec<u8>,
    outside: Vec<bool>,
}

impl Silhouette {
    fn new(views: &Views) -> Self {
        let (w, h) = (views.front.image.width, views.front.image.height);
        let mut mask = vec![false; w * h];
        for r in 0..h {
            for c in 0..w {
                mask[r * w + c] =
                    views.front.image.get(c, r) > 0 && views.back.image.get(w - 1 - c, r) > 0;
            }
        }
        // Background reachable from the border (4-connected).
        let mut outside = vec![false; w * h];
        let mut stack: Vec<usize> = Vec::new();
        for r in 0..h {
            for c in 0..w {
                if (r == 0 || c == 0 || r == h - 1 || c == w - 1) && !mask[r * w + c] {
                    outside[r * w + c] = true;
                    stack.push(r * w + c);
                }
            }
        }
        while let Some(k) = stack.pop() {
            let (c, r) = (k % w, k / w);
            let mut visit = |q: usize| {
                if !mask[q] && !outside[q] {
                    outside[q] = true;
                    stack.push(q);
                }
            };
            if c > 0 {
                visit(k - 1);
            }
            if c + 1 < w {
                visit(k + 1);
            }
            if r > 0 {
                visit(k - w);
            }
            if r + 1 < h {
                visit(k + w);
            }
        }
        Self {
            w,
            h,
            px: views.front.side.pixel_size,
            origin: [views.front.side.origin.0, views.front.side.origin.1],
            mask,
            label: views.front.part.clone(),
            outside,
        }
    }

    fn pixel(&self, p: P2) -> P2 {
        [
            (p[0] - self.origin[0]) / self.px,
            (self.origin[1] - p[1]) / self.px,
        ]
    }

    fn index(&self, p: P2) -> Option<usize> {
        let [c, r] = self.pixel(p).map(f64::round);
        (c >= 0.0 && r >= 0.0 && c < self.w as f64 && r < self.h as f64)
            .then(|| r as usize * self.w + c as usize)
    }

    fn inside(&self, p: P2) -> bool {
        self.index(p).is_some_and(|k| self.mask[k])
    }

    /// From `start` (inside) along the unit `dir`, the silhouette: the middle of the last step
    /// inside and the first outside (steps of a tenth of a pixel).
    fn march(&self, name: &str, start: P2, dir: P2) -> Result<P2, RangeError> {
        if !self.inside(start) {
            return Err(lerr(
                name,
                format!(
                    "the march to the silhouette starts outside the body, at ({:.1}, {:.1}) mm",
                    start[0], start[1]
                ),
            ));
        }
        let step = 0.1 * self.px;
        let max = (self.w + self.h) as f64 * self.px;
        let mut t = step;
        while t < max {
            if !self.inside(add(start, mul(dir, t))) {
                return Ok(add(start, mul(dir, t - 0.5 * step)));
            }
            t += step;
        }
        Err(lerr(name, "no silhouette along the march"))
    }

    /// After leaving the body at `edge` along `dir`, where it is entered again (within `max` mm).
    fn reentry(&self, edge: P2, dir: P2, max: f64) -> Option<P2> {
        let step = 0.25 * self.px;
        let mut t = step;
        while t < max {
            let q = add(edge, mul(dir, t));
            self.index(q)?;
            if self.inside(q) {
                return Some(q);
            }
            t += step;
        }
        None
    }

    /// The joint point of parts `a` and `b`: the mean of the midpoints of 4-adjacent front pixel
    /// pairs labelled `a` and `b`.
    fn joint(&self, a: Part, b: Part, name: &str) -> Result<P2, RangeError> {
        let (la, lb) = (a.index() as u8, b.index() as u8);
        let (mut s, mut n) = ([0.0, 0.0], 0usize);
        for r in 0..self.h {
            for c in 0..self.w {
                let k = r * self.w + c;
                let l = self.label[k];
                if l == NO_PART || !self.mask[k] || (l != la && l != lb) {
                    continue;
                }
                for (q, (cc, rr)) in [(k + 1, (c + 1, r)), (k + self.w, (c, r + 1))] {
                    if cc >= self.w || rr >= self.h || !self.mask[q] {
                        continue;
                    }
                    let m = self.label[q];
                    if (l == la && m == lb) || (l == lb && m == la) {
                        s[0] += c as f64 + 0.5 * (cc - c) as f64;
                        s[1] += r as f64 + 0.5 * (rr - r) as f64;
                        n += 1;
                    }
                }
            }
        }
        if n == 0 {
            return Err(lerr(
                name,
                format!(
                    "the {} and the {} do not touch in the front view",
                    a.name(),
                    b.name()
                ),
            ));
        }
        let (c, r) = (s[0] / n as f64, s[1] / n as f64);
        Ok([self.origin[0] + c * self.px, self.origin[1] - r * self.px])
    }

    /// Whether `p` lies within 2 pixels of the background connected to the border.
    fn on_outer_outline(&self, p: P2) -> bool {
        let [c, r] = self.pixel(p);
        let (ci, ri) = (c.round() as isize, r.round() as isize);
        for dr in -3..=3isize {
            for dc in -3..=3isize {
                let (cc, rr) = (ci + dc, ri + dr);
                if cc < 0 || rr < 0 || cc >= self.w as isize || rr >= self.h as isize {
                    continue;
                }
                let near = (cc as f64 - c).hypot(rr as f64 - r) <= 2.0;
                if near && self.outside[rr as usize * self.w + cc as usize] {
                    return true;
                }
            }
        }
        false
    }
}

/// Find the 31 landmarks of [`LANDMARKS`] on the front silhouette of `views` (rendered from
/// `mesh`), as front pixels `(column, row)`. The method is in the module documentation and in
/// `docs/body-range.md`; it assumes a roughly upright body whose arms and legs are apart in the
/// front view (an A-pose, a walk); otherwise it returns [`RangeError::Landmark`].
pub fn find_landmarks(
    mesh: &LabelledMesh,
    views: &Views,
) -> Result<BTreeMap<String, (f64, f64)>, RangeError> {
    if views.front.view != View::Front || views.back.view != View::Back {
        return Err(lerr("-", "the views are not a front and a back view"));
    }
    if mesh.triangle_part.len() != mesh.triangles.len()
        || mesh
            .triangles
            .iter()
            .flatten()
            .any(|&i| i as usize >= mesh.vertices.len())
    {
        return Err(RangeError::BadMesh(
            "triangles and labels do not match the vertices".into(),
        ));
    }
    let sil = Silhouette::new(views);
    let shapes = part_shapes(mesh);
    let shape = |p: Part, name: &str| {
        shapes[p.index()].ok_or_else(|| lerr(name, format!("the mesh has no {}", p.name())))
    };
    let mut out: BTreeMap<String, P2> = BTreeMap::new();
    use Part::*;
    let up = unit(sub(
        shape(Chest, "waist_l")?.centroid,
        shape(Pelvis, "hip_l")?.centroid,
    ))
    .ok_or_else(|| lerr("waist_l", "the chest and the pelvis have the same centroid"))?;

    // A cut through the joint point of `p` and `c`, perpendicular to `axis` (or to the line of
    // the centroids): the two silhouette points.
    let cut =
        |p: Part, c: Part, name: &str, axis: Option<P2>| -> Result<(P2, P2, P2), RangeError> {
            let j = sil.joint(p, c, name)?;
            let a = match axis {
                Some(a) => a,
                None => unit(sub(shape(c, name)?.centroid, shape(p, name)?.centroid))
                    .ok_or_else(|| lerr(name, "the parts have the same centroid"))?,
            };
            let n = perp(a);
            Ok((sil.march(name, j, n)?, sil.march(name, j, mul(n, -1.0))?, a))
        };

    // Trunk cuts: `_l` is the point with the larger x.
    for (p, c, base) in [
        (Neck, Head, "chin"),
        (Chest, Neck, "neck"),
        (Abdomen, Chest, "waist"),
        (Pelvis, Abdomen, "hip"),
    ] {
        let (q1, q2, _) = cut(p, c, &format!("{base}_l"), None)?;
        let (l, r) = if q1[0] >= q2[0] { (q1, q2) } else { (q2, q1) };
        out.insert(format!("{base}_l"), l);
        out.insert(format!("{base}_r"), r);
    }
    // Crotch: the lowest point of the trunk's midline.
    let jh = sil.joint(Pelvis, Abdomen, "crotch")?;
    let crotch = sil.march("crotch", jh, mul(up, -1.0))?;
    out.insert("crotch".into(), crotch);

    // `in` is the point on the same side of the cut's axis as `reference`.
    let in_out = |q1: P2, q2: P2, j: P2, a: P2, reference: P2| {
        let side = |q: P2| cross(a, sub(q, j)) > 0.0;
        if side(q1) == side(reference) {
            (q1, q2)
        } else {
            (q2, q1)
        }
    };
    for (s, sfx, ua, fa, ha, th, sh, ft) in [
        (
            1.0,
            "l",
            UpperArmLeft,
            ForearmLeft,
            HandLeft,
            ThighLeft,
            ShinLeft,
            FootLeft,
        ),
        (
            -1.0,
            "r",
            UpperArmRight,
            ForearmRight,
            HandRight,
            ThighRight,
            ShinRight,
            FootRight,
        ),
    ] {
        let name = |b: &str| format!("{b}_{sfx}");
        // Elbow and wrist cuts (joint points and axes; in/out after the armpit).
        let (e1, e2, ea) = cut(ua, fa, &name("elbow_out"), None)?;
        let je = sil.joint(ua, fa, &name("elbow_out"))?;
        let (w1, w2, wa) = cut(fa, ha, &name("wrist_out"), None)?;
        let jw = sil.joint(fa, ha, &name("wrist_out"))?;
        // Armpit: the top of the gap between the trunk and the arm, on lines perpendicular to
        // the trunk axis through the trunk's centre line (through the waist joint point).
        let out_dir = mul([up[1], -up[0]], s);
        let jwaist = sil.joint(Abdomen, Chest, &name("armpit"))?;
        let jneck = sil.joint(Chest, Neck, &name("armpit"))?;
        let (t0, t1) = (dot(sub(je, jwaist), up), dot(sub(jneck, jwaist), up));
        let reach = (sil.w + sil.h) as f64 * sil.px;
        // The gap must move continuously from line to line: when the trunk's edge jumps (the
        // arm touches the trunk and the march runs on through the arm), the gap has closed.
        let mut armpit = None;
        let mut prev_edge: Option<P2> = None;
        let mut t = t0;
        while t <= t1 {
            let base = add(jwaist, mul(up, t));
            let gap = if sil.inside(base) {
                let edge = sil.march(&name("armpit"), base, out_dir)?;
                let jump =
                    prev_edge.is_some_and(|p| dot(sub(edge, p), out_dir).abs() > 3.0 * sil.px);
                prev_edge = Some(edge);
                if jump {
                    None
                } else {
                    sil.reentry(edge, out_dir, reach)
                        .map(|q| mul(add(edge, q), 0.5))
                }
            } else {
                None
            };
            match gap {
                Some(g) => armpit = Some(g),
                None if armpit.is_some() => break,
                None => {}
            }
            t += 0.25 * sil.px;
        }
        let armpit = armpit.ok_or_else(|| {
            lerr(
                &name("armpit"),
                "no gap between the arm and the trunk above the elbow",
            )
        })?;
        out.insert(name("armpit"), armpit);
        // Shoulder: across the upper arm from the armpit.
        let arm = shape(ua, &name("shoulder"))?;
        let d = arm.axis;
        let foot = add(arm.centroid, mul(d, dot(sub(armpit, arm.centroid), d)));
        let mut n = perp(d);
        if dot(n, sub(foot, armpit)) < 0.0 {
            n = mul(n, -1.0);
        }
        out.insert(name("shoulder"), sil.march(&name("shoulder"), foot, n)?);
        let (ei, eo) = in_out(e1, e2, je, ea, armpit);
        out.insert(name("elbow_in"), ei);
        out.insert(name("elbow_out"), eo);
        let (wi, wo) = in_out(w1, w2, jw, wa, ei);
        out.insert(name("wrist_in"), wi);
        out.insert(name("wrist_out"), wo);

        // Legs.
        let (k1, k2, ka) = cut(th, sh, &name("knee_out"), None)?;
        let jk = sil.joint(th, sh, &name("knee_out"))?;
        let (ki, ko) = in_out(k1, k2, jk, ka, crotch);
        out.insert(name("knee_in"), ki);
        out.insert(name("knee_out"), ko);
        let shin = shape(sh, &name("ankle_out"))?;
        let foot_c = shape(ft, &name("ankle_out"))?.centroid;
        let mut sa = shin.axis;
        if dot(sa, sub(foot_c, shin.centroid)) < 0.0 {
            sa = mul(sa, -1.0);
        }
        let (a1, a2, _) = cut(sh, ft, &name("ankle_out"), Some(sa))?;
        let ja = sil.joint(sh, ft, &name("ankle_out"))?;
        let (ai, ao) = in_out(a1, a2, ja, sa, ki);
        out.insert(name("ankle_in"), ai);
        out.insert(name("ankle_out"), ao);
        // Thigh: the outer silhouette 20 mm above the crotch, perpendicular to the trunk axis.
        let start = add(crotch, mul(up, 20.0));
        out.insert(name("thigh"), sil.march(&name("thigh"), start, out_dir)?);
    }

    let mut px = BTreeMap::new();
    for name in LANDMARKS {
        let p = out
            .get(name)
            .copied()
            .ok_or_else(|| lerr(name, "not computed"))?;
        if !sil.on_outer_outline(p) {
            return Err(lerr(
                name,
                format!(
                    "({:.1}, {:.1}) mm is not on the outer silhouette (is a limb touching the trunk?)",
                    p[0], p[1]
                ),
            ));
        }
        let [c, r] = sil.pixel(p);
        px.insert(name.to_owned(), (c, r));
    }
    Ok(px)
}
