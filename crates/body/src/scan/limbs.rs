//! Rings along the limbs (geodesic distance from where a limb leaves the trunk) and the
//! joints found on them: shoulder, elbow, wrist, hip joint, knee, ankle.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use super::ScanError;
use super::landmarks::Girth;
use super::slice::{Contour, Field};
use crate::model::V3;

/// Vertex neighbours (compressed rows).
pub(crate) struct Adjacency {
    start: Vec<usize>,
    next: Vec<u32>,
}

impl Adjacency {
    pub(crate) fn new(n: usize, triangles: &[[u32; 3]]) -> Adjacency {
        let mut pairs: Vec<(u32, u32)> = Vec::with_capacity(6 * triangles.len());
        for t in triangles {
            for e in 0..3 {
                let (a, b) = (t[e], t[(e + 1) % 3]);
                pairs.push((a, b));
                pairs.push((b, a));
            }
        }
        pairs.sort_unstable();
        pairs.dedup();
        let mut start = vec![0; n + 1];
        for &(a, _) in &pairs {
            start[a as usize + 1] += 1;
        }
        for k in 0..n {
            start[k + 1] += start[k];
        }
        Adjacency {
            start,
            next: pairs.into_iter().map(|p| p.1).collect(),
        }
    }

    pub(crate) fn of(&self, v: u32) -> &[u32] {
        &self.next[self.start[v as usize]..self.start[v as usize + 1]]
    }
}

#[derive(PartialEq)]
struct Item(f64, u32);
impl Eq for Item {}
impl PartialOrd for Item {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Item {
    fn cmp(&self, o: &Self) -> Ordering {
        o.0.total_cmp(&self.0).then(o.1.cmp(&self.1))
    }
}

/// A limb: the vertices reached from a seed without crossing its cut, their geodesic distance
/// (along edges) from the cut, and rings of equal distance.
#[derive(Clone, Debug)]
pub(crate) struct Limb {
    /// Ring distances.
    pub s: Vec<f64>,
    /// Centroid of each ring's largest contour.
    pub centre: Vec<V3>,
    /// Length of each ring's largest contour.
    pub girth: Vec<f64>,
    /// Contours longer than 2 cm in each ring.
    pub pieces: Vec<usize>,
    /// The limb's vertex farthest from the cut.
    pub tip: V3,
}

impl Limb {
    /// The limb on the side of `inside` that contains the vertex nearest `seed`.
    pub(crate) fn new(
        vertices: &[V3],
        triangles: &[[u32; 3]],
        adj: &Adjacency,
        inside: impl Fn(&V3) -> bool,
        seed: V3,
        step: f64,
        what: &'static str,
    ) -> Result<Limb, ScanError> {
        let n = vertices.len();
        let start = (0..n)
            .filter(|&k| inside(&vertices[k]))
            .min_by(|&a, &b| {
                (vertices[a] - seed)
                    .norm_squared()
                    .total_cmp(&(vertices[b] - seed).norm_squared())
            })
            .ok_or_else(|| ScanError::Landmark {
                what,
                why: "no vertex on the limb's side of its cut".into(),
            })?;
        // The component, and its border (vertices with a neighbour across the cut).
        let mut member = vec![false; n];
        member[start] = true;
        let mut stack = vec![start as u32];
        let mut heap = BinaryHeap::new();
        let mut dist = vec![f64::INFINITY; n];
        while let Some(v) = stack.pop() {
            let mut border = false;
            for &w in adj.of(v) {
                if !inside(&vertices[w as usize]) {
                    border = true;
                } else if !member[w as usize] {
                    member[w as usize] = true;
                    stack.push(w);
                }
            }
            if border {
                dist[v as usize] = 0.0;
                heap.push(Item(0.0, v));
            }
        }
        if heap.is_empty() {
            return Err(ScanError::Landmark {
                what,
                why: "the limb is not attached to the trunk".into(),
            });
        }
        while let Some(Item(d, v)) = heap.pop() {
            if d > dist[v as usize] {
                continue;
            }
            for &w in adj.of(v) {
                if member[w as usize] {
                    let nd = d + (vertices[w as usize] - vertices[v as usize]).norm();
                    if nd < dist[w as usize] {
                        dist[w as usize] = nd;
                        heap.push(Item(nd, w));
                    }
                }
            }
        }
        let (far, &max) = dist
            .iter()
            .enumerate()
            .filter(|(_, d)| d.is_finite())
            .max_by(|a, b| a.1.total_cmp(b.1))
            .expect("the start vertex");
        let tris: Vec<[u32; 3]> = triangles
            .iter()
            .filter(|t| t.iter().all(|&k| member[k as usize]))
            .copied()
            .collect();
        let s: Vec<f64> = (0..(max / step).floor() as usize)
            .map(|j| (j as f64 + 0.5) * step)
            .collect();
        let rings = Field::new(vertices, &tris, &dist).contours(&s);
        let mut centre = Vec::with_capacity(s.len());
        let mut girth = Vec::with_capacity(s.len());
        let mut pieces = Vec::with_capacity(s.len());
        for ring in &rings {
            let big = ring.iter().max_by(|a, b| a.length().total_cmp(&b.length()));
            centre.push(big.map_or(V3::zeros(), Contour::centroid));
            girth.push(big.map_or(0.0, Contour::length));
            pieces.push(ring.iter().filter(|c| c.length() > 0.02).count());
        }
        Ok(Limb {
            s,
            centre,
            girth,
            pieces,
            tip: vertices[far],
        })
    }

