//! A hysteretic bending row read on the spindle itself (`bending.spindle_rows`): the turn at
//! which the spindle, from the direction's committed hysteresis state, gives the moment the
//! row's multiplier exerts, as an edge's row reads its tensile loop at its own force. The step
//! is then backward Euler in the hysteresis; the linearised row (`NodeBend::offset`,
//! `NodeBend::compliance`) is a single Newton step of this one, taken at the start of the step.

use atelier_fabric::{BendingState, Spindle};

/// What a bending row needs to read the spindle during the solve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpindleRow {
    /// The direction's spindle, regularised as the step's parameters say.
    pub spindle: Spindle,
    /// Its committed hysteresis state (the start of the step).
    pub state: BendingState,
    /// Mean rest length l̄ of the line's two edges, m.
    pub length: f64,
    /// The node's area S, m².
    pub area: f64,
}

/// Iterations of the scalar inversion before it takes what it has (it needs 5–10).
const MAX_INVERSION_STEPS: usize = 100;

/// Half-width of the blend that rounds the spindle's kink at the committed curvature, as a
/// fraction of the characteristic's M₀/B: the width over which the linearised rows' slope is
/// a central difference (`targets.rs`). Measured (`docs/validation.md`, "The spindle's kink
/// rounded, session 26"): without the blend one step of the small coarse drape cycled across
/// the kink and ended at 4.4e-4 against the tolerance 1e-4; with it every step converged, at
/// the same Newton iterations per step.
const KINK_HALF_WIDTH: f64 = 1e-3;

/// The slope's central-difference step, as a fraction of the blend's half-width.
const SLOPE_STEP: f64 = 0.1;

impl SpindleRow {
    /// The moment per width (N) the row's multiplier λ exerts over a step of `dt`:
    /// m = −l̄ λ/(S Δt²) (the linearised row's balance θ − θ₀ = l̄(m − m₀)/k gives the same).
    pub fn moment(&self, lambda: f64, dt: f64) -> f64 {
        -self.length * lambda / (self.area * dt * dt)
    }

    /// Half-width (m⁻¹) of the blend around the committed curvature: `KINK_HALF_WIDTH`·M₀/B.
    fn kink_half_width(&self) -> f64 {
        let s = &self.spindle;
        KINK_HALF_WIDTH * s.residual_moment() / s.rigidity()
    }

    /// The moment per width (N) the row reads at curvature `eta` (m⁻¹): the spindle moved
    /// there from the committed state, except within [`KINK_HALF_WIDTH`]·M₀/B of the committed
    /// curvature, where the spindle's slope jumps (from the curve it travels to stick·B on a
    /// reversal) and a cubic Hermite blend takes the spindle's values and one-sided slopes at
    /// the blend's two ends. So the moment is continuously differentiable and its central
    /// difference is its derivative: a Newton iteration's row slope then matches the moment it
    /// reads, which a central difference across the kink itself (the mean of the two sides
    /// against a one-sided moment) did not. Within the blend the moment departs from the
    /// spindle's by at most (stick − 1)·B·w/4 = 7.5e-4·M₀ at stick 4 (w the half-width); the
    /// committed state is the spindle's (`BendingState::update` at the step's end).
    pub fn moment_at(&self, eta: f64) -> f64 {
        let (s, st) = (&self.spindle, &self.state);
        let (eta0, w) = (st.curvature(), self.kink_half_width());
        if w.is_nan() || w <= 0.0 || (eta - eta0).abs() >= w {
            return st.moment(s, eta);
        }
        let (a, c) = (eta0 - w, eta0 + w);
        let d = 1e-6 * w;
        let (ma, mc) = (st.moment(s, a), st.moment(s, c));
        let (ka, kc) = (
            (ma - st.moment(s, a - d)) / d,
            (st.moment(s, c + d) - mc) / d,
        );
        let span = 2.0 * w;
        let t = (eta - a) / span;
        let (t2, t3) = (t * t, t * t * t);
        (2.0 * t3 - 3.0 * t2 + 1.0) * ma
            + (t3 - 2.0 * t2 + t) * span * ka
            + (3.0 * t2 - 2.0 * t3) * mc
            + (t3 - t2) * span * kc
    }

