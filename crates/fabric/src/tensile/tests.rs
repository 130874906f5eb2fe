//! Tests of [`super`].

use super::*;
use approx::assert_relative_eq;

fn cotton() -> TensileSummary {
    TensileSummary {
        lt: 0.7,
        emt: 0.05,
        rt: 0.5,
        f_max: crate::units::KES_MAX_TENSILE_FORCE,
    }
}

#[test]
fn lookup_is_exact_at_knots_and_inverse_round_trips() {
    let l = TensileLoop::from_summary(&cotton()).expect("loop");
    for j in [0, 1, 7, 100, 513, TABLE_SEGMENTS] {
        let f = l.knot_force(j);
        assert_relative_eq!(
            l.strain(Branch::Loading, f),
            l.knots(Branch::Loading)[j],
            max_relative = 1e-12
        );
    }
    for &f in &[0.01, 1.0, 37.5, 200.0, 490.0] {
        for b in [Branch::Loading, Branch::Unloading] {
            let e = l.strain(b, f);
            assert_relative_eq!(l.force(b, e), f, max_relative = 1e-9);
        }
    }
}

#[test]
fn extrapolates_linearly_above_the_apex_and_clamps_below_zero() {
    let l = TensileLoop::from_summary(&cotton()).expect("loop");
    let fm = l.max_force();
    let slope =
        (l.strain(Branch::Loading, fm) - l.strain(Branch::Loading, fm * 0.999)) / (0.001 * fm);
    let above = l.strain(Branch::Loading, 1.1 * fm);
    assert_relative_eq!(
        above,
        l.apex_strain() + slope * 0.1 * fm,
        max_relative = 1e-3
    );
    assert!(!l.in_range(1.1 * fm));
    assert_relative_eq!(l.strain(Branch::Unloading, -5.0), l.residual_strain());
    assert!(l.strain(Branch::Loading, f64::NAN).is_nan());
}

#[test]
fn invalid_tables_are_rejected_with_their_kind() {
    let n = TABLE_SEGMENTS + 1;
    let up: Vec<f64> = (0..n).map(|j| j as f64).collect();
    let mut bad = up.clone();
    bad[5] = 1.0;
    let e = TensileLoop::from_knots(1.0, bad, up.clone()).expect_err("non-monotone");
    assert_eq!(e.kind, ErrorKind::NonMonotone);
    let below: Vec<f64> = up.iter().map(|e| e * 0.5).collect();
    let e = TensileLoop::from_knots(1.0, up.clone(), below).expect_err("crossing");
    assert_eq!(e.kind, ErrorKind::Inconsistent);
    let e = TensileLoop::from_knots(f64::NAN, up.clone(), up.clone()).expect_err("nan");
    assert_eq!(e.kind, ErrorKind::OutOfRange);
}

