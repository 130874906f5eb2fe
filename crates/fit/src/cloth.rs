//! The method carried over to cloth (issue 9, first part): a fabric's bending rigidity B from an
//! observed cantilever profile.
//!
//! A strip clamped horizontally and overhanging by L droops as the heavy inextensible elastica
//! (`reference/elastica.md`): `θ'' = −λ(1 − σ) cos θ`, `θ(0) = 0`, `θ'(1) = 0`, σ = s/L,
//! λ = wL³/B (w the weight per area). Given the observed centreline — each point's arc length
//! from the clamp and its position — the λ whose elastica passes nearest the points (least
//! squares, a one-dimensional search on ln λ) gives the bending length c = L λ^(−1/3) and
//! B = w c³. This is Peirce's cantilever test (which uses only the tip's chord angle) with the
//! whole profile, the model fitted to the shape as in the string method.

use crate::FitError;

/// The heavy elastica at λ, on `n` RK4 steps: the centreline (x, droop)/L at σ = k/n,
/// k = 0…n, found by shooting on θ'(0) (bisection until θ'(1) = 0).
pub fn elastica(lambda: f64, n: usize) -> Vec<(f64, f64)> {
    let h = 1.0 / n as f64;
    let shoot = |k: f64, keep: bool| -> (f64, Vec<(f64, f64)>) {
        let f = |s: f64, th: f64, w: f64| (w, -lambda * (1.0 - s) * th.cos());
        let (mut th, mut w) = (0.0, k);
        let mut pts = vec![(0.0, 0.0)];
        let (mut x, mut y) = (0.0, 0.0);
        for i in 0..n {
            let s = i as f64 * h;
            let (a1, b1) = f(s, th, w);
            let (a2, b2) = f(s + h / 2.0, th + h / 2.0 * a1, w + h / 2.0 * b1);
            let (a3, b3) = f(s + h / 2.0, th + h / 2.0 * a2, w + h / 2.0 * b2);
            let (a4, b4) = f(s + h, th + h * a3, w + h * b3);
            let th_new = th + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4);
            w += h / 6.0 * (b1 + 2.0 * b2 + 2.0 * b3 + b4);
            if keep {
                x += 0.5 * h * (th.cos() + th_new.cos());
                y += 0.5 * h * (th.sin() + th_new.sin());
                pts.push((x, y));
            }
            th = th_new;
        }
        (w, pts)
    };
    let (mut lo, mut hi) = (0.0, lambda / 2.0);
    for _ in 0..64 {
        let mid = 0.5 * (lo + hi);
        if shoot(mid, false).0 > 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    shoot(0.5 * (lo + hi), true).1
}

/// One observed point of a cantilever's centreline: its arc length from the clamp and its
/// position (x forward from the clamp, droop downwards), m.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProfilePoint {
    /// Arc length from the clamp, m (in [0, L]).
    pub s: f64,
    /// Distance forward from the clamp, m.
    pub x: f64,
    /// Droop below the clamp, m.
    pub droop: f64,
}

/// The outcome of a cantilever fit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CantileverFit {
    /// λ = wL³/B.
    pub lambda: f64,
    /// Bending length c = (B/w)^(1/3), m.
    pub bending_length: f64,
    /// RMS distance of the points from the fitted elastica, m.
    pub rms: f64,
}

/// RMS distance of `points` from the elastica at λ (overhang `length`).
fn profile_rms(points: &[ProfilePoint], length: f64, lambda: f64) -> f64 {
    let n = 1000;
    let e = elastica(lambda, n);
    let sq: f64 = points
        .iter()
        .map(|p| {
            // Linear interpolation along the stations.
            let u = (p.s / length).clamp(0.0, 1.0) * n as f64;
            let k = (u.floor() as usize).min(n - 1);
            let t = u - k as f64;
            let (x, y) = (
                e[k].0 + t * (e[k + 1].0 - e[k].0),
                e[k].1 + t * (e[k + 1].1 - e[k].1),
            );
            (p.x - x * length).powi(2) + (p.droop - y * length).powi(2)
        })
        .sum();
    (sq / points.len() as f64).sqrt()
}

