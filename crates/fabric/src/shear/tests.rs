//! Tests of [`super`].

use super::*;
use approx::assert_relative_eq;

fn cotton() -> ShearLoop {
    ShearLoop::from_kes_units(1.5, 2.5, Some(4.5)).expect("valid")
}

#[test]
fn branches_and_widths_follow_the_kes_values() {
    let l = cotton();
    assert_relative_eq!(l.half_width(0.0), units::force_from_kes(1.25));
    assert_relative_eq!(l.half_width(0.3 * DEG), units::force_from_kes(1.25));
    assert_relative_eq!(
        l.half_width(2.75 * DEG),
        units::force_from_kes(1.75),
        max_relative = 1e-12
    );
    assert_relative_eq!(
        l.half_width(-7.0 * DEG),
        units::force_from_kes(2.25),
        max_relative = 1e-12
    );
    for g in [-0.1, -0.03, 0.004, 0.05, 0.12] {
        assert_relative_eq!(l.lower(-g), -l.upper(g), max_relative = 1e-15);
    }
    // Δ_j = 2HG/G = 2.5/1.5 degrees; initial slope 3G.
    assert_relative_eq!(l.join_angle(), 2.5 / 1.5 * DEG, max_relative = 1e-12);
    assert_relative_eq!(l.initial_slope(), 3.0 * l.stiffness(), max_relative = 1e-12);
}

#[test]
fn invalid_values_are_rejected() {
    let kind = |r: Result<ShearLoop, InvalidValue>| r.expect_err("invalid").kind;
    assert_eq!(
        kind(ShearLoop::from_kes(0.0, 1.0, None)),
        ErrorKind::OutOfRange
    );
    assert_eq!(
        kind(ShearLoop::from_kes(-1.0, 1.0, None)),
        ErrorKind::Negative
    );
    assert_eq!(
        kind(ShearLoop::from_kes(1.0, f64::NAN, None)),
        ErrorKind::NotFinite
    );
    assert_eq!(
        kind(ShearLoop::from_kes(1.0, 1.0, Some(-2.0))),
        ErrorKind::Negative
    );
    // The lower branch would fall: 2HG5 − 2HG > 2G·4.5°.
    assert_eq!(
        kind(ShearLoop::from_kes_units(0.5, 0.4, Some(5.0))),
        ErrorKind::Inconsistent
    );
}

#[test]
fn the_join_angle_is_capped_at_two_and_a_half_degrees() {
    let l = ShearLoop::from_kes_units(0.5, 4.0, None).expect("valid");
    assert_relative_eq!(l.join_angle(), MAX_JOIN_ANGLE, max_relative = 1e-15);
    assert!(l.initial_slope() > 3.0 * l.stiffness());
    // Without 2HG the width at 5° sets the join.
    let l = ShearLoop::from_kes_units(1.0, 0.0, Some(1.0)).expect("valid");
    assert_relative_eq!(l.join_angle(), 1.0 * DEG, max_relative = 1e-12);
    assert_relative_eq!(l.initial_slope(), l.stiffness(), max_relative = 1e-12);
}

#[test]
fn elastic_loop_is_linear_and_needs_no_state() {
    let l = ShearLoop::elastic(80.0).expect("valid");
    assert!(!l.is_hysteretic());
    let mut st = ShearState::VIRGIN;
    for g in [0.0, 0.05, -0.02, 0.1, 0.03] {
        assert_relative_eq!(st.update(&l, g), 80.0 * g, max_relative = 1e-15);
        assert_relative_eq!(st.tangent(&l, g), 80.0);
    }
    assert_relative_eq!(l.initial_slope(), 80.0);
    assert_relative_eq!(l.max_tangent(), 80.0);
}

#[test]
fn non_finite_angles_leave_the_state_alone() {
    let l = cotton();
    let mut st = ShearState::VIRGIN;
    st.update(&l, 0.02);
    let before = st;
    assert!(st.update(&l, f64::NAN).is_nan());
    assert!(st.stress(&l, f64::INFINITY).is_nan());
    assert!(st.tangent(&l, f64::NAN).is_nan());
    assert_eq!(st, before);
}

/// The alternative the module doc rejects: a curve that always joins smoothly, with its span
/// proportional to the distance left (constant initial slope). A small cycle a → b → a from
/// the lower branch then creates energy; the truncated Masing curve dissipates.
#[test]
fn a_smooth_join_from_inside_the_loop_would_create_energy() {
    let l = cotton();
    let (g, h) = (l.stiffness(), l.half_width(0.0));
    let dj = l.join_angle();
    let (a, b) = (0.0, 0.2 * dj);
    // Rising from the lower branch at a: the same curve in both models.
    let rising = |x: f64| {
        let q = 1.0 - progress((x - a) / dj);
        g * x + h - 2.0 * h * q.max(0.0)
    };
    // Falling from b; q₀ = its normalised distance from the lower branch.
    let q0 = (rising(b) - (g * b - h)) / (2.0 * h);
    let smooth = |x: f64| {
        let span = q0 * dj;
        let u = ((b - x) / span).min(1.0);
        g * x - h + 2.0 * h * q0 * (1.0 - u) * (1.0 - u)
    };
    // Onto the lower branch at a (falling from +0.2 rad), then up to b.
    let mut st = ShearState::VIRGIN;
    st.update(&l, 0.2);
    st.update(&l, a);
    assert_relative_eq!(st.stress(&l, a), l.lower(a), max_relative = 1e-12);
    st.update(&l, b);
    assert_relative_eq!(st.stress(&l, b), rising(b), max_relative = 1e-12);
    let n = 20_000;
    let dx = (b - a) / n as f64;
    let (mut w_smooth, mut w_masing) = (0.0, 0.0);
    for i in 0..n {
        let x = a + (i as f64 + 0.5) * dx;
        w_smooth += (rising(x) - smooth(x)) * dx;
        w_masing += (rising(x) - st.stress(&l, x)) * dx;
    }
    assert!(w_smooth < 0.0, "smooth-join cycle dissipates {w_smooth}");
    assert!(w_masing > 0.0, "Masing cycle dissipates {w_masing}");
}
