//! Tensile loops: KES identities, synthesis, measured tables and the minor-loop model (40).

use approx::assert_relative_eq;
use atelier_fabric::{Branch, TensileLoop, TensileState, TensileSummary, units};
use proptest::prelude::*;

fn summary(lt: f64, emt_percent: f64, rt_percent: f64) -> TensileSummary {
    TensileSummary {
        lt,
        emt: units::strain_from_percent(emt_percent),
        rt: units::strain_from_percent(rt_percent),
        f_max: units::KES_MAX_TENSILE_FORCE,
    }
}

/// Composite Simpson's rule with `n` (even) intervals.
fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    let h = (b - a) / n as f64;
    let inner: f64 = (1..n)
        .map(|i| f(a + i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 })
        .sum();
    (f(a) + f(b) + inner) * h / 3.0
}

/// KES identity: with Fm = 500 gf/cm and EMT in %, WT = 2.5·LT·EMT (gf·cm/cm²).
#[test]
fn wt_equals_2_5_lt_emt_in_kes_units() {
    for &(lt, emt) in &[(0.5, 2.0), (0.72, 3.0), (0.9, 15.0), (1.3, 7.5)] {
        let s = summary(lt, emt, 50.0);
        assert_relative_eq!(
            units::energy_to_kes(s.wt()),
            2.5 * lt * emt,
            max_relative = 1e-12
        );
    }
}

/// The synthetic curves of method §1.4, integrated with a fine quadrature, return LT, EMT and RT
/// (relative 1e-6).
#[test]
fn synthetic_curves_integrate_back_to_lt_emt_rt() {
    for &(lt, emt, rt) in &[
        (0.5, 3.0, 30.0),
        (0.68, 6.0, 45.0),
        (0.72, 3.0, 48.0),
        (0.9, 12.0, 80.0),
    ] {
        let s = summary(lt, emt, rt);
        assert_relative_eq!(s.loading_force(s.emt), s.f_max, max_relative = 1e-12);
        assert_relative_eq!(s.unloading_force(s.emt), s.f_max, max_relative = 1e-12);
        let wt = simpson(|e| s.loading_force(e), 0.0, s.emt, 20_000);
        let wt_back = simpson(|e| s.unloading_force(e), s.residual_strain(), s.emt, 20_000);
        let lt_measured = wt / (s.f_max * s.emt / 2.0);
        assert_relative_eq!(lt_measured, lt, max_relative = 1e-6);
        assert_relative_eq!(wt_back / wt, s.rt, max_relative = 1e-6);
        assert_relative_eq!(wt, s.wt(), max_relative = 1e-6);
    }
}

/// The tabulated loop (1024 quadratically spaced segments) keeps the summary: its exact
/// piecewise-linear energy returns LT and RT within 2e-6 and EMT exactly.
#[test]
fn tabulated_loop_returns_the_summary() {
    for &(lt, emt, rt) in &[(0.5, 3.0, 30.0), (0.72, 3.0, 48.0), (0.9, 12.0, 80.0)] {
        let s = summary(lt, emt, rt);
        let l = TensileLoop::from_summary(&s).expect("loop");
        let back = l.summary();
        assert_relative_eq!(back.emt, s.emt, max_relative = 1e-12);
        assert_relative_eq!(back.lt, lt, max_relative = 2e-6);
        assert_relative_eq!(back.rt, s.rt, max_relative = 2e-6);
        assert_relative_eq!(
            l.residual_strain(),
            s.residual_strain(),
            max_relative = 1e-12
        );
        // Between knots the table is within 1e-4·EMT of the closed form above 1 % of Fm.
        for i in 1..=200 {
            let f = s.f_max * (0.01 + 0.99 * i as f64 / 200.0);
            assert!((l.strain(Branch::Loading, f) - s.loading_strain(f)).abs() < 1e-4 * s.emt);
            assert!((l.strain(Branch::Unloading, f) - s.unloading_strain(f)).abs() < 1e-4 * s.emt);
        }
    }
}

