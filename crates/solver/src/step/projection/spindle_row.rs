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

impl SpindleRow {
    /// The moment per width (N) the row's multiplier λ exerts over a step of `dt`:
    /// m = −l̄ λ/(S Δt²) (the linearised row's balance θ − θ₀ = l̄(m − m₀)/k gives the same).
    pub fn moment(&self, lambda: f64, dt: f64) -> f64 {
        -self.length * lambda / (self.area * dt * dt)
    }

    /// The curvature (m⁻¹) at which the spindle, moved there from the committed state, gives
    /// the moment `m`, and its slope there (N·m, by a central difference over a small part of
    /// the reversal width, within [B, stick·B] as the linearised rows take it). The spindle's
    /// moment rises with the curvature (its slopes lie between B and stick·B), so the root is
    /// bracketed and found by the Illinois variant of regula falsi.
    pub fn curvature_at(&self, m: f64) -> (f64, f64) {
        let (s, st) = (&self.spindle, &self.state);
        let b = s.rigidity();
        let f = |eta: f64| st.moment(s, eta) - m;
        let eta0 = st.curvature();
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
        let h = 1e-3 * s.residual_moment() / b;
        let slope = if h > 0.0 {
            ((st.moment(s, eta + h) - st.moment(s, eta - h)) / (2.0 * h))
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
            let row = SpindleRow {
                spindle,
                state,
                length: 0.01,
                area: 1e-4,
            };
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
}
