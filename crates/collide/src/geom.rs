//! Small geometry shared by the collision stages: the vector type, axis-aligned boxes and the
//! point of a triangle nearest to a point.

/// 3-vector (m, m/s).
pub type V3 = nalgebra::Vector3<f64>;

/// An axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Smallest corner.
    pub min: V3,
    /// Largest corner.
    pub max: V3,
}

impl Aabb {
    /// The empty box (the identity of [`Aabb::union`]).
    pub const EMPTY: Aabb = Aabb {
        min: V3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY),
        max: V3::new(f64::NEG_INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY),
    };

    /// The box of some points.
    pub fn from_points<'a>(points: impl IntoIterator<Item = &'a V3>) -> Self {
        points.into_iter().fold(Self::EMPTY, |b, p| b.including(p))
    }

    /// This box grown to include `p`.
    #[must_use]
    pub fn including(self, p: &V3) -> Self {
        Self {
            min: self.min.inf(p),
            max: self.max.sup(p),
        }
    }

    /// This box grown by `r` on every side.
    #[must_use]
    pub fn grown(self, r: f64) -> Self {
        let d = V3::repeat(r);
        Self {
            min: self.min - d,
            max: self.max + d,
        }
    }

    /// The smallest box holding both.
    #[must_use]
    pub fn union(self, other: &Aabb) -> Self {
        Self {
            min: self.min.inf(&other.min),
            max: self.max.sup(&other.max),
        }
    }

    /// Whether the boxes overlap (touching counts).
    pub fn overlaps(&self, other: &Aabb) -> bool {
        (0..3).all(|k| self.min[k] <= other.max[k] && other.min[k] <= self.max[k])
    }
}

/// The point of triangle `x` nearest to `p`, with its barycentric weights (Ericson, Real-Time
/// Collision Detection §5.1.5).
pub fn closest_point(p: &V3, x: [&V3; 3]) -> (V3, [f64; 3]) {
    let (a, b, c) = (x[0], x[1], x[2]);
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(&ap), ac.dot(&ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return (*a, [1.0, 0.0, 0.0]);
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(&bp), ac.dot(&bp));
    if d3 >= 0.0 && d4 <= d3 {
        return (*b, [0.0, 1.0, 0.0]);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (a + ab * v, [1.0 - v, v, 0.0]);
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(&cp), ac.dot(&cp));
    if d6 >= 0.0 && d5 <= d6 {
        return (*c, [0.0, 0.0, 1.0]);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (a + ac * w, [1.0 - w, 0.0, w]);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + (c - b) * w, [0.0, 1.0 - w, w]);
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    (a + ab * v + ac * w, [1.0 - v - w, v, w])
}

/// Where the line `p + s·n` meets the triangle `x` (edges included; Möller–Trumbore): `s`, or
/// `None` when it misses or runs parallel to the triangle's plane.
pub fn line_triangle(p: &V3, n: &V3, x: [&V3; 3]) -> Option<f64> {
    let e1 = x[1] - x[0];
    let e2 = x[2] - x[0];
    let h = n.cross(&e2);
    let det = e1.dot(&h);
    if det.abs() <= 1e-14 * e1.norm() * e2.norm() * n.norm() {
        return None;
    }
    let to = p - x[0];
    let u = to.dot(&h) / det;
    let q = to.cross(&e1);
    let w = n.dot(&q) / det;
    if u < 0.0 || w < 0.0 || u + w > 1.0 {
        return None;
    }
    Some(e2.dot(&q) / det)
}

/// Unit area-weighted vertex normals of `triangles` at `positions` into `out` (zero for a
/// vertex in no triangle).
pub fn vertex_normals(positions: &[V3], triangles: &[[u32; 3]], out: &mut Vec<V3>) {
    out.clear();
    out.resize(positions.len(), V3::zeros());
    for t in triangles {
        let [a, b, c] = t.map(|k| positions[k as usize]);
        let n = (b - a).cross(&(c - a));
        for &k in t {
            out[k as usize] += n;
        }
    }
    for n in out.iter_mut() {
        let len = n.norm();
        if len > 0.0 {
            *n /= len;
        }
    }
}
