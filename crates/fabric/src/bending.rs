//! The bending characteristic M = ϕʰ(η) and its hysteresis: the spindle model of thesis §3.7.2,
//! (41)–(42), as restated in `method.md` §1.2.
//!
//! Assumption (I): the measured loop is spindle-shaped, approximated by the two branches
//! `M = Bη + M₀` (curvature rising) and `M = Bη − M₀` (falling), with B the bending rigidity and M₀
//! the residual moment (KES 2HB = 2M₀); [`fit_spindle`] finds B and M₀ by least squares from a
//! measured loop. Assumption (II): a curve from any turning point has the shape of the initial
//! curve. The printed (41) and (42) lost the extent of their square roots; the reading used here
//! joins every curve to its branch with matching slope:
//!
//! - initial curve from rest: `M = √(4ηM₀B)` for `0 ≤ η ≤ M₀/B`, where it meets `Bη + M₀` with slope
//!   B; mirrored for η < 0;
//! - after a turning point `(η_t, M_t)`: `M = M_t ± √(8|η − η_t|M₀B)` until it meets the opposite
//!   branch. From a point on a branch that happens at `|η − η_t| = 2M₀/B` with slope B; from a
//!   point inside the loop the curve crosses the branch earlier, at the smaller root of
//!   `B x² − √(8M₀B) x + a = 0` (x = √|η − η_t|, a = height above the target branch), with a kink.
//!
//! The moment always stays within `[Bη − M₀, Bη + M₀]`. Units: curvature η in m⁻¹, moment per width
//! M in N·m/m = N, rigidity B in N·m.

use crate::error::{ErrorKind, InvalidValue};
use crate::interp::fit_line;
use crate::units;

/// A spindle-shaped bending characteristic: rigidity B (N·m) and residual moment M₀ (N).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spindle {
    rigidity: f64,
    residual_moment: f64,
    /// Largest tangent of the initial and reversal curves as a multiple of B (∞: the exact
    /// square roots, infinitely steep at every turning point).
    stick_slope: f64,
    /// Curvature band (m⁻¹) within which moving back does not count as a reversal.
    deadband: f64,
}

impl Spindle {
    /// A characteristic with rigidity `rigidity` (B > 0, N·m) and residual moment
    /// `residual_moment` (M₀ ≥ 0, N; KES 2HB = 2M₀).
    pub fn new(rigidity: f64, residual_moment: f64) -> Result<Self, InvalidValue> {
        for (name, v) in [("rigidity", rigidity), ("residual_moment", residual_moment)] {
            if !v.is_finite() {
                return Err(InvalidValue::new(
                    ErrorKind::NotFinite,
                    name,
                    format!("{v}"),
                ));
            }
            if v < 0.0 {
                return Err(InvalidValue::new(ErrorKind::Negative, name, format!("{v}")));
            }
        }
        if rigidity == 0.0 {
            return Err(InvalidValue::new(
                ErrorKind::OutOfRange,
                "rigidity",
                "bending rigidity must be positive",
            ));
        }
        Ok(Self {
            rigidity,
            residual_moment,
            stick_slope: f64::INFINITY,
            deadband: 0.0,
        })
    }

    /// From KES values: B in gf·cm²/cm and 2HB in gf·cm/cm.
    pub fn from_kes(b: f64, two_hb: f64) -> Result<Self, InvalidValue> {
        Self::new(
            units::rigidity_from_kes(b),
            units::moment_from_kes(two_hb) / 2.0,
        )
    }

    /// The same characteristic with the square-root curves regularised: within a tiny band
    /// after each turning point the curve is the straight chord of slope `slope·B`, joining the
    /// square root where it reaches it (at `|η − η_t| = 4M₀/(slope²B)` on the initial curve,
    /// `8M₀/(slope²B)` on a reversal curve). The exact curves are infinitely steep at a turning
    /// point, which makes an explicit bending force amplify rounding noise ("chatter"); with a
    /// finite slope the loop keeps its branches, widths and joins. `slope` must exceed 1;
    /// `f64::INFINITY` restores the exact curves.
    pub fn with_stick_slope(mut self, slope: f64) -> Self {
        self.stick_slope = if slope > 1.0 { slope } else { f64::INFINITY };
        self
    }

