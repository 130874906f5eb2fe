//! Bending: the spindle model's joins, the virtual KES test, the least-squares fit, and the
//! envelope property.

use approx::assert_relative_eq;
use atelier_fabric::{BendingState, Spindle, fit_spindle, kes_bending_test, units};
use proptest::prelude::*;

use crate::common::{FIXTURES, Rng, fixture};

fn cotton() -> Spindle {
    Spindle::from_kes(0.118, 0.124).expect("valid")
}

/// One-sided slopes of `m` at `x` with step `h`.
fn slopes(m: impl Fn(f64) -> f64, x: f64, h: f64) -> (f64, f64) {
    ((m(x) - m(x - h)) / h, (m(x + h) - m(x)) / h)
}

/// The initial curve √(4ηM₀B) meets the branch Bη + M₀ at η = M₀/B with slope B on both sides.
#[test]
fn initial_curve_joins_the_branch_with_matching_slope() {
    let s = cotton();
    let x0 = s.residual_moment() / s.rigidity();
    let h = 1e-7 * x0;
    let (left, right) = slopes(|e| s.initial_curve(e), x0, h);
    assert_relative_eq!(right, s.rigidity(), max_relative = 1e-6);
    assert_relative_eq!(left, s.rigidity(), max_relative = 1e-6);
}

/// A reversal from a point on the rising branch, M_t − √(8|η−η_t|M₀B), meets the falling branch
/// at η_t − 2M₀/B with slope B on both sides (moment continuous there too).
#[test]
fn reversal_curve_joins_the_opposite_branch_with_matching_slope() {
    let s = cotton();
    let mut st = BendingState::VIRGIN;
    let eta_t = 2.0 * units::CURVATURE;
    st.update(&s, eta_t);
    st.update(&s, eta_t - 1e-9);
    let join = eta_t - 2.0 * s.residual_moment() / s.rigidity();
    let h = 1e-7 * join;
    let (left, right) = slopes(|e| st.branch_moment(&s, e), join, h);
    assert_relative_eq!(left, s.rigidity(), max_relative = 1e-6);
    assert_relative_eq!(right, s.rigidity(), max_relative = 1e-6);
    assert_relative_eq!(
        st.branch_moment(&s, join),
        s.falling_branch(join),
        max_relative = 1e-12
    );
    // And the reversal curve starts at the turning point (no jump).
    assert_relative_eq!(
        st.branch_moment(&s, eta_t),
        s.rising_branch(eta_t),
        max_relative = 1e-12
    );
}

/// A reversal from inside the loop (on the initial curve) crosses the opposite branch before
/// 2M₀/B and then follows it.
#[test]
fn reversal_from_inside_the_loop_switches_at_the_first_crossing() {
    let s = cotton();
    let eta_t = 0.5 * s.residual_moment() / s.rigidity();
    let mut st = BendingState::VIRGIN;
    let m_t = st.update(&s, eta_t);
    assert_relative_eq!(
        m_t,
        (4.0 * eta_t * s.residual_moment() * s.rigidity()).sqrt(),
        max_relative = 1e-12
    );
    st.update(&s, eta_t * 0.999);
    // Height above the falling branch and the predicted crossing.
    let a = m_t - s.falling_branch(eta_t);
    let (b, m0) = (s.rigidity(), s.residual_moment());
    let x = ((8.0 * m0 * b).sqrt() - (8.0 * m0 * b - 4.0 * b * a).sqrt()) / (2.0 * b);
    let cross = eta_t - x * x;
    assert!(x * x < 2.0 * m0 / b);
    assert_relative_eq!(
        st.branch_moment(&s, cross),
        s.falling_branch(cross),
        max_relative = 1e-9
    );
    let beyond = cross - 0.1 * units::CURVATURE;
    assert_relative_eq!(
        st.branch_moment(&s, beyond),
        s.falling_branch(beyond),
        max_relative = 1e-12
    );
}

