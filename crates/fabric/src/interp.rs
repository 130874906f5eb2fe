//! Monotone piecewise-cubic Hermite interpolation (Fritsch & Carlson 1980, with the three-point
//! end slopes of Fritsch & Butland 1984 as used by SciPy's `PchipInterpolator`), for resampling
//! measured curves; and a least-squares straight line.
//!
//! Measured KES curves arrive as a few dozen digitised points. They are interpolated with PCHIP,
//! which never overshoots monotone data, then resampled once into the dense tables the model
//! looks values up in (see [`crate::tensile::TensileLoop`]).

/// A monotone cubic interpolant through `(x, y)` with `x` strictly increasing and `y`
/// non-decreasing. Outside `[x₀, xₙ]` it continues linearly with the end slopes.
#[derive(Clone, Debug)]
pub(crate) struct Pchip {
    x: Vec<f64>,
    y: Vec<f64>,
    slope: Vec<f64>,
}

impl Pchip {
    /// Build from points; the caller has validated them (at least two, `x` strictly increasing).
    pub(crate) fn new(points: &[(f64, f64)]) -> Self {
        let x: Vec<f64> = points.iter().map(|p| p.0).collect();
        let y: Vec<f64> = points.iter().map(|p| p.1).collect();
        let n = x.len();
        let h: Vec<f64> = x.windows(2).map(|w| w[1] - w[0]).collect();
        let delta: Vec<f64> = (0..n - 1).map(|k| (y[k + 1] - y[k]) / h[k]).collect();
        let mut slope = vec![0.0; n];
        if n == 2 {
            slope = vec![delta[0]; 2];
        } else {
            for k in 1..n - 1 {
                if delta[k - 1] * delta[k] <= 0.0 {
                    slope[k] = 0.0;
                } else {
                    // Weighted harmonic mean (Fritsch–Butland).
                    let w1 = 2.0 * h[k] + h[k - 1];
                    let w2 = h[k] + 2.0 * h[k - 1];
                    slope[k] = (w1 + w2) / (w1 / delta[k - 1] + w2 / delta[k]);
                }
            }
            slope[0] = end_slope(h[0], h[1], delta[0], delta[1]);
            slope[n - 1] = end_slope(h[n - 2], h[n - 3], delta[n - 2], delta[n - 3]);
        }
        Self { x, y, slope }
    }

    /// Interpolated value at `t`.
    pub(crate) fn eval(&self, t: f64) -> f64 {
        let n = self.x.len();
        if t <= self.x[0] {
            return self.y[0] + self.slope[0] * (t - self.x[0]);
        }
        if t >= self.x[n - 1] {
            return self.y[n - 1] + self.slope[n - 1] * (t - self.x[n - 1]);
        }
        let k = self.x.partition_point(|&xk| xk <= t) - 1;
        let h = self.x[k + 1] - self.x[k];
        let s = (t - self.x[k]) / h;
        let (h00, h10, h01, h11) = (
            (1.0 + 2.0 * s) * (1.0 - s) * (1.0 - s),
            s * (1.0 - s) * (1.0 - s),
            s * s * (3.0 - 2.0 * s),
            s * s * (s - 1.0),
        );
        h00 * self.y[k]
            + h10 * h * self.slope[k]
            + h01 * self.y[k + 1]
            + h11 * h * self.slope[k + 1]
    }
}

/// One-sided three-point end slope, limited to keep the interpolant monotone.
fn end_slope(h0: f64, h1: f64, d0: f64, d1: f64) -> f64 {
    let d = ((2.0 * h0 + h1) * d0 - h0 * d1) / (h0 + h1);
    if d * d0 <= 0.0 {
        0.0
    } else if d0 * d1 <= 0.0 && d.abs() > 3.0 * d0.abs() {
        3.0 * d0
    } else {
        d
    }
}

/// Least-squares line `y = slope·x + intercept` through the points; `None` with fewer than two
/// distinct abscissae.
pub(crate) fn fit_line(points: impl Iterator<Item = (f64, f64)>) -> Option<(f64, f64)> {
    let (mut n, mut sx, mut sy, mut sxx, mut sxy) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for (x, y) in points {
        n += 1.0;
        sx += x;
        sy += y;
        sxx += x * x;
        sxy += x * y;
    }
    let det = n * sxx - sx * sx;
    if n < 2.0 || det.abs() <= f64::EPSILON * n * sxx {
        return None;
    }
    let slope = (n * sxy - sx * sy) / det;
    Some((slope, (sy - slope * sx) / n))
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn pchip_passes_through_the_points_and_stays_monotone() {
        let pts = [
            (0.0, 0.0),
            (1.0, 0.5),
            (2.0, 0.6),
            (3.0, 2.0),
            (4.0, 2.0),
            (6.0, 5.0),
        ];
        let p = Pchip::new(&pts);
        for &(x, y) in &pts {
            assert_relative_eq!(p.eval(x), y, epsilon = 1e-12);
        }
        let mut last = p.eval(0.0);
        for i in 1..=600 {
            let v = p.eval(i as f64 * 0.01);
            assert!(v >= last - 1e-12, "not monotone at {}", i as f64 * 0.01);
            last = v;
        }
        // Flat data stays flat between equal values.
        assert_relative_eq!(p.eval(3.5), 2.0, epsilon = 1e-12);
    }

    #[test]
    fn pchip_reproduces_a_straight_line_and_extrapolates_linearly() {
        let p = Pchip::new(&[(0.0, 1.0), (2.0, 5.0), (3.0, 7.0)]);
        assert_relative_eq!(p.eval(1.3), 3.6, epsilon = 1e-12);
        assert_relative_eq!(p.eval(4.0), 9.0, epsilon = 1e-12);
        assert_relative_eq!(p.eval(-1.0), -1.0, epsilon = 1e-12);
    }

    #[test]
    fn line_fit_recovers_slope_and_intercept() {
        let (m, c) = fit_line((0..10).map(|i| (i as f64, 3.0 * i as f64 - 2.0))).expect("fit");
        assert_relative_eq!(m, 3.0, epsilon = 1e-12);
        assert_relative_eq!(c, -2.0, epsilon = 1e-12);
        assert!(fit_line([(1.0, 2.0)].into_iter()).is_none());
    }
}