    /// First ring (beyond `from`) where the limb has parted into several pieces (fingers,
    /// toes), or the number of rings.
    fn split(&self, from: f64) -> usize {
        (0..self.s.len())
            .find(|&i| self.s[i] > from && self.pieces[i] >= 2)
            .unwrap_or(self.s.len())
    }

    /// The ring in `range` whose centre lies farthest from the line through the centres of
    /// rings `a` and `b`, with that distance.
    fn farthest_from_chord(
        &self,
        a: usize,
        b: usize,
        range: std::ops::Range<usize>,
    ) -> (usize, f64) {
        let (p, q) = (self.centre[a], self.centre[b]);
        let d = (q - p).normalize();
        range
            .map(|i| {
                let r = self.centre[i] - p;
                (i, (r - d * r.dot(&d)).norm())
            })
            .max_by(|x, y| x.1.total_cmp(&y.1))
            .unwrap_or((a, 0.0))
    }

    /// Index of the first ring at distance ≥ `s`.
    fn at(&self, s: f64) -> usize {
        self.s
            .partition_point(|&x| x < s)
            .min(self.s.len().saturating_sub(1))
    }
}

/// Least-squares line through points: (centroid, unit direction from the first point's side to
/// the last's).
fn fit_line(points: &[V3]) -> (V3, V3) {
    let c = points.iter().sum::<V3>() / points.len() as f64;
    let mut m = nalgebra::Matrix3::<f64>::zeros();
    for p in points {
        let r = p - c;
        m += r * r.transpose();
    }
    let e = m.symmetric_eigen();
    let k = e.eigenvalues.imax();
    let mut d: V3 = e.eigenvectors.column(k).into_owned();
    if d.dot(&(points[points.len() - 1] - points[0])) < 0.0 {
        d = -d;
    }
    (c, d)
}

pub(crate) struct ArmMarks {
    pub shoulder: V3,
    pub elbow: V3,
    pub wrist: V3,
    pub tip: V3,
}

pub(crate) struct LegMarks {
    pub hip: V3,
    pub knee: V3,
    pub ankle: V3,
    pub tip: V3,
}

/// Closest points of two lines (point, direction): the midpoint of their common perpendicular,
/// or `None` when they are within 10° of parallel.
fn closest_between(p: (V3, V3), q: (V3, V3)) -> Option<V3> {
    let (a, u) = p;
    let (b, v) = q;
    let w = a - b;
    let (uu, uv, vv) = (u.dot(&u), u.dot(&v), v.dot(&v));
    let den = uu * vv - uv * uv;
    if den < (10f64.to_radians().sin()).powi(2) * uu * vv {
        return None;
    }
    let t = (uv * v.dot(&w) - vv * u.dot(&w)) / den;
    let s = (uu * v.dot(&w) - uv * u.dot(&w)) / den;
    Some(0.5 * ((a + u * t) + (b + v * s)))
}

/// The highest point of the surface on the vertical line through (x, z), if any.
fn top_at(vertices: &[V3], triangles: &[[u32; 3]], x: f64, z: f64) -> Option<f64> {
    let mut best: Option<f64> = None;
    for t in triangles {
        let [a, b, c] = t.map(|k| vertices[k as usize]);
        let d = (b.x - a.x) * (c.z - a.z) - (c.x - a.x) * (b.z - a.z);
        if d.abs() < 1e-18 {
            continue;
        }
        let l1 = ((x - a.x) * (c.z - a.z) - (c.x - a.x) * (z - a.z)) / d;
        let l2 = ((b.x - a.x) * (z - a.z) - (x - a.x) * (b.z - a.z)) / d;
        if l1 >= 0.0 && l2 >= 0.0 && l1 + l2 <= 1.0 {
            let y = a.y + l1 * (b.y - a.y) + l2 * (c.y - a.y);
            best = Some(best.map_or(y, |m: f64| m.max(y)));
        }
    }
    best
}

/// The arm's joints from its rings: the wrist is the narrowest ring in the distal half before
/// the hand parts into fingers; the elbow is where the upper arm's axis (fitted to the ring
/// centres from 3 cm to 40 % of the way to the wrist) and the forearm's (the last 10 cm to 2 cm
/// before the wrist) come closest — for an arm within 10° of straight, the ring centre farthest
/// from the chord; the shoulder joint lies on the upper arm's axis, halfway up between the
/// armpit and the top of the shoulder above the axis at the armpit's height.
pub(crate) fn arm_marks(
    limb: &Limb,
    pit: V3,
    vertices: &[V3],
    triangles: &[[u32; 3]],
    what: &'static str,
) -> Result<ArmMarks, ScanError> {
    let split = limb.split(0.1);
    let i0 = limb.at(0.03);
    if split < i0 + 20 {
        return Err(ScanError::Landmark {
            what,
            why: format!(
                "the arm is {:.2} m long before it parts",
                limb.s.get(split).copied().unwrap_or(0.0)
            ),
        });
    }
    let w = (split / 2..split)
        .min_by(|&a, &b| limb.girth[a].total_cmp(&limb.girth[b]))
        .expect("non-empty");
    let sw = limb.s[w];
    let upper = fit_line(&limb.centre[i0..limb.at(0.4 * sw).max(i0 + 3)]);
    let fa = limb.at(sw - 0.1).max(i0 + 3);
    let fore = fit_line(&limb.centre[fa..limb.at(sw - 0.02).max(fa + 3)]);
    let elbow = closest_between(upper, fore)
        .unwrap_or_else(|| limb.centre[limb.farthest_from_chord(i0, w, i0 + 1..w).0]);
    let (c, d) = upper;
    if d.y.abs() < 0.2 {
        return Err(ScanError::Landmark {
            what,
            why: "the upper arm is within 12° of horizontal; the shoulder is found for arms hanging in an A-pose".into(),
        });
    }
    let at_pit = c + d * ((pit.y - c.y) / d.y);
    let top =
        top_at(vertices, triangles, at_pit.x, at_pit.z).ok_or_else(|| ScanError::Landmark {
            what,
            why: "no surface above the upper arm's axis at the armpit".into(),
        })?;
    let y = 0.5 * (pit.y + top);
    Ok(ArmMarks {
        shoulder: c + d * ((y - c.y) / d.y),
        elbow,
        wrist: limb.centre[w],
        tip: limb.tip,
    })
}

/// Ankle height above the floor as a fraction of the height (Drillis and Contini's segment
/// proportions, as tabulated by Winter, *Biomechanics and Motor Control of Human Movement*).
pub const ANKLE_HEIGHT: f64 = 0.039;

/// The leg's joints from its rings: the hip joint on the thigh's axis (fitted to the ring
/// centres from 5 to 25 cm below the crotch) at the hip line's height; the ankle on the leg's
/// centre line at [`ANKLE_HEIGHT`] × height above the floor; the knee on the centre line halfway
/// up between the two (thigh and shank are of equal length in the same tables: 0.245 and
/// 0.246 of the height).
pub(crate) fn leg_marks(
    limb: &Limb,
    hip: &Girth,
    floor: f64,
    height: f64,
    what: &'static str,
) -> Result<LegMarks, ScanError> {
    let split = limb.split(0.3);
    let i0 = limb.at(0.05);
    let i1 = limb.at(0.25);
    if split < i1 + 10 {
        return Err(ScanError::Landmark {
            what,
            why: format!(
                "the leg's surface reaches only {:.2} m from the crotch (is the body one connected surface?)",
                limb.s.last().copied().unwrap_or(0.0)
            ),
        });
    }
    let (c, d) = fit_line(&limb.centre[i0..i1]);
    if d.y.abs() < 0.5 {
        return Err(ScanError::Landmark {
            what,
            why: "the thigh is more than 60° from vertical".into(),
        });
    }
    let hip_joint = c + d * ((hip.height - c.y) / d.y);
    // The centre line at a height: the first ring centre (going down the leg) at or below it.
    let at_height = |y: f64| -> Result<V3, ScanError> {
        let k = (i0..split)
            .find(|&k| limb.centre[k].y <= y)
            .ok_or_else(|| ScanError::Landmark {
                what,
                why: format!("the leg's centre line does not reach {y:.3} m"),
            })?;
        let (a, b) = (limb.centre[k.max(1) - 1], limb.centre[k]);
        let t = if (a.y - b.y).abs() > 1e-12 {
            ((a.y - y) / (a.y - b.y)).clamp(0.0, 1.0)
        } else {
            1.0
        };
        Ok(a + (b - a) * t)
    };
    let ankle = at_height(floor + ANKLE_HEIGHT * height)?;
    let knee = at_height(0.5 * (hip_joint.y + ankle.y))?;
    Ok(LegMarks {
        hip: hip_joint,
        knee,
        ankle,
        tip: limb.tip,
    })
}
