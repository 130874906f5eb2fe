//! Orthotropic interpolation on whole loops and fabrics: exactness in the measured directions,
//! symmetry, agreement with plate theory, and the per-angle table.

use std::f64::consts::PI;

use approx::assert_relative_eq;
use atelier_fabric::anisotropy::interpolate;
use atelier_fabric::{
    AnisotropyForm, Branch, DEFAULT_LOCKING_ANGLE, Directions, Fabric, MaterialTable, Shear,
    TensileLoop, bias_from_shear, trellis_strain, units,
};

use crate::common::{FIXTURES, fixture};

const FORMS: [AnisotropyForm; 2] = [AnisotropyForm::Thesis, AnisotropyForm::Compliance];

fn same_loop(a: &TensileLoop, b: &TensileLoop, rel: f64) {
    for branch in [Branch::Loading, Branch::Unloading] {
        for (x, y) in a.knots(branch).iter().zip(b.knots(branch)) {
            assert!((x - y).abs() <= rel * (x.abs() + 1e-300), "{x} vs {y}");
        }
    }
}

/// Both forms return the measured loops at 0°, 45°, 90° and 135° (and the measured spindles).
#[test]
fn both_forms_are_exact_in_the_measured_directions() {
    for name in FIXTURES {
        let f = fixture(name);
        for form in FORMS {
            let at = |deg: f64| f.tensile_at(deg.to_radians(), form).expect("defined");
            same_loop(&at(0.0), &f.tensile.warp, 1e-12);
            same_loop(&at(90.0), &f.tensile.weft, 1e-12);
            same_loop(&at(45.0), &f.tensile.bias45, 1e-12);
            same_loop(&at(135.0), &f.tensile.bias135, 1e-12);
            for (deg, s) in [
                (0.0, f.bending.warp),
                (90.0, f.bending.weft),
                (45.0, f.bending.bias45),
                (135.0, f.bending.bias135),
            ] {
                let b = f.bending_at(f64::to_radians(deg), form).expect("defined");
                assert_relative_eq!(b.rigidity(), s.rigidity(), max_relative = 1e-12);
                assert_relative_eq!(
                    b.residual_moment(),
                    s.residual_moment(),
                    max_relative = 1e-12
                );
            }
        }
    }
}

/// θ and θ + 180° are the same line in the fabric: identical characteristics, at 11.25° steps.
#[test]
fn characteristics_are_symmetric_under_a_half_turn() {
    let f = fixture("denim");
    for form in FORMS {
        for k in 0..16 {
            let th = k as f64 * 11.25_f64.to_radians();
            same_loop(
                &f.tensile_at(th, form).expect("a"),
                &f.tensile_at(th + PI, form).expect("b"),
                1e-9,
            );
            let (a, b) = (
                f.bending_at(th, form).expect("a"),
                f.bending_at(th + PI, form).expect("b"),
            );
            assert_relative_eq!(a.rigidity(), b.rigidity(), max_relative = 1e-12);
        }
    }
}

/// A linear orthotropic sheet (E_v, E_u, G, ν = 0): the compliance form reproduces the plate-theory
/// law 1/E_θ = c⁴/E_v + s²c²/G + s⁴/E_u at every 11.25° step (to 1e-9), and the thesis form departs
/// from it by a recorded amount (largest relative strain difference 81.08 % for this cloth-like
/// material with a soft bias, at 22.5°; see docs/fabric.md).
#[test]
fn compliance_form_is_plate_theory_and_the_thesis_form_departs() {
    let (ev, eu, g) = (2.0e4, 1.0e4, 300.0); // N/m, N/m, N/(m·rad)
    let fm = units::KES_MAX_TENSILE_FORCE;
    let e45 = 4.0 / (1.0 / ev + 1.0 / eu + 1.0 / g);
    let lin = |e: f64| TensileLoop::linear(e, fm).expect("linear");
    let dirs = Directions {
        warp: lin(ev),
        weft: lin(eu),
        bias45: lin(e45),
        bias135: lin(e45),
    };
    let f = 100.0;
    let mut departure: f64 = 0.0;
    let mut worst_angle = 0.0;
    for k in 0..=16 {
        let th = k as f64 * 11.25_f64.to_radians();
        let (s, c) = th.sin_cos();
        let plate = f * (c.powi(4) / ev + s * s * c * c / g + s.powi(4) / eu);
        let b = dirs.bias_for(th);
        let strains = |br| {
            (
                dirs.warp.strain(br, f),
                dirs.weft.strain(br, f),
                b.strain(br, f),
            )
        };
        let (v, u, bb) = strains(Branch::Loading);
        let compliance = interpolate(AnisotropyForm::Compliance, th, v, u, bb).expect("defined");
        assert_relative_eq!(compliance, plate, max_relative = 1e-9);
        let thesis = interpolate(AnisotropyForm::Thesis, th, v, u, bb).expect("defined");
        let d = (thesis / plate - 1.0).abs();
        // The thesis form by hand (method.md §1: 1/ε_θ = Σ wᵢ/εᵢ with the weights c²(c²−s²),
        // 4s²c², s²(s²−c²)); for linear directions ε = f/E, so ε_θ = f/(Σ wᵢ·Eᵢ).
        let by_hand = f
            / (c * c * (c * c - s * s) * ev
                + 4.0 * s * s * c * c * e45
                + s * s * (s * s - c * c) * eu);
        let d_by_hand = (by_hand / plate - 1.0).abs();
        assert!(
            (d - d_by_hand).abs() < 1e-9,
            "at {}°: departure {d}, by hand {d_by_hand}",
            th.to_degrees()
        );
        if d > departure {
            departure = d;
            worst_angle = th.to_degrees();
        }
    }
    // docs/fabric.md prints the largest departure as 81.08 % (the by-hand value at 22.5°:
    // 1/(11 609.7 N/m × 4.5524e-4 m/N) − 1 = −0.8108).
    assert!(
        (departure - 0.8108).abs() < 5e-5,
        "thesis form departs by {departure} at {worst_angle}°"
    );
    assert!((worst_angle - 22.5).abs() < 1e-9 || (worst_angle - 157.5).abs() < 1e-9);
}