/// A seeded uniform generator in [0, 1) (xorshift64).
fn xorshift(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The minor-loop formula (40) itself, without the envelope clamp, stays inside the major
/// loop for synthetic loops (LT 0.5–0.9, RT 30–80 %, EMT 1–15 %): 2000 random reversal
/// sequences of 40 forces (`method.md` §1.1 reports the same for its check).
#[test]
fn unclamped_minor_loops_stay_inside_synthetic_loops() {
    let mut uniform = xorshift(0x1234_5678);
    for _ in 0..2000 {
        let s = TensileSummary {
            lt: 0.5 + 0.4 * uniform(),
            emt: 0.01 + 0.14 * uniform(),
            rt: 0.3 + 0.5 * uniform(),
            f_max: crate::units::KES_MAX_TENSILE_FORCE,
        };
        let l = TensileLoop::from_summary(&s).expect("loop");
        let tol = 1e-12 * s.emt;
        let mut st = TensileState::VIRGIN;
        for _ in 0..40 {
            let f = uniform() * s.f_max;
            st.update(&l, f);
            let e = st.eval_unclamped(&l, f);
            let (lo, hi) = l.strains(f);
            assert!(
                e >= lo - tol && e <= hi + tol,
                "{e} outside [{lo}, {hi}] at f = {f}"
            );
        }
    }
}

/// Why the clamp exists: on measured-like loops (8 points per concave branch, random shapes,
/// 2000 loops × 40 random forces) the unclamped formula (40) leaves the major loop, by more
/// than 1 % of EMT at worst (10.1 % with this seed; docs/fabric.md). The clamped model, which
/// callers see, stays inside (integration test `measured_loops_keep_minor_branches_inside`).
#[test]
fn unclamped_minor_loops_can_leave_measured_loops() {
    let mut uniform = xorshift(7);
    let mut worst: f64 = 0.0;
    for _ in 0..2000 {
        let (fm, emt) = (490.0, 0.02 + 0.1 * uniform());
        let res = emt * (0.2 + 0.5 * uniform());
        let mut steps = |n: usize| {
            let mut v: Vec<f64> = (0..n).map(|_| uniform() + 0.05).collect();
            v.sort_by(|a, b| b.total_cmp(a));
            let total: f64 = v.iter().sum();
            v.into_iter().map(|x| x / total).collect::<Vec<f64>>()
        };
        let (su, sd) = (steps(8), steps(8));
        let (mut up, mut down) = (vec![(0.0, 0.0)], vec![(0.0, res)]);
        let (mut eu, mut ed) = (0.0, res);
        for i in 0..8 {
            let f = fm * (i + 1) as f64 / 8.0;
            eu += emt * su[i];
            ed += (emt - res) * sd[i];
            up.push((f, eu));
            down.push((f, ed.max(eu)));
        }
        let Ok(l) = TensileLoop::from_measured(&up, &down) else {
            continue;
        };
        let mut st = TensileState::VIRGIN;
        for _ in 0..40 {
            let f = uniform() * fm;
            st.update(&l, f);
            let e = st.eval_unclamped(&l, f);
            let (lo, hi) = l.strains(f);
            worst = worst.max((lo - e).max(e - hi) / emt);
        }
    }
    assert!(worst > 0.01, "largest excursion {worst} of EMT");
}

#[test]
fn linear_toe_is_a_chord_and_keeps_the_rest() {
    let l = TensileLoop::from_summary(&cotton()).expect("loop");
    let f0 = 0.01 * l.max_force();
    let t = l.with_linear_toe(f0);
    for &f in &[0.1 * f0, 0.5 * f0, 0.9 * f0] {
        let chord = l.strain(Branch::Loading, f0) * f / f0;
        assert!((t.strain(Branch::Loading, f) - chord).abs() < 1e-6 * l.apex_strain());
        assert!(t.strain(Branch::Loading, f) < l.strain(Branch::Loading, f));
        assert!(t.strain(Branch::Unloading, f) >= t.strain(Branch::Loading, f));
    }
    // From the knot after f0 on (the segment straddling f0 blends the chord and the curve).
    for &f in &[1.05 * f0, 2.0 * f0, 0.5 * l.max_force(), l.max_force()] {
        assert_relative_eq!(
            t.strain(Branch::Loading, f),
            l.strain(Branch::Loading, f),
            max_relative = 1e-9
        );
        assert_relative_eq!(
            t.strain(Branch::Unloading, f),
            l.strain(Branch::Unloading, f),
            max_relative = 1e-9
        );
    }
    assert_relative_eq!(t.residual_strain(), l.residual_strain());
    // Finite initial compliance: the strain at a tiny force is proportional to it.
    let tiny = 1e-6 * f0;
    assert!(t.strain(Branch::Loading, tiny) < 1e-5 * l.apex_strain());
}

/// The loader accepts branches that cross or fall back by a rounding-level amount (1e-9 of the
/// apex strain, 1e-12 relative), and repairs them, so a strain on the major loop lies inside it:
/// a measured-loop property test drew a loop whose loading strain lay 6.1e-10 of the apex strain
/// above the unloading one at knot 1023 (the draw is kept in
/// `tests/proptest-regressions/tensile.txt`).
#[test]
fn rounding_level_crossings_are_repaired_at_load() {
    let n = TABLE_SEGMENTS;
    let mut load: Vec<f64> = (0..=n).map(|j| 0.05 * j as f64 / n as f64).collect();
    let mut unload: Vec<f64> = load.iter().map(|e| 0.01 + 0.04 * e / 0.05).collect();
    unload[n] = load[n] - 2e-10 * load[n];
    load[n - 1] = load[n - 2] - 1e-13 * load[n - 2];
    let l = TensileLoop::from_knots(490.0, load, unload).expect("within the rounding tolerances");
    for j in 0..=n {
        let (lo, hi) = l.strains(l.knot_force(j));
        assert!(lo <= hi, "knot {j}: loading {lo} above unloading {hi}");
        if j > 0 {
            let prev = l.strains(l.knot_force(j - 1));
            assert!(lo >= prev.0 && hi >= prev.1, "knot {j}: a branch falls");
        }
    }
}