    /// The same characteristic with a reversal dead band: a change of direction counts as a
    /// turning point only once the curvature has moved back by more than `band` (m⁻¹) from its
    /// extreme; smaller excursions run back along the current curve. Without it, the jitter of an
    /// iterative solver turns every step into a tiny minor loop, and since the model has no
    /// return-point memory the loop collapses towards the centre line (measured in
    /// `docs/solver.md`). Negative or NaN bands are treated as 0.
    pub fn with_deadband(mut self, band: f64) -> Self {
        self.deadband = if band > 0.0 { band } else { 0.0 };
        self
    }

    /// The reversal dead band, m⁻¹.
    pub fn deadband(&self) -> f64 {
        self.deadband
    }

    /// The regularisation slope (multiple of B), ∞ when exact.
    pub fn stick_slope(&self) -> f64 {
        self.stick_slope
    }

    /// `√(k·Δ·M₀·B)` (k = 4 on the initial curve, 8 on reversal curves), replaced by its chord
    /// of slope `stick_slope·B` where that lies below it.
    #[inline]
    fn root(&self, k: f64, delta: f64) -> f64 {
        let exact = (k * delta * self.residual_moment * self.rigidity).sqrt();
        exact.min(self.stick_slope * self.rigidity * delta)
    }

    /// Bending rigidity B, N·m.
    pub fn rigidity(&self) -> f64 {
        self.rigidity
    }

    /// Residual moment M₀ = 2HB/2, N.
    pub fn residual_moment(&self) -> f64 {
        self.residual_moment
    }

    /// Whether the characteristic has hysteresis (M₀ > 0); an elastic one needs no state.
    pub fn is_hysteretic(&self) -> bool {
        self.residual_moment > 0.0
    }

    /// Rising branch `Bη + M₀`.
    pub fn rising_branch(&self, curvature: f64) -> f64 {
        self.rigidity * curvature + self.residual_moment
    }

    /// Falling branch `Bη − M₀`.
    pub fn falling_branch(&self, curvature: f64) -> f64 {
        self.rigidity * curvature - self.residual_moment
    }

    /// The initial curve from rest: `sign(η)·√(4|η|M₀B)` up to `|η| = M₀/B`, then the branch.
    pub fn initial_curve(&self, curvature: f64) -> f64 {
        let x = curvature.abs();
        let m = if x * self.rigidity < self.residual_moment {
            self.root(4.0, x)
        } else {
            self.rigidity * x + self.residual_moment
        };
        m.copysign(curvature)
    }

    /// Curvature span of a reversal curve that starts a height `a` above (falling) or below
    /// (rising) the branch it heads for: the first crossing with that branch.
    fn reach(&self, a: f64) -> f64 {
        if a.is_nan() || a <= 0.0 || self.residual_moment == 0.0 {
            return 0.0;
        }
        let eight_mb = 8.0 * self.residual_moment * self.rigidity;
        // Within the regularised chord (slope s·B against the branch's B) the crossing is linear.
        if self.stick_slope.is_finite() {
            let chord_end =
                8.0 * self.residual_moment / (self.stick_slope * self.stick_slope * self.rigidity);
            let linear = a / ((self.stick_slope - 1.0) * self.rigidity);
            if linear <= chord_end {
                return linear;
            }
        }
        let disc = (eight_mb - 4.0 * self.rigidity * a).max(0.0);
        let x = 2.0 * a / (eight_mb.sqrt() + disc.sqrt());
        x * x
    }
}

/// Where a [`BendingState`] is on the characteristic.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Mode {
    /// On the initial curve from rest.
    Virgin,
    /// Curvature rising after a turning point.
    Rising,
    /// Curvature falling after a turning point.
    Falling,
}

/// The bending hysteresis state of one node and axial neighbour: the last curvature, and the
/// turning point and reach of the curve it travels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BendingState {
    curvature: f64,
    turn_curvature: f64,
    turn_moment: f64,
    reach: f64,
    mode: Mode,
}

impl Default for BendingState {
    fn default() -> Self {
        Self::VIRGIN
    }
}

impl BendingState {
    /// At rest, never bent.
    pub const VIRGIN: Self = Self {
        curvature: 0.0,
        turn_curvature: 0.0,
        turn_moment: 0.0,
        reach: 0.0,
        mode: Mode::Virgin,
    };

    /// The last committed curvature, m⁻¹.
    pub fn curvature(&self) -> f64 {
        self.curvature
    }

    /// The last turning point `(η_t, M_t)`, or `None` while on the initial curve.
    pub fn turning_point(&self) -> Option<(f64, f64)> {
        (self.mode != Mode::Virgin).then_some((self.turn_curvature, self.turn_moment))
    }