/// Refuse an overhang that is not finite and positive, a profile of fewer than two points, a
/// non-finite point or an arc length outside [0, L].
pub(crate) fn check_profile(points: &[ProfilePoint], length: f64) -> Result<(), FitError> {
    if !(length.is_finite() && length > 0.0) {
        return Err(FitError::invalid(
            "length",
            0,
            length,
            "must be finite and > 0",
        ));
    }
    if points.len() < 2 {
        return Err(FitError::invalid(
            "points",
            points.len(),
            points.len() as f64,
            "a profile needs at least 2 points",
        ));
    }
    for (k, p) in points.iter().enumerate() {
        if !(p.s.is_finite() && p.x.is_finite() && p.droop.is_finite()) {
            return Err(FitError::invalid("points", k, f64::NAN, "not finite"));
        }
        if p.s < 0.0 || p.s > length * (1.0 + 1e-9) {
            return Err(FitError::invalid(
                "points",
                k,
                p.s,
                format!("arc length outside [0, {length}]"),
            ));
        }
    }
    Ok(())
}

/// Fit the elastica to an observed centreline of a strip overhanging by `length`: golden-section
/// search on ln λ over λ ∈ [0.01, 1000] (a strip drooping 0.1 % to 89 % of its length) to a
/// relative precision of 1e-6.
pub fn fit_cantilever(points: &[ProfilePoint], length: f64) -> Result<CantileverFit, FitError> {
    check_profile(points, length)?;
    let f = |ln: f64| profile_rms(points, length, ln.exp());
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut a, mut b) = (0.01f64.ln(), 1000f64.ln());
    let (mut c, mut d) = (b - g * (b - a), a + g * (b - a));
    let (mut fc, mut fd) = (f(c), f(d));
    while b - a > 1e-6 {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = f(d);
        }
    }
    let lambda = (0.5 * (a + b)).exp();
    Ok(CantileverFit {
        lambda,
        bending_length: length * lambda.powf(-1.0 / 3.0),
        rms: profile_rms(points, length, lambda),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use atelier_files::noise::Rng;

    /// The elastica reproduces the reference numbers (`reference/elastica.md`): λ = 8.0042 gives
    /// the 41.5° chord with the tip at (0.7243, 0.6408)·L; small deflection y/L = λ/8.
    #[test]
    fn the_elastica_reproduces_the_reference_numbers() {
        let pts = elastica(8.00420, 4000);
        let (x, y) = pts[pts.len() - 1];
        assert!((y.atan2(x).to_degrees() - 41.5).abs() < 1e-3);
        assert!(
            (x - 0.7243).abs() < 1e-4 && (y - 0.6408).abs() < 1e-4,
            "({x}, {y})"
        );
        let small = elastica(0.01, 2000);
        assert!((small[small.len() - 1].1 - 0.01 / 8.0).abs() < 1e-6);
    }

    /// A profile sampled from the elastica itself (20 points, L = 10 cm, λ = 8) gives λ back
    /// within 1e-5 without noise; with 0.2 mm of noise per coordinate within 3 %.
    #[test]
    fn the_elastica_is_fitted_back() {
        let (length, lambda) = (0.1, 8.0);
        let e = elastica(lambda, 2000);
        let points: Vec<ProfilePoint> = (1..=20)
            .map(|k| {
                let (x, y) = e[k * 100];
                ProfilePoint {
                    s: k as f64 * length / 20.0,
                    x: x * length,
                    droop: y * length,
                }
            })
            .collect();
        let exact = fit_cantilever(&points, length).expect("fit");
        assert!((exact.lambda / lambda - 1.0).abs() < 1e-5, "{exact:?}");
        let mut noise = Rng::new(3);
        let noisy: Vec<ProfilePoint> = points
            .iter()
            .map(|p| ProfilePoint {
                x: p.x + 2e-4 * noise.normal(),
                droop: p.droop + 2e-4 * noise.normal(),
                ..*p
            })
            .collect();
        let fit = fit_cantilever(&noisy, length).expect("fit");
        assert!((fit.lambda / lambda - 1.0).abs() < 0.03, "{fit:?}");
    }
}