/// A virtual KES-FB2 cycle ±2.5 cm⁻¹ measures B (slope over 0.5–1.5 cm⁻¹) and 2HB (width at
/// |K| = 1 cm⁻¹) within 1 % of the input, for every fixture direction.
#[test]
fn kes_cycle_reproduces_b_and_2hb_within_one_percent() {
    for name in FIXTURES {
        let f = fixture(name);
        for (dir, s) in [
            ("warp", f.bending.warp),
            ("weft", f.bending.weft),
            ("bias45", f.bending.bias45),
        ] {
            let t = kes_bending_test(&s, 200);
            let b_err = (t.rigidity / s.rigidity() - 1.0).abs();
            let h_err = (t.hysteresis / (2.0 * s.residual_moment()) - 1.0).abs();
            assert!(
                b_err < 0.01,
                "{name} {dir}: B off by {:.3} %",
                100.0 * b_err
            );
            assert!(
                h_err < 0.01,
                "{name} {dir}: 2HB off by {:.3} %",
                100.0 * h_err
            );
        }
    }
}

/// Least squares recovers B and M₀ within 2 % from a synthetic KES loop with noise of 2 % of
/// the peak moment added to every sample.
#[test]
fn least_squares_fit_recovers_b_and_m0_from_a_noisy_loop() {
    let mut rng = Rng::new(0x5EED_0FC0_770A);
    for s in [
        cotton(),
        Spindle::from_kes(0.019, 0.007).expect("faille"),
        Spindle::from_kes(1.2, 0.6).expect("denim"),
    ] {
        let clean = kes_bending_test(&s, 100).loop_points;
        let peak = clean.iter().map(|p| p.1.abs()).fold(0.0, f64::max);
        let noisy: Vec<(f64, f64)> = clean
            .iter()
            .map(|&(k, m)| (k, m + 0.02 * peak * rng.normal()))
            .collect();
        let fit = fit_spindle(&noisy, atelier_fabric::bending::KES_FIT_BAND).expect("fit");
        assert_relative_eq!(fit.spindle.rigidity(), s.rigidity(), max_relative = 0.02);
        assert_relative_eq!(
            fit.spindle.residual_moment(),
            s.residual_moment(),
            max_relative = 0.02
        );
        // Without noise the fit is exact (the band lies on the branches).
        let exact = fit_spindle(&clean, atelier_fabric::bending::KES_FIT_BAND).expect("fit");
        assert_relative_eq!(exact.spindle.rigidity(), s.rigidity(), max_relative = 1e-3);
        assert_relative_eq!(
            exact.spindle.residual_moment(),
            s.residual_moment(),
            max_relative = 1e-3
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 1000, ..ProptestConfig::default() })]

    /// Any curvature path: the moment stays within [Bη − M₀, Bη + M₀] (the initial curve and every
    /// reversal curve lie inside the spindle), and every reversal starts at the turning point.
    #[test]
    fn moment_never_leaves_the_spindle(
        b in 0.01f64..2.0,
        ratio in 0.0f64..1.5,
        path in prop::collection::vec(-3.0f64..3.0, 1..50),
    ) {
        let s = Spindle::from_kes(b, ratio * b).expect("valid");
        let tol = 1e-12 * (s.rigidity() * 300.0 + s.residual_moment());
        let mut st = BendingState::VIRGIN;
        for k in path {
            let eta = units::curvature_from_kes(k);
            let before = st;
            let m = st.update(&s, eta);
            let turn = before.curvature();
            prop_assert!((st.branch_moment(&s, turn) - before.branch_moment(&s, turn)).abs() <= 1e3 * tol);
            prop_assert!(m <= s.rising_branch(eta) + tol, "above the rising branch at {}", k);
            prop_assert!(m >= s.falling_branch(eta) - tol, "below the falling branch at {}", k);
        }
    }
}