    /// Moment per width at `curvature` if the edge moved there now, without committing. O(1).
    #[inline]
    pub fn moment(&self, s: &Spindle, curvature: f64) -> f64 {
        self.advance(s, curvature).1
    }

    /// Move to `curvature`, detecting a reversal, and return the moment per width. O(1).
    #[inline]
    pub fn update(&mut self, s: &Spindle, curvature: f64) -> f64 {
        let (next, m) = self.advance(s, curvature);
        *self = next;
        m
    }

    /// Moment on the curve currently travelled at `curvature`, without reversal detection.
    pub fn branch_moment(&self, s: &Spindle, curvature: f64) -> f64 {
        self.eval(s, curvature)
    }

    #[inline]
    fn eval(&self, s: &Spindle, eta: f64) -> f64 {
        match self.mode {
            Mode::Virgin => s.initial_curve(eta),
            Mode::Rising => {
                let d = (eta - self.turn_curvature).max(0.0);
                if d < self.reach {
                    self.turn_moment + s.root(8.0, d)
                } else {
                    s.rising_branch(eta)
                }
            }
            Mode::Falling => {
                let d = (self.turn_curvature - eta).max(0.0);
                if d < self.reach {
                    self.turn_moment - s.root(8.0, d)
                } else {
                    s.falling_branch(eta)
                }
            }
        }
    }

    #[inline]
    fn advance(&self, s: &Spindle, eta: f64) -> (Self, f64) {
        let prev = self.curvature;
        let backwards = match self.mode {
            Mode::Virgin => (prev > 0.0 && eta < prev) || (prev < 0.0 && eta > prev),
            Mode::Rising => eta < prev,
            Mode::Falling => eta > prev,
        };
        if backwards && (eta - prev).abs() <= s.deadband {
            // Inside the dead band: back along the current curve, the extreme kept.
            return (*self, self.eval(s, eta));
        }
        let reverses = backwards;
        if !reverses {
            let next = Self {
                curvature: eta,
                ..*self
            };
            return (next, next.eval(s, eta));
        }
        let m_t = self.eval(s, prev);
        let falling = eta < prev;
        let a = if falling {
            m_t - s.falling_branch(prev)
        } else {
            s.rising_branch(prev) - m_t
        };
        let next = Self {
            curvature: eta,
            turn_curvature: prev,
            turn_moment: m_t,
            reach: s.reach(a),
            mode: if falling { Mode::Falling } else { Mode::Rising },
        };
        (next, next.eval(s, eta))
    }
}

/// Result of a least-squares spindle fit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpindleFit {
    /// The fitted characteristic.
    pub spindle: Spindle,
    /// Root-mean-square moment residual of the points used, N.
    pub rms_residual: f64,
    /// Number of points inside the fit band.
    pub points_used: usize,
}

/// The KES band for the bending slope and the fit: 0.5 ≤ |K| ≤ 1.5 cm⁻¹, in m⁻¹.
pub const KES_FIT_BAND: (f64, f64) = (0.5 * units::CURVATURE, 1.5 * units::CURVATURE);

