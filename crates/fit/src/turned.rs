//! Bending hysteresis from a turned cantilever (issue 9, carried over to cloth; `docs/fit.md`).
//!
//! A strip held horizontally droops along the spindle's *loading* curve, and a single drooped
//! profile cannot tell B from M₀: a stiffer B with a smaller M₀ droops alike (measured: fitting
//! both to a slowly lowered strip gave B −75 % and M₀ three times too large). Turning the clamp
//! downwards unloads it: near the clamp the moment falls from its loaded value towards zero,
//! the curvature runs back down the falling side of the loop, and the strip keeps a set curl of
//! the order of M₀/B. Observing the strip at the horizontal and again with the clamp turned
//! (ideally to the vertical, where the elastic strip would hang straight) separates the two.
//!
//! The forward model is the quasi-static heavy strip: stations `s_k = kL/n`, curvature κ_k,
//! tangent angle below the horizontal `θ(s) = β + ∫₀ˢ κ` (β the clamp's angle), and at every
//! station the moment balance `m_k(κ_k) = w ∫ₛᴸ (L − t) cos θ(t) dt` (the weight beyond, its
//! lever arm; w the weight per area) with `m_k` the spindle through each station's own
//! hysteresis state (`atelier_fabric::BendingState`, the solver's regularisation: stick slope
//! 4·B; no dead band, see [`TurnedStrip::deadband`]). The path is the observation's: gravity applied in `load_steps`
//! equal steps with the clamp horizontal, then the clamp turned down in small steps, every
//! state committed after each equilibrium (Newton with backtracking on the stations' κ).

use atelier_fabric::{BendingState, Spindle};
use nalgebra::{DMatrix, DVector};

use crate::FitError;
use crate::cloth::{ProfilePoint, check_profile, fit_cantilever};

/// One observed profile of a turned strip.
#[derive(Clone, Debug, PartialEq)]
pub struct TurnedProfile {
    /// The clamp's angle below the horizontal, degrees (0: the ordinary cantilever).
    pub clamp_deg: f64,
    /// The centreline, in the fixed frame: x forward from the clamp, droop downwards, m.
    pub points: Vec<ProfilePoint>,
}

/// The quasi-static strip: overhang, weight and discretisation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TurnedStrip {
    /// Overhang L, m.
    pub length: f64,
    /// Weight per area w, N/m².
    pub weight: f64,
    /// Stations along the strip. Default 60.
    pub stations: usize,
    /// Equal steps in which gravity is applied. Default 10.
    pub load_steps: usize,
    /// Clamp increment, degrees. Default 1.
    pub turn_step_deg: f64,
    /// The spindle's regularisation slope (multiple of B). Default 4, the solver's.
    pub stick_slope: f64,
    /// The reversal dead band as a fraction of M₀/B. Default 0: the solver's 5 % band (there
    /// against iteration jitter) makes the moment jump by (stick − 1)·B·band at the band's
    /// edge, where a static balance can have no solution.
    pub deadband: f64,
}

/// A shape: (x, droop) at each station, m.
pub type Centreline = Vec<(f64, f64)>;