    /// The curvature (m⁻¹) at which the row reads the moment `m` ([`SpindleRow::moment_at`]),
    /// and its slope there (N·m, by a central difference over a tenth of the kink's blend,
    /// within [B, stick·B] as the linearised rows take it): the derivative of the moment the
    /// row reads, as a Newton iteration needs. The row's moment rises with the curvature (its
    /// slopes lie between B and stick·B), so the root is bracketed and found by the Illinois
    /// variant of regula falsi.
    pub fn curvature_at(&self, m: f64) -> (f64, f64) {
        let (s, st) = (&self.spindle, &self.state);
        let b = s.rigidity();
        let eta0 = st.curvature();
        let f = |eta: f64| self.moment_at(eta) - m;
        let f0 = f(eta0);
        let eta = if f0 == 0.0 || !f0.is_finite() {
            eta0
        } else {
            // With slopes ≥ B the root lies within |f0|/B of η₀; widen if the regularised
            // curves are flatter anywhere.
            let dir = if f0 < 0.0 { 1.0 } else { -1.0 };
            let mut reach = f0.abs() / b;
            let (mut a, mut fa) = (eta0, f0);
            let (mut c, mut fc) = (eta0 + dir * reach, f(eta0 + dir * reach));
            let mut widen = 0;
            while fc.signum() == fa.signum() && widen < 60 {
                (a, fa) = (c, fc);
                reach *= 2.0;
                c = eta0 + dir * reach;
                fc = f(c);
                widen += 1;
            }
            let scale = s.residual_moment().max(b * (eta0.abs() + reach));
            let mut side = 0i8;
            let mut x = c;
            for _ in 0..MAX_INVERSION_STEPS {
                x = (a * fc - c * fa) / (fc - fa);
                if !x.is_finite() {
                    x = 0.5 * (a + c);
                }
                let fx = f(x);
                if fx.abs() <= 1e-13 * scale || (c - a).abs() <= 1e-15 * (x.abs() + reach) {
                    break;
                }
                if fx.signum() == fc.signum() {
                    (c, fc) = (x, fx);
                    if side == -1 {
                        fa *= 0.5;
                    }
                    side = -1;
                } else {
                    (a, fa) = (x, fx);
                    if side == 1 {
                        fc *= 0.5;
                    }
                    side = 1;
                }
            }
            x
        };
        let h = SLOPE_STEP * self.kink_half_width();
        let slope = if h > 0.0 {
            ((self.moment_at(eta + h) - self.moment_at(eta - h)) / (2.0 * h))
                .clamp(b, s.stick_slope().max(1.0) * b)
        } else {
            b
        };
        (eta, slope)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A row of a 1 cm line on a 1 cm² node.
    fn test_row(spindle: Spindle, state: BendingState) -> SpindleRow {
        SpindleRow {
            spindle,
            state,
            length: 0.01,
            area: 1e-4,
        }
    }

    /// The inversion gives back curvatures the spindle was read at, on the initial curve,
    /// after a reversal and on the far side of the loop.
    #[test]
    fn the_inverse_reads_back_the_spindles_curvature() {
        let spindle = Spindle::new(1e-5, 2e-5)
            .expect("spindle")
            .with_stick_slope(4.0)
            .with_deadband(0.05 * 2.0);
        let mut state = BendingState::VIRGIN;
        for eta in [0.0, 3.0, 1.0, -2.0] {
            state.update(&spindle, eta);
            let row = test_row(spindle, state);
            for target in [-4.0, -0.3, 0.0, 0.02, 0.7, 5.0] {
                let m = state.moment(&spindle, target);
                let (back, slope) = row.curvature_at(m);
                assert!(
                    (state.moment(&spindle, back) - m).abs() <= 1e-12 * 2e-5,
                    "from {eta}: {target} read back as {back}"
                );
                assert!((1e-5..=4e-5 * (1.0 + 1e-12)).contains(&slope), "{slope}");
            }
        }
    }

    /// The row's moment is the spindle's outside the blend around the committed curvature,
    /// within (stick − 1)·B·w/4 of it inside and rising through it; the slope `curvature_at`
    /// gives is the derivative of the moment the row reads, within the blend too. (Without the
    /// blend the slope half a blend width from the kink was the central difference across it,
    /// 3.35·B against the moment's 4·B there.)
    #[test]
    fn the_rows_moment_is_smooth_at_the_committed_curvature_and_its_slope_is_its_derivative() {
        let stick = 4.0;
        let spindle = Spindle::new(1e-5, 2e-5)
            .expect("spindle")
            .with_stick_slope(stick);
        let (b, m0) = (spindle.rigidity(), spindle.residual_moment());
        // Turned at 3, falling to 1.
        let mut state = BendingState::VIRGIN;
        for eta in [3.0, 1.0] {
            state.update(&spindle, eta);
        }
        let row = test_row(spindle, state);
        let eta0 = 1.0;
        let w = KINK_HALF_WIDTH * m0 / b;
        let one_sided =
            |x: f64| (state.moment(&spindle, eta0 + x) - state.moment(&spindle, eta0)) / x;
        // The kink: onward along the reversal curve from 3, back up at stick·B.
        let (onward, back) = (one_sided(-1e-4 * w), one_sided(1e-4 * w));
        assert!(onward < 0.5 * stick * b, "onward slope {onward}");
        assert!(
            (back - stick * b).abs() <= 1e-6 * b,
            "reversal slope {back}"
        );
        for x in [-2.0 * w, -w, w, 1.5 * w, 0.3, -0.5] {
            // Exactly the spindle's, bit for bit.
            assert_eq!(
                row.moment_at(eta0 + x).to_bits(),
                state.moment(&spindle, eta0 + x).to_bits(),
                "at {x}"
            );
        }
        let bound = (stick - 1.0) * b * w / 4.0;
        let mut before = f64::NEG_INFINITY;
        for k in 0..=200 {
            let eta = eta0 - w + 2.0 * w * k as f64 / 200.0;
            let m = row.moment_at(eta);
            let departure = (m - state.moment(&spindle, eta)).abs();
            assert!(
                departure <= bound * (1.0 + 1e-6),
                "{departure} > {bound} at {eta}"
            );
            assert!(m > before, "rising");
            before = m;
        }
        for x in [-0.5 * w, 0.0, 0.5 * w, -3.0 * w, 3.0 * w, -0.5, 1.0] {
            let (eta, slope) = row.curvature_at(row.moment_at(eta0 + x));
            assert!(
                (eta - (eta0 + x)).abs() <= 1e-6 * w,
                "read back {eta} for {x}"
            );
            let h = 1e-3 * w;
            let derivative = (row.moment_at(eta + h) - row.moment_at(eta - h)) / (2.0 * h);
            assert!(
                (slope - derivative).abs() <= 1e-4 * derivative,
                "at {x}: slope {slope}, derivative {derivative}"
            );
        }
    }
}
