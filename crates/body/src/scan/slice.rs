//! Level sets of a scalar field on a triangle mesh: horizontal sections (the field is the
//! height) and rings along a limb (the field is a geodesic distance from the limb's root).
//!
//! A vertex is "above" a level `s` when its value is `> s`, so every triangle the level crosses
//! has exactly two crossing edges and the crossing points chain, edge by edge, into loops (open
//! chains where the mesh has a border).

use crate::model::V3;

/// One connected curve of a level set.
#[derive(Clone, Debug)]
pub(crate) struct Contour {
    /// Points along the curve, in order.
    pub points: Vec<V3>,
    /// Whether the curve closes on itself.
    pub closed: bool,
}

impl Contour {
    /// Length along the points (closing segment included for a loop).
    pub fn length(&self) -> f64 {
        let n = self.points.len();
        let mut l: f64 = self.points.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
        if self.closed && n > 2 {
            l += (self.points[0] - self.points[n - 1]).norm();
        }
        l
    }

    /// Length-weighted centroid of the curve (for a loop: the centroid of its outline).
    pub fn centroid(&self) -> V3 {
        let n = self.points.len();
        let mut sum = V3::zeros();
        let mut w = 0.0;
        let segs = if self.closed { n } else { n.saturating_sub(1) };
        for k in 0..segs {
            let (a, b) = (self.points[k], self.points[(k + 1) % n]);
            let l = (b - a).norm();
            sum += (a + b) * (0.5 * l);
            w += l;
        }
        if w > 0.0 {
            sum / w
        } else {
            self.points.iter().sum::<V3>() / n.max(1) as f64
        }
    }
}

/// Per triangle the range of the field over its corners.
pub(crate) struct Field<'a> {
    vertices: &'a [V3],
    triangles: &'a [[u32; 3]],
    value: &'a [f64],
}

impl<'a> Field<'a> {
    /// The field `value` (one per vertex) on the mesh.
    pub fn new(vertices: &'a [V3], triangles: &'a [[u32; 3]], value: &'a [f64]) -> Self {
        Field {
            vertices,
            triangles,
            value,
        }
    }

    /// The level sets at `levels` (increasing), each a list of contours. Triangles are visited
    /// once each, for the levels their range spans.
    pub fn contours(&self, levels: &[f64]) -> Vec<Vec<Contour>> {
        // Per level: segments as pairs of (edge key, point).
        let mut segs: Vec<Vec<[(u64, V3); 2]>> = vec![Vec::new(); levels.len()];
        for t in self.triangles {
            let f = t.map(|k| self.value[k as usize]);
            let lo = f.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = f.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            if !(lo.is_finite() && hi.is_finite()) {
                continue;
            }
            // Levels s with lo <= s < hi (a vertex equal to s counts as below).
            let first = levels.partition_point(|&s| s < lo);
            let last = levels.partition_point(|&s| s < hi);
            for (li, &s) in levels.iter().enumerate().take(last).skip(first) {
                let mut pts = [(0u64, V3::zeros()); 2];
                let mut n = 0;
                for e in 0..3 {
                    let (a, b) = (t[e], t[(e + 1) % 3]);
                    let (fa, fb) = (self.value[a as usize], self.value[b as usize]);
                    if (fa > s) != (fb > s) && n < 2 {
                        let w = (s - fa) / (fb - fa);
                        let p = self.vertices[a as usize]
                            + (self.vertices[b as usize] - self.vertices[a as usize]) * w;
                        let key = (u64::from(a.min(b)) << 32) | u64::from(a.max(b));
                        pts[n] = (key, p);
                        n += 1;
                    }
                }
                if n == 2 {
                    segs[li].push(pts);
                }
            }
        }
        segs.into_iter().map(chain).collect()
    }
}