/// For bending the thesis (reciprocal) form is the plate-theory law for rigidity:
/// 1/B_θ = c⁴/B_v + (4/B₄₅ − 1/B_v − 1/B_u) s²c² + s⁴/B_u.
#[test]
fn thesis_form_is_plate_theory_for_bending_rigidity() {
    let f = fixture("denim");
    let (bv, bu, b45) = (
        f.bending.warp.rigidity(),
        f.bending.weft.rigidity(),
        f.bending.bias45.rigidity(),
    );
    for k in 0..8 {
        let th = k as f64 * 11.25_f64.to_radians();
        let (s, c) = th.sin_cos();
        let inv =
            c.powi(4) / bv + (4.0 / b45 - 1.0 / bv - 1.0 / bu) * s * s * c * c + s.powi(4) / bu;
        let b = f.bending_at(th, AnisotropyForm::Thesis).expect("defined");
        assert_relative_eq!(b.rigidity(), 1.0 / inv, max_relative = 1e-12);
    }
}

/// The bias loop derived from shear: at small force its compliance is
/// 1/E₄₅ = ¼(1/E_v + 1/E_u + 1/G) (method §1.4); at every force it is the closed form
/// ½ε_v(f/2) + ½ε_u(f/2) + √(1 + sin γ) − 1 with γ = γ_lock·tanh(τ/(Gγ_lock)), τ = f/2; and the
/// shear locking bounds it (no unbounded bias strain).
#[test]
fn bias_from_shear_matches_its_closed_form_and_the_small_strain_compliance() {
    let fm = units::KES_MAX_TENSILE_FORCE;
    let (ev, eu) = (2.0e4, 1.0e4);
    let shear = Shear {
        stiffness: units::shear_stiffness_from_kes(1.5),
        hysteresis: 0.0,
        hysteresis_5deg: None,
        locking_angle: DEFAULT_LOCKING_ANGLE,
    };
    let (warp, weft) = (
        TensileLoop::linear(ev, fm).expect("v"),
        TensileLoop::linear(eu, fm).expect("u"),
    );
    let bias = bias_from_shear(&warp, &weft, &shear).expect("bias");
    let (g, lock) = (shear.stiffness, shear.locking_angle);
    let closed = |f: f64| {
        0.25 * f * (1.0 / ev + 1.0 / eu) + trellis_strain(lock * (0.5 * f / (g * lock)).tanh())
    };
    for &f in &[0.01, 1.0, 10.0, 200.0, fm] {
        assert_relative_eq!(
            bias.strain(Branch::Loading, f),
            closed(f),
            max_relative = 1e-6
        );
    }
    let compliance = 0.25 * (1.0 / ev + 1.0 / eu + 1.0 / g);
    assert_relative_eq!(
        bias.strain(Branch::Loading, 0.01) / 0.01,
        compliance,
        max_relative = 1e-4
    );
    // Locked: at Fm the shear term is within 1 % of (and below) the trellis strain at the locking
    // angle, whatever G (a linear shear term, γ/2, would give 1.45 here).
    let shear_term = bias.apex_strain() - 0.25 * fm * (1.0 / ev + 1.0 / eu);
    assert!(shear_term < trellis_strain(lock) && shear_term > 0.99 * trellis_strain(lock));
    // With 2HG > 0 the loop opens: the unloading branch ends at the trellis strain of the
    // residual shear angle HG/G, and closes at the apex.
    let hyst = Shear {
        hysteresis: units::force_from_kes(2.5),
        ..shear
    };
    let l = bias_from_shear(&warp, &weft, &hyst).expect("bias");
    assert!(l.is_hysteretic());
    let residual = trellis_strain(lock * (0.5 * hyst.hysteresis / (g * lock)).tanh());
    assert_relative_eq!(l.residual_strain(), residual, max_relative = 1e-9);
    assert_relative_eq!(
        l.strain(Branch::Unloading, fm),
        l.apex_strain(),
        max_relative = 1e-9
    );
}

