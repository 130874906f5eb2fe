//! Scenes 4 and 5: virtual KES tests. The simulated strip, loaded the way the KES-FB
//! instruments load a specimen, must give back the characteristics it was built from.

use atelier_fabric::{AnisotropyForm, Branch, TensileState, units};
use atelier_solver::kes::{self, Direction};

use crate::common::fabric;

/// The KES-FB1 tensile specimen along the warp ([`kes::tensile_test`]): the mean strain of the
/// interior warp edges after holding each force of `path` (gf/cm) for `hold` steps.
fn tensile_test(name: &str, path: &[f64], hold: usize) -> Vec<(f64, f64)> {
    let f = fabric(name);
    let si: Vec<f64> = path.iter().map(|&k| units::force_from_kes(k)).collect();
    let curve =
        kes::tensile_test(&f, AnisotropyForm::Thesis, Direction::Warp, &si, hold).expect("runs");
    path.iter()
        .zip(&curve.points)
        .map(|(&k, &(_, strain))| (k, strain))
        .collect()
}

/// The strain the tensile model itself gives along `path` (gf/cm), edge by edge.
fn model_strains(name: &str, path: &[f64]) -> Vec<f64> {
    let l = fabric(name).tensile.warp;
    let mut st = TensileState::VIRGIN;
    path.iter()
        .map(|&f| st.update(&l, units::force_from_kes(f)))
        .collect()
}

/// A quasi-static path: `0 → peak → 0` in steps of 5 gf/cm.
fn cycle(peak: f64) -> Vec<f64> {
    let up = (1..=(peak / 5.0) as usize).map(|k| 5.0 * k as f64);
    let down = (0..(peak / 5.0) as usize).rev().map(|k| 5.0 * k as f64);
    up.chain(down).collect()
}

/// Scene 4: loaded to 500 gf/cm and back, and a partial cycle to 250 gf/cm, the strip returns
/// the input loading and unloading curves and the minor loop within 2 % strain at ten force
/// levels each; and the loop's KES values (EMT, LT, WT, RT) those of the input loop.
#[test]
fn virtual_kes_tensile_test_recovers_the_loops() {
    for name in ["cotton_broad", "silk"] {
        let l = fabric(name).tensile.warp;
        let full = cycle(500.0);
        let sim = tensile_test(name, &full, 3);
        let model = model_strains(name, &full);
        let mut checked = 0;
        let mut worst: f64 = 0.0;
        for (k, (&(force, strain), &expect)) in sim.iter().zip(&model).enumerate() {
            let loading = k < 100;
            if force % 50.0 != 0.0 || force == 0.0 && loading {
                continue;
            }
            // The model along the path is the major loop: loading, then unloading from Fm.
            let branch = if loading {
                Branch::Loading
            } else {
                Branch::Unloading
            };
            let major = l.strain(branch, units::force_from_kes(force));
            assert!(
                (expect - major).abs() < 1e-9,
                "{name}: path model off the major loop"
            );
            let err = (strain - expect).abs() / expect;
            assert!(
                err < 0.02,
                "{name} at {force} gf/cm ({branch:?}): simulated {strain:.5}, input {expect:.5} ({:.2} %)",
                100.0 * err
            );
            checked += 1;
            worst = worst.max(err);
        }
        assert_eq!(checked, 20, "{name}: ten levels on each branch");
        eprintln!(
            "KES tensile {name}: largest strain error on the major loop {:.2e} (relative)",
            worst
        );
        // The loop's KES values against the model's along the same path.
        let si = |pts: &[(f64, f64)]| -> Vec<(f64, f64)> {
            pts.iter()
                .map(|&(f, e)| (units::force_from_kes(f), e))
                .collect()
        };
        let simulated = kes::values_of(&si(&sim));
        let input = kes::values_of(
            &full
                .iter()
                .zip(&model)
                .map(|(&f, &e)| (units::force_from_kes(f), e))
                .collect::<Vec<_>>(),
        );
        eprintln!("KES tensile {name}: simulated {simulated:?}, input {input:?}");
        for (what, a, b) in [
            ("EMT", simulated.emt, input.emt),
            ("LT", simulated.lt, input.lt),
            ("WT", simulated.wt, input.wt),
            ("RT", simulated.rt, input.rt),
        ] {
            assert!((a / b - 1.0).abs() < 0.03, "{name} {what}: {a} vs {b}");
        }
        // Partial cycle to 250 gf/cm: the minor unloading branch of (40).
        let partial = cycle(250.0);
        let sim = tensile_test(name, &partial, 3);
        let model = model_strains(name, &partial);
        let minor: Vec<(f64, f64, f64)> = sim
            .iter()
            .zip(&model)
            .skip(50)
            .filter(|((f, _), _)| f % 25.0 == 0.0)
            .map(|(&(f, s), &m)| (f, s, m))
            .collect();
        assert_eq!(minor.len(), 10);
        let mut worst_minor: f64 = 0.0;
        for (force, strain, expect) in minor {
            let err = (strain - expect).abs() / expect;
            worst_minor = worst_minor.max(err);
            assert!(
                err < 0.02,
                "{name} minor loop at {force} gf/cm: {strain:.5} vs {expect:.5}"
            );
            // And it lies strictly inside the major loop.
            let f = units::force_from_kes(force);
            assert!(
                expect < l.strain(Branch::Unloading, f)
                    && expect >= l.strain(Branch::Loading, f) - 1e-12
            );
        }
    }
}

/// Scene 5: the KES-FB2 bending test on a simulated strip ([`kes::bending_test`]): B (slope
/// over 0.5–1.5 cm⁻¹) and 2HB (loop width at ±1 cm⁻¹) within 5 % of the fabric's, along the
/// warp and across it.
#[test]
fn virtual_kes_bending_test_recovers_b_and_2hb() {
    for (name, direction) in [
        ("cotton_broad", Direction::Warp),
        ("wool_tropical", Direction::Warp),
        ("denim", Direction::Weft),
    ] {
        let f = fabric(name);
        let curve = kes::bending_test(&f, AnisotropyForm::Thesis, direction, 500).expect("runs");
        let spindle = match direction {
            Direction::Warp => &f.bending.warp,
            Direction::Weft => &f.bending.weft,
        };
        let (b, two_hb) = (curve.rigidity, curve.two_hb);
        let (b_in, hb_in) = (spindle.rigidity(), 2.0 * spindle.residual_moment());
        eprintln!(
            "KES bending {name} {direction:?}: B {:.4} (input {:.4}) gf·cm²/cm, 2HB {:.4} (input {:.4}) gf·cm/cm",
            units::rigidity_to_kes(b),
            units::rigidity_to_kes(b_in),
            units::moment_to_kes(two_hb),
            units::moment_to_kes(hb_in)
        );
        assert!((b / b_in - 1.0).abs() < 0.05, "{name}: B {b} vs {b_in}");
        assert!(
            (two_hb / hb_in - 1.0).abs() < 0.05,
            "{name}: 2HB {two_hb} vs {hb_in}"
        );
    }
}
