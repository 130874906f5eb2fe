//! Outline geometry: path segments (lines, cubic Bézier curves, circular arcs) flattened to
//! polylines, and the polygon tests the pattern checks need.

use serde::{Deserialize, Serialize};

/// A point in a pattern file, cm.
pub type Point = (f64, f64);

/// One segment of a path, from the current point to its end.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Segment {
    /// A straight line to the point.
    Line(Point),
    /// A cubic Bézier curve: two control points, then the end.
    Cubic(Point, Point, Point),
    /// A circular arc about `centre` to `to` (at the same radius), counter-clockwise when `ccw`.
    Arc {
        /// Centre, cm.
        centre: Point,
        /// End point, cm.
        to: Point,
        /// Counter-clockwise (true) or clockwise.
        ccw: bool,
    },
}

impl Segment {
    /// The end point.
    pub fn end(&self) -> Point {
        match *self {
            Segment::Line(p) | Segment::Cubic(_, _, p) => p,
            Segment::Arc { to, .. } => to,
        }
    }

    /// Every coordinate, for finiteness checks.
    pub fn coordinates(&self) -> Vec<f64> {
        let pts: Vec<Point> = match *self {
            Segment::Line(p) => vec![p],
            Segment::Cubic(a, b, c) => vec![a, b, c],
            Segment::Arc { centre, to, .. } => vec![centre, to],
        };
        pts.into_iter().flat_map(|p| [p.0, p.1]).collect()
    }

    /// Append the segment, flattened, to `out` (whose last point is the segment's start).
    pub fn flatten_into(&self, out: &mut Vec<[f64; 2]>) {
        let start = *out.last().expect("a path starts at a point");
        match *self {
            Segment::Line(p) => out.push([p.0, p.1]),
            Segment::Cubic(c1, c2, e) => {
                const STEPS: usize = 64;
                for k in 1..=STEPS {
                    let t = k as f64 / STEPS as f64;
                    let s = 1.0 - t;
                    let w = [s * s * s, 3.0 * s * s * t, 3.0 * s * t * t, t * t * t];
                    out.push([
                        w[0] * start[0] + w[1] * c1.0 + w[2] * c2.0 + w[3] * e.0,
                        w[0] * start[1] + w[1] * c1.1 + w[2] * c2.1 + w[3] * e.1,
                    ]);
                }
            }
            Segment::Arc { centre, to, ccw } => {
                let (c, r0) = (
                    [centre.0, centre.1],
                    [start[0] - centre.0, start[1] - centre.1],
                );
                let r1 = [to.0 - c[0], to.1 - c[1]];
                let (a0, a1) = (r0[1].atan2(r0[0]), r1[1].atan2(r1[0]));
                let tau = std::f64::consts::TAU;
                let mut sweep = if ccw {
                    (a1 - a0).rem_euclid(tau)
                } else {
                    -(a0 - a1).rem_euclid(tau)
                };
                if sweep == 0.0 {
                    sweep = if ccw { tau } else { -tau };
                }
                let (rs, re) = (r0[0].hypot(r0[1]), r1[0].hypot(r1[1]));
                let steps = ((sweep.abs() / 1f64.to_radians()).ceil() as usize).max(2);
                for k in 1..=steps {
                    let t = k as f64 / steps as f64;
                    let (a, r) = (a0 + sweep * t, rs + (re - rs) * t);
                    out.push([c[0] + r * a.cos(), c[1] + r * a.sin()]);
                }
                *out.last_mut().expect("pushed") = [to.0, to.1];
            }
        }
    }
}

/// Flatten a path starting at `start`.
pub fn flatten(start: [f64; 2], path: &[Segment]) -> Vec<[f64; 2]> {
    let mut out = vec![start];
    for s in path {
        s.flatten_into(&mut out);
    }
    out
}

/// Signed area of a closed polygon (positive when counter-clockwise).
pub fn signed_area(poly: &[[f64; 2]]) -> f64 {
    0.5 * (0..poly.len())
        .map(|k| {
            let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<f64>()
}

/// Whether `p` lies inside the closed polygon (even–odd rule).
pub fn contains(poly: &[[f64; 2]], p: [f64; 2]) -> bool {
    let mut inside = false;
    let n = poly.len();
    for k in 0..n {
        let (a, b) = (poly[k], poly[(k + 1) % n]);
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if p[0] < x {
                inside = !inside;
            }
        }
    }
    inside
}

/// The first pair of non-adjacent edges of a closed polygon that cross (the smallest `(i, j)`,
/// `i < j`, in the order of `poly`), as the two points where the crossing edges start (indices
/// into `poly`), or `None` for a simple polygon. A sweep over the edges sorted by their lowest
/// x: only edges whose x ranges overlap are tested against each other, so an outline of n
/// points costs O(n log n) plus its overlapping pairs instead of n²/2 tests (the flattened
/// FreeSewing outlines have thousands of points, and the importer checks each dart it closes).
pub fn self_intersection(poly: &[[f64; 2]]) -> Option<(usize, usize)> {
    let n = poly.len();
    let end = |i: usize| poly[(i + 1) % n];
    let lo_x = |i: usize| poly[i][0].min(end(i)[0]);
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| lo_x(a).total_cmp(&lo_x(b)));
    let mut first: Option<(usize, usize)> = None;
    for (k, &e) in order.iter().enumerate() {
        let hi_x = poly[e][0].max(end(e)[0]);
        for &f in &order[k + 1..] {
            if lo_x(f) > hi_x {
                break;
            }
            let (i, j) = (e.min(f), e.max(f));
            if j < i + 2 || (i == 0 && j == n - 1) || first.is_some_and(|p| p <= (i, j)) {
                continue;
            }
            if edges_cross([poly[i], end(i)], [poly[j], end(j)]) {
                first = Some((i, j));
            }
        }
    }
    first
}