/// A loop measured at 26 points per branch (sampled from a known curve) and resampled through
/// the monotone cubic reproduces the curve: strain within 1 % of EMT above 2 % of Fm, LT within
/// 1 %, RT within 2 %.
#[test]
fn measured_branches_are_interpolated_monotonically() {
    let s = summary(0.7, 5.0, 55.0);
    let sample = |g: &dyn Fn(f64) -> f64| -> Vec<(f64, f64)> {
        (0..=25)
            .map(|i| {
                let f = s.f_max * (i as f64 / 25.0).powi(2);
                (f, g(f))
            })
            .collect()
    };
    let up = sample(&|f| s.loading_strain(f));
    let down = sample(&|f| s.unloading_strain(f));
    let l = TensileLoop::from_measured(&up, &down).expect("measured loop");
    for i in 1..=100 {
        let f = s.f_max * (0.02 + 0.98 * i as f64 / 100.0);
        assert!((l.strain(Branch::Loading, f) - s.loading_strain(f)).abs() < 0.01 * s.emt);
    }
    let back = l.summary();
    assert_relative_eq!(back.lt, 0.7, max_relative = 0.01);
    assert_relative_eq!(back.rt, 0.55, max_relative = 0.02);
}

fn cotton_warp() -> TensileLoop {
    TensileLoop::from_summary(&summary(0.72, 3.0, 48.0)).expect("loop")
}

/// Unloading from a point on the loading branch follows the unloading branch scaled about the
/// origin (40): the ratio to the major branch is the constant λ = ε_t/ε_r, so the minor branch
/// ends at zero force at λ·ε_res, between the origin and the major residual strain.
#[test]
fn unloading_minor_branch_is_the_major_branch_scaled_about_the_origin() {
    let l = cotton_warp();
    let mut st = TensileState::VIRGIN;
    let f_t = 150.0;
    let eps_t = st.update(&l, f_t);
    st.update(&l, f_t - 1.0);
    let lambda = eps_t / l.strain(Branch::Unloading, f_t);
    assert_relative_eq!(st.scale(), lambda, max_relative = 1e-12);
    for &f in &[140.0, 100.0, 50.0, 10.0, 0.0] {
        assert_relative_eq!(
            st.branch_strain(&l, f) / l.strain(Branch::Unloading, f),
            lambda,
            max_relative = 1e-12
        );
    }
    let end = st.update(&l, 0.0);
    assert!(end > 0.0 && end < l.residual_strain());
}

/// Reloading after a partial unload heads for the apex (ε_m = apex strain) and rejoins the
/// major loop there; above Fm it follows the major loading branch.
#[test]
fn reloading_rejoins_the_major_loop_at_the_apex() {
    let l = cotton_warp();
    let fm = l.max_force();
    let mut st = TensileState::VIRGIN;
    st.update(&l, 0.8 * fm);
    st.update(&l, 0.3 * fm);
    let eps_turn = st.update(&l, 0.3 * fm + 1.0);
    assert!(st.scale() < 1.0 && st.scale() > 0.0);
    assert!(eps_turn > l.strain(Branch::Loading, 0.3 * fm + 1.0));
    assert_relative_eq!(st.update(&l, fm), l.apex_strain(), max_relative = 1e-12);
    assert_relative_eq!(
        st.update(&l, 1.05 * fm),
        l.strain(Branch::Loading, 1.05 * fm),
        max_relative = 1e-12
    );
    assert_relative_eq!(st.scale(), 1.0);
}

/// No return-point memory (method §1.1): reloading after a partial unload does not return to
/// the last turning point but passes below it.
#[test]
fn the_model_has_no_return_point_memory() {
    let l = cotton_warp();
    let mut st = TensileState::VIRGIN;
    let at_turn = st.update(&l, 200.0);
    st.update(&l, 100.0);
    let back = st.update(&l, 200.0);
    assert!((back - at_turn).abs() > 1e-6 * l.apex_strain());
}