/// The material table builds one entry per distinct angle (mod 180°) and maps every edge to it.
#[test]
fn material_table_shares_entries_between_equal_angles() {
    let f: Fabric = fixture("cotton_broad");
    let angles = [
        0.0,
        PI / 2.0,
        PI,
        PI / 4.0,
        -PI / 4.0,
        3.0 * PI / 4.0,
        1e-12,
        0.3,
    ];
    let (table, idx) = MaterialTable::build(&f, AnisotropyForm::Thesis, &angles).expect("table");
    assert_eq!(table.len(), 5);
    assert_eq!(idx, vec![0, 1, 0, 2, 3, 3, 0, 4]);
    assert_relative_eq!(table.angle(idx[4]), 0.75 * PI, max_relative = 1e-12);
    same_loop(table.tensile(idx[1]), &f.tensile.weft, 1e-12);
}

/// Every fixture interpolates at every 11.25° step in both forms; where a branch dips (the
/// thesis form's sign-changing weights) the repair stays far below the 1 % limit.
#[test]
fn every_fixture_interpolates_at_every_angle() {
    let angles: Vec<f64> = (0..16).map(|k| (k as f64 * 11.25).to_radians()).collect();
    let mut worst: f64 = 0.0;
    for name in FIXTURES {
        let f = fixture(name);
        for form in FORMS {
            let (table, idx) = MaterialTable::build(&f, form, &angles).expect("all angles defined");
            assert_eq!(table.len(), 16);
            for &i in &idx {
                worst = worst.max(table.repair(i));
            }
        }
    }
    assert!(worst < 1e-3, "largest repair {worst}");
}

/// The plate-theory form is the compliance form for tensile loops and the reciprocal (thesis)
/// form for bending, and it is valid for every fixture at every half degree, where the thesis
/// form is not (it turns the cotton's loop inside out near 52.5°).
#[test]
fn plate_theory_form_is_valid_at_every_angle() {
    for name in FIXTURES {
        let f = fixture(name);
        let angles: Vec<f64> = (0..360).map(|k| (k as f64 * 0.5).to_radians()).collect();
        let (table, idx) =
            MaterialTable::build(&f, AnisotropyForm::PlateTheory, &angles).expect("every angle");
        assert!(
            idx.iter().all(|&i| table.repair(i) < 1e-3),
            "{name}: large repair"
        );
        let th = 0.3;
        same_loop(
            &f.tensile_at(th, AnisotropyForm::PlateTheory).expect("a"),
            &f.tensile_at(th, AnisotropyForm::Compliance).expect("b"),
            1e-12,
        );
        let (a, b) = (
            f.bending_at(th, AnisotropyForm::PlateTheory).expect("a"),
            f.bending_at(th, AnisotropyForm::Thesis).expect("b"),
        );
        assert_relative_eq!(a.rigidity(), b.rigidity(), max_relative = 1e-12);
    }
    let cotton = fixture("cotton_broad");
    assert!(
        cotton
            .tensile_at(52.5_f64.to_radians(), AnisotropyForm::Thesis)
            .is_err()
    );
}

/// Binning the edge angles to `MaterialTable::ANGLE_RESOLUTION` (0.1°) moves an edge's angle by
/// at most half a bin. Over every fixture, at every degree, half a bin changes the loading strain
/// at 10 %, 50 % and 100 % of the maximum force by at most 1.03 % of itself (polyester faille at
/// 5° and 10 % of the force, where the strain climbs steeply away from the stiff warp), at most
/// 4.9e-4 in strain; and the bending rigidity by at most 0.06 %.
#[test]
fn half_an_angle_bin_changes_the_characteristics_little() {
    let half = 0.5 * MaterialTable::ANGLE_RESOLUTION;
    let (mut relative, mut absolute, mut rigidity): (f64, f64, f64) = (0.0, 0.0, 0.0);
    for name in FIXTURES {
        let f = fixture(name);
        for k in 0..180 {
            let theta = (k as f64).to_radians();
            let form = AnisotropyForm::PlateTheory;
            let (a, b) = (
                f.tensile_at(theta, form).expect("a"),
                f.tensile_at(theta + half, form).expect("b"),
            );
            for frac in [0.1, 0.5, 1.0] {
                let force = frac * a.max_force();
                let (ea, eb) = (
                    a.strain(Branch::Loading, force),
                    b.strain(Branch::Loading, force),
                );
                relative = relative.max(((ea - eb) / ea).abs());
                absolute = absolute.max((ea - eb).abs());
            }
            let (ba, bb) = (
                f.bending_at(theta, form).expect("a").rigidity(),
                f.bending_at(theta + half, form).expect("b").rigidity(),
            );
            rigidity = rigidity.max(((ba - bb) / ba).abs());
        }
    }
    eprintln!(
        "half a bin: strain {relative:.2e} relative, {absolute:.2e} absolute; rigidity {rigidity:.2e}"
    );
    assert!(relative < 0.011 && absolute < 6e-4 && rigidity < 1e-3);
}