impl TurnedStrip {
    /// The strip overhanging by `length` (m) with weight per area `weight` (N/m²).
    pub fn new(length: f64, weight: f64) -> Result<Self, FitError> {
        for (field, v) in [("length", length), ("weight", weight)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(FitError::invalid(field, 0, v, "must be finite and > 0"));
            }
        }
        Ok(Self {
            length,
            weight,
            stations: 60,
            load_steps: 10,
            turn_step_deg: 1.0,
            stick_slope: 4.0,
            deadband: 0.0,
        })
    }

    /// The centrelines at each clamp angle of `clamp_deg` (degrees, non-decreasing, in
    /// [0, 180]), for rigidity B (N·m) and residual moment M₀ (N).
    pub fn shapes(
        &self,
        rigidity: f64,
        residual_moment: f64,
        clamp_deg: &[f64],
    ) -> Result<Vec<Centreline>, FitError> {
        check_angles(clamp_deg)?;
        let spindle = Spindle::new(rigidity, residual_moment)
            .map_err(|e| FitError::invalid("spindle", 0, rigidity, e.to_string()))?
            .with_stick_slope(self.stick_slope);
        let spindle = spindle.with_deadband(self.deadband * residual_moment / rigidity);
        let n = self.stations;
        let mut states = vec![BendingState::VIRGIN; n];
        let mut kappa = DVector::zeros(n);
        let commit = |states: &mut [BendingState], kappa: &DVector<f64>| {
            for (st, &k) in states.iter_mut().zip(kappa.iter()) {
                st.update(&spindle, k);
            }
        };
        for step in 1..=self.load_steps {
            let load = step as f64 / self.load_steps as f64;
            self.equilibrium(&spindle, &states, 0.0, load, &mut kappa)?;
            commit(&mut states, &kappa);
        }
        let mut beta = 0.0f64;
        let mut out = Vec::with_capacity(clamp_deg.len());
        for &target in clamp_deg {
            let target = target.to_radians();
            let increment = self.turn_step_deg.to_radians();
            while beta < target {
                beta = (beta + increment).min(target);
                self.equilibrium(&spindle, &states, beta, 1.0, &mut kappa)?;
                commit(&mut states, &kappa);
            }
            out.push(self.centreline(beta, &kappa));
        }
        Ok(out)
    }

    /// Tangent angles θ_k (k = 0…n) for clamp angle β and station curvatures κ (κ_n = 0).
    fn angles(&self, beta: f64, kappa: &DVector<f64>) -> Vec<f64> {
        let n = self.stations;
        let h = self.length / n as f64;
        let k = |i: usize| if i < n { kappa[i] } else { 0.0 };
        let mut theta = vec![beta; n + 1];
        for i in 1..=n {
            theta[i] = theta[i - 1] + 0.5 * h * (k(i - 1) + k(i));
        }
        theta
    }

    fn centreline(&self, beta: f64, kappa: &DVector<f64>) -> Centreline {
        let h = self.length / self.stations as f64;
        let theta = self.angles(beta, kappa);
        let mut pts = vec![(0.0, 0.0)];
        let (mut x, mut y) = (0.0, 0.0);
        for w in theta.windows(2) {
            x += 0.5 * h * (w[0].cos() + w[1].cos());
            y += 0.5 * h * (w[0].sin() + w[1].sin());
            pts.push((x, y));
        }
        pts
    }

    /// The gravity moments M_i = load·w·∫_{s_i}^L (L − t) cos θ dt (trapezoid) and, when
    /// `jacobian`, their derivatives by κ_j.
    fn moments(
        &self,
        beta: f64,
        load: f64,
        kappa: &DVector<f64>,
        jacobian: bool,
    ) -> (DVector<f64>, Option<DMatrix<f64>>) {
        let n = self.stations;
        let (l, h) = (self.length, self.length / n as f64);
        let wl = load * self.weight;
        let theta = self.angles(beta, kappa);
        let arm = |k: usize| l - k as f64 * h;
        let mut m = DVector::zeros(n);
        // Suffix sums of the full-weight terms: S_k = Σ_{k' ≥ k} h·(L − s_k')·cos θ_k'.
        let mut cos_suffix = vec![0.0; n + 2];
        let mut sin_suffix = vec![0.0; n + 2];
        for k in (0..=n).rev() {
            cos_suffix[k] = cos_suffix[k + 1] + h * arm(k) * theta[k].cos();
            sin_suffix[k] = sin_suffix[k + 1] + h * arm(k) * theta[k].sin();
        }
        for i in 0..n {
            // Trapezoid from s_i: half weight at i (the end at n has a zero arm).
            m[i] = wl * (cos_suffix[i] - 0.5 * h * arm(i) * theta[i].cos());
        }
        if !jacobian {
            return (m, None);
        }
        // ∂θ_k/∂κ_j = h/2 [j ≤ k − 1] + h/2 [1 ≤ j ≤ k]; g_k = c_ik (L − s_k) sin θ_k.
        let mut jac = DMatrix::zeros(n, n);
        for i in 0..n {
            let g_i = 0.5 * h * arm(i) * theta[i].sin();
            // Σ_{k ≥ a, k ≥ i} g_k with the half weight at k = i.
            let tail = |a: usize| {
                if a > i {
                    sin_suffix[a]
                } else {
                    sin_suffix[i] - g_i
                }
            };
            let g = |k: usize| {
                if k == i {
                    g_i
                } else {
                    h * arm(k) * theta[k].sin()
                }
            };
            for j in 0..n {
                let d = if j == 0 {
                    0.5 * h * tail(1.max(i))
                } else {
                    h * tail((j + 1).max(i)) + if j >= i { 0.5 * h * g(j) } else { 0.0 }
                };
                jac[(i, j)] = -wl * d;
            }
        }
        (m, Some(jac))
    }

    /// Newton on the stations' curvatures: m_k(κ_k) through each state = M_k(κ).
    fn equilibrium(
        &self,
        spindle: &Spindle,
        states: &[BendingState],
        beta: f64,
        load: f64,
        kappa: &mut DVector<f64>,
    ) -> Result<(), FitError> {
        let n = self.stations;
        let scale = self.weight * self.length * self.length;
        let residual = |kappa: &DVector<f64>| -> DVector<f64> {
            let (m, _) = self.moments(beta, load, kappa, false);
            DVector::from_fn(n, |i, _| {
                (states[i].moment(spindle, kappa[i]) - m[i]) / scale
            })
        };
        let mut r = residual(kappa);
        let mut norm = r.amax();
        for iteration in 0..60 {
            if norm < 1e-11 {
                return Ok(());
            }
            let (_, jac) = self.moments(beta, load, kappa, true);
            let mut jac = -jac.expect("asked for") / scale;
            for i in 0..n {
                let d = 1e-7 * (kappa[i].abs() + 1.0 / self.length);
                let slope = (states[i].moment(spindle, kappa[i] + d)
                    - states[i].moment(spindle, kappa[i] - d))
                    / (2.0 * d);
                jac[(i, i)] += slope / scale;
            }
            let Some(step) = jac.lu().solve(&r) else {
                return Err(no_equilibrium(iteration, norm, &r));
            };
            let mut t = 1.0;
            loop {
                let trial = &*kappa - t * &step;
                let rt = residual(&trial);
                if rt.amax() < norm || t < 1e-4 {
                    *kappa = trial;
                    r = rt;
                    norm = r.amax();
                    break;
                }
                t *= 0.5;
            }
            if !norm.is_finite() {
                return Err(no_equilibrium(iteration, norm, &r));
            }
        }
        if norm < 1e-9 {
            Ok(())
        } else {
            Err(no_equilibrium(60, norm, &r))
        }
    }
}