/// A converged cycle between two forces dissipates energy ∮ f dε > 0 (and exactly 0 without
/// hysteresis).
fn cycle_energy(l: &TensileLoop, f_lo: f64, f_hi: f64) -> f64 {
    let mut st = TensileState::VIRGIN;
    st.update(l, f_hi);
    // Run cycles until the strain at f_hi repeats (the minor loops converge to a limit cycle).
    let mut last = f64::NAN;
    for _ in 0..200 {
        st.update(l, f_lo);
        let e = st.update(l, f_hi);
        if (e - last).abs() < 1e-14 {
            break;
        }
        last = e;
    }
    let n = 2000;
    let mut work = 0.0;
    let (mut f_prev, mut e_prev) = (f_hi, st.branch_strain(l, f_hi));
    let path = (1..=n)
        .map(|i| f_hi + (f_lo - f_hi) * i as f64 / n as f64)
        .chain((1..=n).map(|i| f_lo + (f_hi - f_lo) * i as f64 / n as f64));
    for f in path {
        let e = st.update(l, f);
        work += 0.5 * (f + f_prev) * (e - e_prev);
        (f_prev, e_prev) = (f, e);
    }
    work
}

#[test]
fn every_closed_cycle_dissipates_energy() {
    let l = cotton_warp();
    let fm = l.max_force();
    for &(a, b) in &[
        (0.0, 0.7),
        (0.2, 0.6),
        (0.5, 0.55),
        (0.05, 0.3),
        (0.3, 0.95),
    ] {
        let w = cycle_energy(&l, a * fm, b * fm);
        assert!(w > 0.0, "cycle {a}–{b} Fm: work {w}");
    }
    // The first load–unload cycle from rest traces the major loop: the work done is the loop's
    // area WT − WT′ = WT (1 − RT) (the strain does not close: it ends at ε_res).
    let s = l.summary();
    let mut st = TensileState::VIRGIN;
    let (mut work, mut f_prev, mut e_prev) = (0.0, 0.0, 0.0);
    for i in (1..=4000).chain((0..4000).rev()) {
        let f = fm * (i as f64 / 4000.0).powi(2);
        let e = st.update(&l, f);
        work += 0.5 * (f + f_prev) * (e - e_prev);
        (f_prev, e_prev) = (f, e);
    }
    assert_relative_eq!(
        work,
        s.lt * s.f_max * s.emt / 2.0 * (1.0 - s.rt),
        max_relative = 1e-4
    );
    // With the §1.4 synthesis (unloading = loading with the same exponent, shifted), reloading
    // from any point of the major unloading branch is the loading branch scaled about the apex
    // by (EMT − ε_res)/EMT, which *is* the unloading branch: cycles that reach Fm retrace it
    // after the first and dissipate nothing (docs/fabric.md).
    assert!(cycle_energy(&l, 0.0, fm).abs() < 1e-9 * s.wt());
    assert!(cycle_energy(&l, 0.3 * fm, fm).abs() < 1e-9 * s.wt());
    let elastic = TensileLoop::linear(2e4, fm).expect("linear");
    assert!(cycle_energy(&elastic, 0.1 * fm, 0.7 * fm).abs() < 1e-12);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]

    /// Random reversal sequences on random synthetic loops (LT 0.5–0.9, RT 30–80 %, EMT 1–15 %):
    /// the strain never leaves the major loop's envelope, and it is continuous at every reversal
    /// (the new branch passes through the turning point).
    #[test]
    fn random_reversals_stay_inside_the_major_loop(
        lt in 0.5f64..0.9,
        rt in 30.0f64..80.0,
        emt in 1.0f64..15.0,
        forces in prop::collection::vec(0.0f64..1.0, 1..40),
    ) {
        let l = TensileLoop::from_summary(&summary(lt, emt, rt)).expect("loop");
        let fm = l.max_force();
        let tol = 1e-12 * l.apex_strain();
        let mut st = TensileState::VIRGIN;
        for x in forces {
            let f = x * fm;
            let before = st;
            let eps = st.update(&l, f);
            // Continuity: the branch now travelled passes through the last turning point.
            let turn = before.force();
            prop_assert!((st.branch_strain(&l, turn) - before.branch_strain(&l, turn)).abs() <= 1e3 * tol);
            prop_assert!(eps >= l.strain(Branch::Loading, f) - tol, "below loading at f = {}", f);
            prop_assert!(eps <= l.strain(Branch::Unloading, f) + tol, "above unloading at f = {}", f);
        }
    }

    /// Every converged cycle between two forces dissipates energy (≥ 0, to rounding).
    #[test]
    fn random_cycles_dissipate_energy(
        lt in 0.5f64..0.9,
        rt in 30.0f64..80.0,
        a in 0.0f64..1.0,
        b in 0.0f64..1.0,
    ) {
        let l = TensileLoop::from_summary(&summary(lt, 5.0, rt)).expect("loop");
        let (lo, hi) = if a < b { (a, b) } else { (b, a) };
        let w = cycle_energy(&l, lo * l.max_force(), hi * l.max_force());
        prop_assert!(w >= -1e-9 * l.summary().wt(), "work {} for {}–{}", w, lo, hi);
    }

}