/// Least-squares fit of B and M₀ to a measured loop: `points` are `(curvature m⁻¹, moment N)` in
/// the order they were measured; the direction of travel at each point (from its neighbours)
/// says which branch it belongs to, `M = Bη ± M₀`. Only points with `band.0 ≤ |η| ≤ band.1` are
/// used, which keeps the reversal transients near ±2.5 cm⁻¹ out of the fit.
pub fn fit_spindle(points: &[(f64, f64)], band: (f64, f64)) -> Result<SpindleFit, InvalidValue> {
    if let Some((i, p)) = points
        .iter()
        .enumerate()
        .find(|(_, p)| !(p.0.is_finite() && p.1.is_finite()))
    {
        return Err(InvalidValue::new(
            ErrorKind::NotFinite,
            format!("[{i}]"),
            format!("point ({}, {})", p.0, p.1),
        ));
    }
    let n = points.len();
    let mut rows = Vec::new();
    for i in 0..n {
        let (a, b) = (points[i.saturating_sub(1)].0, points[(i + 1).min(n - 1)].0);
        let dir = b - a;
        let (eta, m) = points[i];
        if dir != 0.0 && eta.abs() >= band.0 && eta.abs() <= band.1 {
            rows.push((eta, dir.signum(), m));
        }
    }
    let rising = rows.iter().filter(|r| r.1 > 0.0).count();
    let falling = rows.len() - rising;
    if rising < 2 || falling < 2 {
        return Err(InvalidValue::new(
            ErrorKind::TooShort,
            "",
            format!(
                "{rising} rising and {falling} falling point(s) inside the fit band; a loop \
                 needs at least 2 of each"
            ),
        ));
    }
    // Normal equations of M = B·η + M₀·s.
    let (mut see, mut ses, mut sss, mut sem, mut ssm) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for &(e, s, m) in &rows {
        see += e * e;
        ses += e * s;
        sss += s * s;
        sem += e * m;
        ssm += s * m;
    }
    let det = see * sss - ses * ses;
    if det.is_nan() || det.abs() <= 1e-12 * see * sss {
        return Err(InvalidValue::new(
            ErrorKind::Inconsistent,
            "",
            "the points do not determine a slope and a width",
        ));
    }
    let b = (sem * sss - ssm * ses) / det;
    let m0 = (see * ssm - ses * sem) / det;
    if b <= 0.0 || m0 < 0.0 {
        return Err(InvalidValue::new(
            ErrorKind::Inconsistent,
            "",
            format!("fit gives B = {b:e} N·m, M₀ = {m0:e} N; is the loop traversed backwards?"),
        ));
    }
    let rms = (rows
        .iter()
        .map(|&(e, s, m)| (m - b * e - m0 * s).powi(2))
        .sum::<f64>()
        / rows.len() as f64)
        .sqrt();
    Ok(SpindleFit {
        spindle: Spindle::new(b, m0)?,
        rms_residual: rms,
        points_used: rows.len(),
    })
}

/// What a KES-FB2 bending tester reports for a characteristic.
#[derive(Clone, Debug, PartialEq)]
pub struct KesBendingTest {
    /// B: mean slope over 0.5–1.5 cm⁻¹ (front bending) and −1.5…−0.5 cm⁻¹ (back bending), N·m.
    pub rigidity: f64,
    /// 2HB: mean loop width at K = +1 and −1 cm⁻¹, N.
    pub hysteresis: f64,
    /// The recorded loop `(curvature m⁻¹, moment N)`: 0 → +2.5 → −2.5 → 0 cm⁻¹.
    pub loop_points: Vec<(f64, f64)>,
}