fn no_equilibrium(iterations: usize, residual: f64, r: &DVector<f64>) -> FitError {
    FitError::NoEquilibrium {
        iterations,
        residual,
        particle: r.iamax(),
    }
}

fn check_angles(clamp_deg: &[f64]) -> Result<(), FitError> {
    let mut last = 0.0;
    for (k, &a) in clamp_deg.iter().enumerate() {
        if !(a.is_finite() && (0.0..=180.0).contains(&a)) {
            return Err(FitError::invalid("clamp_deg", k, a, "must be in [0, 180]"));
        }
        if a < last {
            return Err(FitError::invalid(
                "clamp_deg",
                k,
                a,
                format!("the clamp only turns downwards: below the previous {last}"),
            ));
        }
        last = a;
    }
    Ok(())
}

/// The shape at arc length `s` on a centreline of stations `s_k = kL/n`, linearly.
fn at_arc(line: &Centreline, length: f64, s: f64) -> (f64, f64) {
    let n = line.len() - 1;
    let u = (s / length).clamp(0.0, 1.0) * n as f64;
    let k = (u.floor() as usize).min(n - 1);
    let t = u - k as f64;
    (
        line[k].0 + t * (line[k + 1].0 - line[k].0),
        line[k].1 + t * (line[k + 1].1 - line[k].1),
    )
}

