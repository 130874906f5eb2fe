//! The initial grid (thesis §4.4.1): nodes evenly spaced by arc length along boundary curves,
//! and the interior by a Coons patch — bilinearly blended transfinite interpolation of the four
//! boundary curves.
//!
//! Grids are stored row by row: node `(i, j)` (i along u, j along v) at index `j·nu + i`.

/// Points `n ≥ 2` evenly spaced by arc length along the polyline `points` (both ends included).
/// A polyline of zero length gives `n` copies of its first point.
pub fn resample<const D: usize>(points: &[[f64; D]], n: usize) -> Vec<[f64; D]> {
    assert!(
        n >= 2 && !points.is_empty(),
        "resample needs n ≥ 2 and a point"
    );
    let cumulative = arc_lengths(points);
    let total = *cumulative.last().unwrap_or(&0.0);
    let mut out = Vec::with_capacity(n);
    let mut seg = 0;
    for k in 0..n {
        let s = total * k as f64 / (n - 1) as f64;
        while seg + 2 < points.len() && cumulative[seg + 1] < s {
            seg += 1;
        }
        if points.len() == 1 || total == 0.0 {
            out.push(points[0]);
            continue;
        }
        let (s0, s1) = (cumulative[seg], cumulative[seg + 1]);
        let t = if s1 > s0 {
            ((s - s0) / (s1 - s0)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        out.push(lerp(points[seg], points[seg + 1], t));
    }
    // The last point exactly (no rounding drift).
    out[n - 1] = points[points.len() - 1];
    out
}

/// Cumulative arc length at every point of a polyline (starts at 0).
pub fn arc_lengths<const D: usize>(points: &[[f64; D]]) -> Vec<f64> {
    let mut acc = 0.0;
    let mut out = Vec::with_capacity(points.len());
    out.push(0.0);
    for w in points.windows(2) {
        acc += distance(w[0], w[1]);
        out.push(acc);
    }
    out
}

/// Euclidean distance.
pub fn distance<const D: usize>(a: [f64; D], b: [f64; D]) -> f64 {
    (0..D).map(|k| (b[k] - a[k]).powi(2)).sum::<f64>().sqrt()
}

fn lerp<const D: usize>(a: [f64; D], b: [f64; D], t: f64) -> [f64; D] {
    std::array::from_fn(|k| a[k] + t * (b[k] - a[k]))
}

/// The Coons patch of four boundary curves given as node lists: `bottom` (j = 0) and `top`
/// (j = nv − 1) with `nu` nodes each from left to right, `left` (i = 0) and `right` (i = nu − 1)
/// with `nv` nodes each from bottom to top. Corners must agree (`bottom[0] == left[0]` …); the
/// blending parameters are the index fractions `i/(nu−1)`, `j/(nv−1)`, so boundary nodes are
/// reproduced exactly and a rectangle with evenly spaced sides gives the uniform grid.
///
/// Returns `nu·nv` positions, row by row.
pub fn coons<const D: usize>(
    bottom: &[[f64; D]],
    top: &[[f64; D]],
    left: &[[f64; D]],
    right: &[[f64; D]],
) -> Vec<[f64; D]> {
    let (nu, nv) = (bottom.len(), left.len());
    assert!(
        nu >= 2 && nv >= 2 && top.len() == nu && right.len() == nv,
        "Coons needs matching opposite sides"
    );
    let (p00, p10, p01, p11) = (bottom[0], bottom[nu - 1], top[0], top[nu - 1]);
    let mut out = Vec::with_capacity(nu * nv);
    for j in 0..nv {
        let t = j as f64 / (nv - 1) as f64;
        for i in 0..nu {
            let s = i as f64 / (nu - 1) as f64;
            out.push(std::array::from_fn(|k| {
                (1.0 - t) * bottom[i][k] + t * top[i][k] + (1.0 - s) * left[j][k] + s * right[j][k]
                    - ((1.0 - s) * (1.0 - t) * p00[k]
                        + s * (1.0 - t) * p10[k]
                        + (1.0 - s) * t * p01[k]
                        + s * t * p11[k])
            }));
        }
    }
    // Boundary nodes exactly as given.
    for i in 0..nu {
        out[i] = bottom[i];
        out[(nv - 1) * nu + i] = top[i];
    }
    for j in 0..nv {
        out[j * nu] = left[j];
        out[j * nu + nu - 1] = right[j];
    }
    out
}

/// The Coons patch of a grid closed in u (a tube or an annulus): `bottom` and `top` are closed
/// loops of `nu` nodes each (the first not repeated at the end), `seam` the `nv` nodes of the
/// line `i = 0` from bottom to top. The interpolant is the ruled blend of the two loops plus the
/// seam's departure from its own chord, so an annulus with evenly spaced rings and a straight
/// radial seam gives the exact polar grid.
pub fn coons_periodic<const D: usize>(
    bottom: &[[f64; D]],
    top: &[[f64; D]],
    seam: &[[f64; D]],
) -> Vec<[f64; D]> {
    let (nu, nv) = (bottom.len(), seam.len());
    assert!(
        nu >= 3 && nv >= 2 && top.len() == nu,
        "a periodic Coons patch needs loops of equal length"
    );
    let (b0, t0) = (bottom[0], top[0]);
    let mut out = Vec::with_capacity(nu * nv);
    for (j, sj) in seam.iter().enumerate() {
        let t = j as f64 / (nv - 1) as f64;
        for i in 0..nu {
            out.push(std::array::from_fn(|k| {
                (1.0 - t) * bottom[i][k] + t * top[i][k] + sj[k] - ((1.0 - t) * b0[k] + t * t0[k])
            }));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use std::f64::consts::PI;

    fn line(a: [f64; 2], b: [f64; 2], n: usize) -> Vec<[f64; 2]> {
        resample(&[a, b], n)
    }

    #[test]
    fn rectangle_gives_the_exact_uniform_grid() {
        let (w, h, nu, nv) = (0.7, 0.4, 8, 5);
        let g = coons(
            &line([0.0, 0.0], [w, 0.0], nu),
            &line([0.0, h], [w, h], nu),
            &line([0.0, 0.0], [0.0, h], nv),
            &line([w, 0.0], [w, h], nv),
        );
        for j in 0..nv {
            for i in 0..nu {
                let p = g[j * nu + i];
                assert_relative_eq!(p[0], w * i as f64 / 7.0, epsilon = 1e-15);
                assert_relative_eq!(p[1], h * j as f64 / 4.0, epsilon = 1e-15);
            }
        }
    }

    #[test]
    fn annulus_gives_the_exact_polar_grid() {
        let (ri, ro, nu, nv) = (0.0635, 0.3175, 24, 7);
        let ring = |r: f64| -> Vec<[f64; 2]> {
            (0..nu)
                .map(|i| {
                    let a = 2.0 * PI * i as f64 / nu as f64;
                    [r * a.cos(), r * a.sin()]
                })
                .collect()
        };
        let g = coons_periodic(&ring(ri), &ring(ro), &line([ri, 0.0], [ro, 0.0], nv));
        for j in 0..nv {
            let r = ri + (ro - ri) * j as f64 / (nv - 1) as f64;
            for i in 0..nu {
                let a = 2.0 * PI * i as f64 / nu as f64;
                let p = g[j * nu + i];
                assert_relative_eq!(p[0], r * a.cos(), epsilon = 1e-15);
                assert_relative_eq!(p[1], r * a.sin(), epsilon = 1e-15);
            }
        }
    }

    #[test]
    #[allow(clippy::float_cmp, reason = "the last point is copied, exactly")]
    fn resampling_is_even_by_arc_length() {
        let poly = [[0.0, 0.0], [1.0, 0.0], [1.0, 3.0]];
        let r = resample(&poly, 5);
        let s = arc_lengths(&r);
        for w in s.windows(2) {
            assert_relative_eq!(w[1] - w[0], 1.0, epsilon = 1e-12);
        }
        assert_eq!(r[4], [1.0, 3.0]);
    }
}