/// The reversal dead band (`TensileLoop::with_deadband`): a rising force with backward jitter
/// smaller than the band stays on the major loading branch (no minor loop, λ = 1), where the
/// same jitter without a band starts minor loops; a move back beyond the band starts a minor
/// loop at the band's edge, (40) through the point of the loading branch there, and the strain
/// is continuous across the edge.
#[test]
fn tensile_deadband_ignores_jitter_smaller_than_the_band() {
    let band = 2.0; // N/m
    let plain = cotton_warp();
    let l = cotton_warp().with_deadband(band);
    assert!((l.deadband() - band).abs() < 1e-15 && plain.deadband() == 0.0);
    let apex = l.apex_strain();
    let (mut st, mut st_plain) = (TensileState::VIRGIN, TensileState::VIRGIN);
    let mut plain_left_the_branch = false;
    for k in 1..=100 {
        let f = 3.0 * k as f64;
        for x in [f, f - 1.5] {
            let e = st.update(&l, x);
            assert_relative_eq!(e, l.strain(Branch::Loading, x), max_relative = 1e-12);
            assert_eq!(st.branch(), Branch::Loading);
            assert_relative_eq!(st.scale(), 1.0);
            let e_plain = st_plain.update(&plain, x);
            plain_left_the_branch |=
                (e_plain - plain.strain(Branch::Loading, x)).abs() > 1e-6 * apex;
        }
    }
    assert!(plain_left_the_branch);
    // Beyond the band: the minor loop starts at the edge, continuously.
    let top = st.force();
    assert_relative_eq!(top, 300.0);
    let edge = top - band;
    let (inside, outside) = (st.strain(&l, edge + 1e-9), st.strain(&l, edge - 1e-9));
    assert!(
        (inside - outside).abs() < 1e-9 * apex,
        "{inside} against {outside}"
    );
    st.update(&l, top - 3.0);
    assert_eq!(st.branch(), Branch::Unloading);
    let (eps_t, eps_r) = (
        l.strain(Branch::Loading, edge),
        l.strain(Branch::Unloading, edge),
    );
    assert_relative_eq!(st.scale(), eps_t / eps_r, max_relative = 1e-12);
    assert_relative_eq!(st.branch_strain(&l, edge), eps_t, max_relative = 1e-12);
    // Negative and NaN bands are no band.
    assert!(cotton_warp().with_deadband(-1.0).deadband() == 0.0);
    assert!(cotton_warp().with_deadband(f64::NAN).deadband() == 0.0);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 1000, ..ProptestConfig::default() })]

    /// With any dead band, random force sequences keep the strain inside the major loop, every
    /// reversal starts on the curve it leaves, and the peeked strain has no jump at the band's
    /// edge.
    #[test]
    fn deadband_keeps_the_strain_inside_and_continuous(
        lt in 0.5f64..0.9,
        rt in 30.0f64..80.0,
        band_fraction in 0.0f64..0.05,
        forces in prop::collection::vec(0.0f64..1.0, 1..40),
    ) {
        let base = TensileLoop::from_summary(&summary(lt, 5.0, rt)).expect("loop");
        let fm = base.max_force();
        let band = band_fraction * fm;
        let l = base.with_deadband(band);
        let tol = 1e-12 * l.apex_strain();
        let mut st = TensileState::VIRGIN;
        for x in forces {
            let f = x * fm;
            let before = st;
            let eps = st.update(&l, f);
            if st.branch() != before.branch() {
                // The reversal happened at the band's edge on the old curve.
                let edge = if before.branch() == Branch::Loading {
                    before.force() - band
                } else {
                    before.force() + band
                };
                prop_assert!((st.branch_strain(&l, edge) - before.branch_strain(&l, edge)).abs() <= 1e3 * tol);
            }
            let (lo, hi) = l.strains(f);
            prop_assert!(eps >= lo - tol && eps <= hi + tol);
            let edge = if st.branch() == Branch::Loading { st.force() - band } else { st.force() + band };
            if edge > 1e-6 * fm && edge < fm {
                let d = 1e-9 * fm;
                let jump = (st.strain(&l, edge + d) - st.strain(&l, edge - d)).abs();
                prop_assert!(jump <= 1e-6 * l.apex_strain(), "jump {} at the edge {}", jump, edge);
            }
        }
    }
}