/// The outcome of a hysteresis fit.
#[derive(Clone, Debug, PartialEq)]
pub struct HysteresisFit {
    /// Bending rigidity B, N·m.
    pub rigidity: f64,
    /// Residual moment M₀ = 2HB/2, N.
    pub residual_moment: f64,
    /// RMS distance of all points from the fitted shapes, m.
    pub rms: f64,
    /// RMS of the best elastic fit (M₀ = 0, B free) to the same profiles, m: how much the
    /// hysteresis explains.
    pub elastic_rms: f64,
    /// Levenberg–Marquardt's evaluations of the forward model (each a whole path).
    pub evaluations: usize,
    /// How the minimiser ended.
    pub termination: String,
}

struct Problem<'a> {
    strip: TurnedStrip,
    profiles: &'a [TurnedProfile],
    angles: Vec<f64>,
    evaluations: std::sync::atomic::AtomicUsize,
}

impl Problem<'_> {
    fn rows(&self) -> usize {
        2 * self.profiles.iter().map(|p| p.points.len()).sum::<usize>()
    }

    fn residuals_at(&self, p: &DVector<f64>) -> Option<DVector<f64>> {
        self.evaluations
            .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let shapes = self
            .strip
            .shapes(p[0].exp(), p[1].exp(), &self.angles)
            .ok()?;
        let mut r = DVector::zeros(self.rows());
        let mut row = 0;
        for (profile, line) in self.profiles.iter().zip(&shapes) {
            for q in &profile.points {
                let (x, y) = at_arc(line, self.strip.length, q.s);
                r[row] = x - q.x;
                r[row + 1] = y - q.droop;
                row += 2;
            }
        }
        Some(r)
    }
}

pub use crate::differenced::minimise;