/// Whether two segments cross at a point interior to both (touching or collinear overlap is
/// not a crossing).
fn edges_cross([a, b]: [[f64; 2]; 2], [c, d]: [[f64; 2]; 2]) -> bool {
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    if c[1].max(d[1]) < a[1].min(b[1]) || c[1].min(d[1]) > a[1].max(b[1]) {
        return false;
    }
    let (d1, d2) = (cross(a, b, c), cross(a, b, d));
    let (d3, d4) = (cross(c, d, a), cross(c, d, b));
    d1 * d2 < 0.0 && d3 * d4 < 0.0
}

/// Distance from `p` to the segment `a–b`, and the parameter of the nearest point.
pub fn segment_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> (f64, f64) {
    let (ab, ap) = ([b[0] - a[0], b[1] - a[1]], [p[0] - a[0], p[1] - a[1]]);
    let len2 = ab[0] * ab[0] + ab[1] * ab[1];
    let t = if len2 > 0.0 {
        ((ap[0] * ab[0] + ap[1] * ab[1]) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let q = [a[0] + t * ab[0] - p[0], a[1] + t * ab[1] - p[1]];
    (q[0].hypot(q[1]), t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// The quadratic search the sweep replaced: every pair in the polygon's order.
    fn self_intersection_by_all_pairs(poly: &[[f64; 2]]) -> Option<(usize, usize)> {
        let n = poly.len();
        for i in 0..n {
            for j in i + 2..n {
                if i == 0 && j == n - 1 {
                    continue;
                }
                if edges_cross([poly[i], poly[(i + 1) % n]], [poly[j], poly[(j + 1) % n]]) {
                    return Some((i, j));
                }
            }
        }
        None
    }

    proptest::proptest! {
        /// The sweep finds the same first crossing as all pairs: random polygons of 3–60
        /// points (most cross themselves), star-shaped ones (simple) and ones with repeated
        /// coordinates (edges touching and collinear).
        #[test]
        fn the_sweep_finds_the_first_crossing_of_all_pairs(
            pts in proptest::collection::vec((-5i32..5, -5i32..5, 0.0f64..1.0), 3..60),
            star in proptest::bool::ANY,
            grid in proptest::bool::ANY,
        ) {
            let poly: Vec<[f64; 2]> = if star {
                let n = pts.len();
                pts.iter()
                    .enumerate()
                    .map(|(k, &(_, _, r))| {
                        let t = std::f64::consts::TAU * k as f64 / n as f64;
                        [(0.5 + r) * t.cos(), (0.5 + r) * t.sin()]
                    })
                    .collect()
            } else if grid {
                pts.iter().map(|&(x, y, _)| [f64::from(x), f64::from(y)]).collect()
            } else {
                pts.iter().map(|&(x, y, r)| [f64::from(x) + r, f64::from(y) - r]).collect()
            };
            proptest::prop_assert_eq!(self_intersection(&poly), self_intersection_by_all_pairs(&poly));
            if star {
                proptest::prop_assert_eq!(self_intersection(&poly), None);
            }
        }
    }

    #[test]
    fn arcs_and_cubics_flatten_onto_their_curves() {
        let half = flatten(
            [1.0, 0.0],
            &[Segment::Arc {
                centre: (0.0, 0.0),
                to: (-1.0, 0.0),
                ccw: true,
            }],
        );
        assert!(half.iter().all(|p| (p[0].hypot(p[1]) - 1.0).abs() < 1e-12));
        assert!(
            half.iter().all(|p| p[1] >= -1e-12),
            "went the short way round"
        );
        let cw = flatten(
            [1.0, 0.0],
            &[Segment::Arc {
                centre: (0.0, 0.0),
                to: (0.0, 1.0),
                ccw: false,
            }],
        );
        assert!(cw.len() > 200, "clockwise quarter to 90° is three quarters");
        // A cubic with collinear controls is the straight line.
        let c = flatten(
            [0.0, 0.0],
            &[Segment::Cubic((1.0, 0.0), (2.0, 0.0), (3.0, 0.0))],
        );
        assert_relative_eq!(c.last().unwrap()[0], 3.0);
        assert!(c.iter().all(|p| p[1] == 0.0));
    }

    #[test]
    fn polygon_tests() {
        let square = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        assert_relative_eq!(signed_area(&square), 1.0);
        assert!(contains(&square, [0.5, 0.5]) && !contains(&square, [1.5, 0.5]));
        assert_eq!(self_intersection(&square), None);
        let bow = [[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]];
        assert!(self_intersection(&bow).is_some());
    }
}