/// Run a virtual KES bending test: bend from rest to +2.5 cm⁻¹, back to −2.5 cm⁻¹ and to 0,
/// with `steps_per_cm` samples per cm⁻¹ (the curvatures ±1.0 cm⁻¹ are sampled exactly when
/// `steps_per_cm` is a whole multiple of 2), and measure B and 2HB as KES defines them.
pub fn kes_bending_test(s: &Spindle, steps_per_cm: usize) -> KesBendingTest {
    let k = units::KES_MAX_CURVATURE;
    let n = (2.5 * steps_per_cm as f64).round().max(2.0) as usize;
    let leg = |from: f64, to: f64| (1..=n).map(move |i| from + (to - from) * i as f64 / n as f64);
    let path: Vec<(usize, f64)> = leg(0.0, k)
        .map(|e| (0, e))
        .chain(leg(k, 0.0).chain(leg(0.0, -k)).map(|e| (1, e)))
        .chain(leg(-k, 0.0).map(|e| (2, e)))
        .collect();
    let mut state = BendingState::VIRGIN;
    let mut pass = [Vec::new(), Vec::new(), Vec::new()];
    let mut loop_points = vec![(0.0, 0.0)];
    for (p, eta) in path {
        let m = state.update(s, eta);
        pass[p].push((eta, m));
        loop_points.push((eta, m));
    }
    let (lo, hi) = KES_FIT_BAND;
    let slope = |pts: &[(f64, f64)], sign: f64| {
        fit_line(
            pts.iter()
                .copied()
                .filter(|p| sign * p.0 >= lo && sign * p.0 <= hi),
        )
        .map_or(f64::NAN, |(m, _)| m)
    };
    let at = |pts: &[(f64, f64)], eta: f64| {
        pts.iter()
            .min_by(|a, b| (a.0 - eta).abs().total_cmp(&(b.0 - eta).abs()))
            .map_or(f64::NAN, |p| p.1)
    };
    let one = units::CURVATURE;
    let rigidity = 0.5 * (slope(&pass[0], 1.0) + slope(&pass[1], -1.0));
    let hysteresis =
        0.5 * ((at(&pass[0], one) - at(&pass[1], one)) + (at(&pass[2], -one) - at(&pass[1], -one)));
    KesBendingTest {
        rigidity,
        hysteresis,
        loop_points,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn cotton() -> Spindle {
        Spindle::from_kes(0.118, 0.124).expect("valid")
    }

    #[test]
    fn initial_curve_joins_the_branch_at_m0_over_b() {
        let s = cotton();
        let x = s.residual_moment() / s.rigidity();
        assert_relative_eq!(s.initial_curve(x), s.rising_branch(x), max_relative = 1e-12);
        assert_relative_eq!(
            s.initial_curve(-x),
            -s.rising_branch(x),
            max_relative = 1e-12
        );
    }

    #[test]
    fn elastic_characteristic_is_linear_and_stateless() {
        let s = Spindle::new(1e-5, 0.0).expect("valid");
        let mut st = BendingState::VIRGIN;
        for &eta in &[0.0, 50.0, 120.0, 30.0, -80.0, 10.0] {
            assert_relative_eq!(st.update(&s, eta), 1e-5 * eta, max_relative = 1e-12);
        }
        assert!(!s.is_hysteretic());
    }

    #[test]
    fn reversal_from_the_branch_meets_the_opposite_branch_after_2m0_over_b() {
        let s = cotton();
        let mut st = BendingState::VIRGIN;
        st.update(&s, 200.0);
        let span = 2.0 * s.residual_moment() / s.rigidity();
        let m = st.moment(&s, 200.0 - span);
        assert_relative_eq!(m, s.falling_branch(200.0 - span), max_relative = 1e-9);
    }

    #[test]
    fn invalid_parameters_are_rejected() {
        assert_eq!(
            Spindle::new(-1.0, 0.0).expect_err("neg").kind,
            ErrorKind::Negative
        );
        assert_eq!(
            Spindle::new(0.0, 0.0).expect_err("zero").kind,
            ErrorKind::OutOfRange
        );
        assert_eq!(
            Spindle::new(1.0, f64::NAN).expect_err("nan").kind,
            ErrorKind::NotFinite
        );
    }

    #[test]
    fn regularised_curves_keep_the_loop_and_bound_the_slope() {
        let s = cotton().with_stick_slope(4.0);
        let b = s.rigidity();
        // Slope near a turning point is at most 4B.
        let mut st = BendingState::VIRGIN;
        st.update(&s, 150.0);
        st.update(&s, 149.0);
        let (m1, m2) = (
            st.branch_moment(&s, 150.0 - 1e-6),
            st.branch_moment(&s, 150.0 - 2e-6),
        );
        assert!(((m1 - m2) / 1e-6).abs() <= 4.0 * b * (1.0 + 1e-9));
        // Far from turning points the loop is unchanged: the KES cycle gives B and 2HB.
        let t = kes_bending_test(&s, 200);
        assert!((t.rigidity / b - 1.0).abs() < 0.01);
        assert!((t.hysteresis / (2.0 * s.residual_moment()) - 1.0).abs() < 0.01);
        // The reversal from the branch still joins the opposite branch.
        let mut st = BendingState::VIRGIN;
        st.update(&s, 200.0);
        let span = 2.0 * s.residual_moment() / b;
        assert_relative_eq!(
            st.moment(&s, 200.0 - span),
            s.falling_branch(200.0 - span),
            max_relative = 1e-9
        );
        assert!(cotton().with_stick_slope(0.5).stick_slope().is_infinite());
    }

    #[test]
    fn deadband_ignores_small_reversals_and_keeps_the_loop() {
        let s = cotton().with_deadband(1.0);
        let mut st = BendingState::VIRGIN;
        // Rising with jitter of 0.5 m⁻¹ (inside the band): no turning point is recorded and
        // the moment stays on the initial curve / rising branch.
        for k in 0..200 {
            let eta = k as f64 + if k % 2 == 0 { 0.0 } else { -0.5 };
            let m = st.update(&s, eta.max(0.0));
            assert_relative_eq!(m, s.initial_curve(eta.max(0.0)), max_relative = 1e-9);
        }
        assert!(st.turning_point().is_none());
        // A real reversal (beyond the band) is a turning point at the extreme.
        st.update(&s, 195.0);
        assert_eq!(st.turning_point().map(|t| t.0), Some(198.5));
        assert!(cotton().with_deadband(-1.0).deadband().abs() < f64::MIN_POSITIVE);
    }
}