/// Chain segments sharing crossing edges into contours.
fn chain(segs: Vec<[(u64, V3); 2]>) -> Vec<Contour> {
    // (edge key, segment, end) sorted by key: the two ends on one edge are neighbours.
    let mut ends: Vec<(u64, u32, u8)> = Vec::with_capacity(2 * segs.len());
    for (i, s) in segs.iter().enumerate() {
        ends.push((s[0].0, i as u32, 0));
        ends.push((s[1].0, i as u32, 1));
    }
    ends.sort_unstable();
    // partner[2i + e] = the other segment end on the same edge.
    let mut partner = vec![u32::MAX; 2 * segs.len()];
    let mut k = 0;
    while k < ends.len() {
        let mut j = k + 1;
        while j < ends.len() && ends[j].0 == ends[k].0 {
            j += 1;
        }
        if j - k == 2 {
            let a = 2 * ends[k].1 + u32::from(ends[k].2);
            let b = 2 * ends[k + 1].1 + u32::from(ends[k + 1].2);
            partner[a as usize] = b;
            partner[b as usize] = a;
        }
        k = j;
    }
    let mut used = vec![false; segs.len()];
    let mut out = Vec::new();
    // Open chains first (from an end without partner), then loops.
    let starts: Vec<u32> = (0..2 * segs.len() as u32)
        .filter(|&e| partner[e as usize] == u32::MAX)
        .chain(0..2 * segs.len() as u32)
        .collect();
    for start in starts {
        let s0 = (start / 2) as usize;
        if used[s0] {
            continue;
        }
        let open = partner[start as usize] == u32::MAX;
        // Walk: enter segment s0 at end `start`, leave by the other end.
        let mut points = vec![segs[s0][(start % 2) as usize].1];
        let mut cur = start;
        loop {
            let s = (cur / 2) as usize;
            used[s] = true;
            let out_end = cur ^ 1;
            points.push(segs[s][(out_end % 2) as usize].1);
            let next = partner[out_end as usize];
            if next == u32::MAX || used[(next / 2) as usize] {
                break;
            }
            cur = next;
        }
        let closed = !open && points.len() > 2;
        if closed {
            points.pop(); // the first point again
        }
        out.push(Contour { points, closed });
    }
    out
}

/// Perimeter of the convex hull of points in the (x, z) plane (twice the distance for two
/// distinct points, 0 for one).
pub(crate) fn hull_perimeter_xz(points: impl Iterator<Item = V3>) -> f64 {
    let h = crate::build::convex_hull(points.map(|p| (p.x, p.z)).collect());
    if h.len() < 2 {
        return 0.0;
    }
    (0..h.len())
        .map(|k| {
            let (a, b) = (h[k], h[(k + 1) % h.len()]);
            (b.0 - a.0).hypot(b.1 - a.1)
        })
        .sum()
}

/// Whether the point (x, z) lies inside the contour projected on the (x, z) plane (even–odd).
pub(crate) fn inside_xz(c: &Contour, x: f64, z: f64) -> bool {
    let n = c.points.len();
    let mut inside = false;
    for k in 0..n {
        let (a, b) = (c.points[k], c.points[(k + 1) % n]);
        if (a.z > z) != (b.z > z) {
            let xc = a.x + (z - a.z) / (b.z - a.z) * (b.x - a.x);
            if x < xc {
                inside = !inside;
            }
        }
    }
    inside
}

/// (x, z) bounding box of points: [min x, max x, min z, max z].
pub(crate) fn bbox_xz<'a>(points: impl Iterator<Item = &'a V3>) -> [f64; 4] {
    let mut b = [
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    ];
    for p in points {
        b[0] = b[0].min(p.x);
        b[1] = b[1].max(p.x);
        b[2] = b[2].min(p.z);
        b[3] = b[3].max(p.z);
    }
    b
}

/// Whether two (x, z) boxes overlap.
pub(crate) fn boxes_overlap(a: &[f64; 4], b: &[f64; 4]) -> bool {
    a[0] <= b[1] && b[0] <= a[1] && a[2] <= b[3] && b[2] <= a[3]
}

/// Whether two closed contours overlap in the (x, z) projection: a point of either inside the
/// other (a crossing without any point inside is not detected; contours of one body section
/// are rounded and dense enough for that not to matter).
pub(crate) fn overlap_xz(a: &Contour, b: &Contour) -> bool {
    a.points.iter().any(|p| inside_xz(b, p.x, p.z))
        || b.points.iter().any(|p| inside_xz(a, p.x, p.z))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cube_sliced_gives_one_square_loop_of_the_right_perimeter() {
        // Unit cube, outward triangles.
        let v: Vec<V3> = (0..8)
            .map(|k| V3::new((k & 1) as f64, (k >> 1 & 1) as f64, (k >> 2 & 1) as f64))
            .collect();
        let quads = [
            [0, 4, 6, 2],
            [1, 3, 7, 5],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 2, 3, 1],
            [4, 5, 7, 6],
        ];
        let t: Vec<[u32; 3]> = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        let y: Vec<f64> = v.iter().map(|p| p.y).collect();
        let c = Field::new(&v, &t, &y).contours(&[0.3, 0.7]);
        for level in &c {
            assert_eq!(level.len(), 1);
            assert!(level[0].closed);
            assert!((level[0].length() - 4.0).abs() < 1e-12);
            assert!((hull_perimeter_xz(level[0].points.iter().copied()) - 4.0).abs() < 1e-12);
            let m = level[0].centroid();
            assert!((m.x - 0.5).abs() < 1e-12 && (m.z - 0.5).abs() < 1e-12);
            assert!(inside_xz(&level[0], 0.5, 0.5) && !inside_xz(&level[0], 1.5, 0.5));
        }
    }
}