/// Fit B and M₀ to profiles of one strip (overhang `length` m, weight per area `weight`
/// N/m²) observed at increasing clamp angles, at least one of them turned (> 0°) — a
/// horizontal profile alone cannot separate B from M₀. Initial values: B from the elastica
/// fitted to the first profile, then M₀ the best of a scan over (0.01 … 3)·B/L; then
/// Levenberg–Marquardt (the `levenberg-marquardt` crate) on (ln B, ln M₀).
pub fn fit_turned(
    profiles: &[TurnedProfile],
    length: f64,
    weight: f64,
) -> Result<HysteresisFit, FitError> {
    let strip = TurnedStrip::new(length, weight)?;
    if profiles.is_empty() {
        return Err(FitError::invalid("profiles", 0, 0.0, "no profile"));
    }
    let angles: Vec<f64> = profiles.iter().map(|p| p.clamp_deg).collect();
    check_angles(&angles)?;
    for p in profiles {
        check_profile(&p.points, length)?;
    }
    if angles.iter().all(|&a| (a - angles[0]).abs() < 1e-9) {
        return Err(FitError::invalid(
            "profiles",
            0,
            angles[0],
            "every profile at one clamp angle: B and M₀ are not identifiable (they trade off); \
             observe the strip turned as well",
        ));
    }
    // The first profile at the horizontal seen as elastic: rigidity to start from.
    let horizontal: Vec<ProfilePoint> = profiles[0]
        .points
        .iter()
        .map(|q| {
            // Rotate the observation back to the clamp's frame.
            let b = profiles[0].clamp_deg.to_radians();
            ProfilePoint {
                x: q.x * b.cos() + q.droop * b.sin(),
                droop: -q.x * b.sin() + q.droop * b.cos(),
                ..*q
            }
        })
        .collect();
    let elastic = fit_cantilever(&horizontal, length)?;
    let b0 = weight * elastic.bending_length.powi(3);
    let problem = Problem {
        strip,
        profiles,
        angles,
        evaluations: std::sync::atomic::AtomicUsize::new(0),
    };
    let cost = |problem: &Problem, p: &DVector<f64>| {
        problem
            .residuals_at(p)
            .map_or(f64::INFINITY, |r| r.norm_squared())
    };
    let mut best = (f64::INFINITY, 0.0);
    for f in [0.01, 0.03, 0.1, 0.3, 1.0, 3.0] {
        let p = DVector::from_vec(vec![b0.ln(), (f * b0 / length).ln()]);
        let c = cost(&problem, &p);
        if c < best.0 {
            best = (c, p[1]);
        }
    }
    if !best.0.is_finite() {
        return Err(FitError::invalid(
            "profiles",
            0,
            b0,
            "the strip model finds no equilibrium near the elastic estimate",
        ));
    }
    // (ln B, ln M₀); a step of 1e-4 sees through the path's kinks.
    let start = DVector::from_vec(vec![b0.ln(), best.1]);
    let (p, termination) = minimise(start, 1e-4, |p| problem.residuals_at(p));
    let rows = problem.rows() / 2;
    let rms = |c: f64| (c / rows as f64).sqrt();
    let fitted_cost = cost(&problem, &p);
    // The best elastic strip (M₀ → 0): a one-dimensional golden search on ln B around b0.
    let elastic_cost = |lnb: f64| {
        let p = DVector::from_vec(vec![lnb, (1e-9 * b0 / length).ln()]);
        cost(&problem, &p)
    };
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut a, mut b) = (b0.ln() - 2.0, b0.ln() + 1.0);
    let (mut c, mut d) = (b - g * (b - a), a + g * (b - a));
    let (mut fc, mut fd) = (elastic_cost(c), elastic_cost(d));
    while b - a > 1e-4 {
        if fc < fd {
            (b, d, fd) = (d, c, fc);
            c = b - g * (b - a);
            fc = elastic_cost(c);
        } else {
            (a, c, fc) = (c, d, fd);
            d = a + g * (b - a);
            fd = elastic_cost(d);
        }
    }
    Ok(HysteresisFit {
        rigidity: p[0].exp(),
        residual_moment: p[1].exp(),
        rms: rms(fitted_cost),
        elastic_rms: rms(fc.min(fd)),
        evaluations: problem
            .evaluations
            .load(std::sync::atomic::Ordering::Relaxed),
        termination,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cloth::elastica;
    use atelier_fabric::units;
    use atelier_files::noise::Rng;

    /// Wool tropical (Matsudaira B): B 0.067 gf·cm²/cm, 2HB 0.033 gf·cm/cm, 16.29 mg/cm².
    fn wool() -> (f64, f64, f64) {
        let b = units::rigidity_from_kes(0.067);
        let m0 = 0.5 * units::moment_from_kes(0.033);
        let w = 16.29e-6 / 1e-4 * atelier_fabric::STANDARD_GRAVITY;
        (b, m0, w)
    }

    /// Without hysteresis the horizontal strip is the heavy elastica (tip within 0.1 % of L
    /// at λ = 8), and turned to the vertical it hangs straight.
    #[test]
    fn the_elastic_strip_is_the_elastica_and_hangs_straight() {
        let (b, _, w) = wool();
        let c = (b / w).cbrt();
        let length = 2.0003 * c;
        let strip = TurnedStrip::new(length, w).expect("strip");
        let shapes = strip.shapes(b, 0.0, &[0.0, 90.0]).expect("shapes");
        let e = elastica(w * length.powi(3) / b, 2000);
        let (tip, reference) = (shapes[0][60], e[2000]);
        assert!(
            (tip.0 / length - reference.0).abs() < 1e-3
                && (tip.1 / length - reference.1).abs() < 1e-3,
            "{tip:?} against {reference:?}·L"
        );
        let hanging = shapes[1][60];
        assert!(hanging.0.abs() < 1e-9 * length, "{hanging:?}");
        assert!((hanging.1 - length).abs() < 1e-9, "{hanging:?}");
    }

    /// With hysteresis the loaded strip droops less than the elastic one (the loading curve
    /// lies above Bη), and turned to the vertical it keeps a curl back towards the clamp side
    /// whose curvature at the clamp is at most the loop's M₀/B and at least half of it.
    #[test]
    fn the_hysteretic_strip_droops_less_and_keeps_a_set() {
        let (b, m0, w) = wool();
        let length = 2.0003 * (b / w).cbrt();
        let strip = TurnedStrip::new(length, w).expect("strip");
        let elastic = strip.shapes(b, 0.0, &[0.0]).expect("shapes");
        let shapes = strip.shapes(b, m0, &[0.0, 90.0]).expect("shapes");
        assert!(shapes[0][60].1 < elastic[0][60].1);
        let hanging = &shapes[1];
        assert!(hanging[60].0 < -1e-3, "tip {:?}", hanging[60]);
        // Curvature at the clamp from the first two segments' turn.
        let h = length / 60.0;
        let dir = |k: usize| {
            let (a, b) = (hanging[k], hanging[k + 1]);
            (b.1 - a.1).atan2(b.0 - a.0)
        };
        let kappa = (dir(1) - dir(0)) / h;
        assert!(
            kappa > 0.5 * m0 / b && kappa < 1.05 * m0 / b,
            "set curvature {kappa} against M0/B {}",
            m0 / b
        );
    }

    /// Profiles from the model itself at 0°, 45° and 90° (11 points each): B and M₀ come back
    /// within 1e-4 without noise, and within 10 % with 0.1 mm of noise per coordinate.
    #[test]
    fn the_model_is_fitted_back() {
        let (b, m0, w) = wool();
        let length = 2.0003 * (b / w).cbrt();
        let strip = TurnedStrip::new(length, w).expect("strip");
        let angles = [0.0, 45.0, 90.0];
        let shapes = strip.shapes(b, m0, &angles).expect("shapes");
        let profiles = |sigma: f64, seed: u64| {
            let mut noise = Rng::new(seed);
            angles
                .iter()
                .zip(&shapes)
                .map(|(&a, line)| TurnedProfile {
                    clamp_deg: a,
                    points: (1..=10)
                        .map(|k| {
                            let (x, y) = line[6 * k];
                            ProfilePoint {
                                s: 6.0 * k as f64 * length / 60.0,
                                x: x + sigma * noise.normal(),
                                droop: y + sigma * noise.normal(),
                            }
                        })
                        .collect(),
                })
                .collect::<Vec<_>>()
        };
        let exact = fit_turned(&profiles(0.0, 0), length, w).expect("fit");
        assert!(
            (exact.rigidity / b - 1.0).abs() < 1e-4
                && (exact.residual_moment / m0 - 1.0).abs() < 1e-4,
            "{exact:?}"
        );
        assert!(exact.elastic_rms > 100.0 * exact.rms.max(1e-9), "{exact:?}");
        let noisy = fit_turned(&profiles(1e-4, 7), length, w).expect("fit");
        assert!(
            (noisy.rigidity / b - 1.0).abs() < 0.1
                && (noisy.residual_moment / m0 - 1.0).abs() < 0.1,
            "{noisy:?}"
        );
    }

    /// Every profile at one clamp angle is refused as not identifiable; angles that go back up
    /// are refused with their position.
    #[test]
    fn one_angle_or_a_clamp_turning_back_is_refused() {
        let p = |a: f64| TurnedProfile {
            clamp_deg: a,
            points: vec![
                ProfilePoint {
                    s: 0.01,
                    x: 0.01,
                    droop: 0.001,
                },
                ProfilePoint {
                    s: 0.02,
                    x: 0.02,
                    droop: 0.004,
                },
            ],
        };
        let e = fit_turned(&[p(0.0), p(0.0)], 0.03, 1.6).expect_err("one angle");
        assert!(e.to_string().contains("not identifiable"), "{e}");
        let e = fit_turned(&[p(45.0), p(10.0)], 0.03, 1.6).expect_err("turning back");
        assert!(e.to_string().contains("`clamp_deg`[1] = 10"), "{e}");
    }
}