// Its own block for its own reject limit: about 38 % of these draws are rejected, not passed
// (measured: 1 024 rejects against 1 587 passes before the default limit stopped it). The
// generator lets the unloading samples touch the loading ones (`ed.max(eu)`), and the PCHIP
// interpolants of two branches that touch at a knot cross just above it; `from_measured`
// refuses crossing branches, as it must. (Until issue 23 these draws returned Ok, i.e. passed.)
proptest! {
    #![proptest_config(ProptestConfig {
        cases: 2000,
        max_global_rejects: 2500,
        ..ProptestConfig::default()
    })]

    /// Measured-like loops (8 points per concave branch, random shapes): the minor branches (40)
    /// alone can leave the major loop here (by up to 10.1 % of EMT in 2000 random loops, see
    /// docs/fabric.md); the model clamps them to it. The strain stays inside and continuous.
    #[test]
    fn measured_loops_keep_minor_branches_inside(
        emt in 0.02f64..0.12,
        residual in 0.2f64..0.7,
        mut up_steps in prop::collection::vec(0.05f64..1.0, 8),
        mut down_steps in prop::collection::vec(0.05f64..1.0, 8),
        forces in prop::collection::vec(0.0f64..1.0, 1..40),
    ) {
        let fm = 490.0;
        up_steps.sort_by(|a, b| b.total_cmp(a));
        down_steps.sort_by(|a, b| b.total_cmp(a));
        let (su, sd): (f64, f64) = (up_steps.iter().sum(), down_steps.iter().sum());
        let res = residual * emt;
        let (mut up, mut down) = (vec![(0.0, 0.0)], vec![(0.0, res)]);
        let (mut eu, mut ed) = (0.0, res);
        for i in 0..8 {
            let f = fm * (i + 1) as f64 / 8.0;
            eu += emt * up_steps[i] / su;
            ed += (emt - res) * down_steps[i] / sd;
            up.push((f, eu));
            down.push((f, ed.max(eu)));
        }
        // Reject (not pass) the rare draws whose interpolated branches cross.
        let l = TensileLoop::from_measured(&up, &down);
        prop_assume!(l.is_ok());
        let l = l.expect("assumed");
        let tol = 1e-12 * emt;
        let mut st = TensileState::VIRGIN;
        for x in forces {
            let f = x * fm;
            let before = st;
            let eps = st.update(&l, f);
            let turn = before.force();
            prop_assert!((st.branch_strain(&l, turn) - before.branch_strain(&l, turn)).abs() <= 1e3 * tol);
            let (lo, hi) = l.strains(f);
            prop_assert!(eps >= lo - tol && eps <= hi + tol);
        }
    }
}
