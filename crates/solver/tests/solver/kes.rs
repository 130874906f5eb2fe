//! Scenes 4 and 5: virtual KES instruments (issue 21). The simulated specimen, clamped and
//! driven the way the KES-FB instruments drive it and read from its clamps' reactions, must give
//! back the KES values of the fabric it was built from.

use atelier_fabric::{AnisotropyForm, Fabric, units};
use atelier_solver::kes::{self, Direction, ShearProtocol, ShearValues};

use crate::common::fabric;

const FIXTURES: [&str; 7] = [
    "cotton_broad",
    "wool_tropical",
    "polyester_tropical",
    "polyester_faille",
    "polyester_satin_wet",
    "silk",
    "denim",
];

/// The fabric's KES shear values (SI).
fn shear_input(f: &Fabric) -> ShearValues {
    let s = f.shear.as_ref().expect("a shear section");
    ShearValues {
        g: s.stiffness,
        two_hg: s.hysteresis,
        two_hg5: s.hysteresis_5deg.unwrap_or(s.hysteresis),
    }
}

/// The virtual KES-FB1 shear test at `protocol` on `f`, with the run's diagnostics printed.
fn shear(name: &str, f: &Fabric, protocol: &ShearProtocol) -> ShearValues {
    let clock = std::time::Instant::now();
    let c = kes::shear_test(f, AnisotropyForm::Thesis, protocol).expect("runs");
    let v = c.values;
    eprintln!(
        "KES shear {name}: G {:.4} gf/(cm·deg), 2HG {:.4} gf/cm, 2HG5 {:.4} gf/cm; pull within \
         {:.2} % of the pretension (rms {:.2} %); {} steps ({} above the tolerance, worst {:.1e} at {:?}) in {:.1?}",
        units::shear_stiffness_to_kes(v.g),
        units::force_to_kes(v.two_hg),
        units::force_to_kes(v.two_hg5),
        100.0 * c.tension_error,
        100.0 * c.tension_rms_error,
        c.steps,
        c.stats.shape_unconverged,
        c.stats.worst_violation,
        c.stats.worst,
        clock.elapsed()
    );
    v
}

/// Relative errors of G, 2HG, 2HG5.
fn errors(got: &ShearValues, want: &ShearValues) -> [(&'static str, f64); 3] {
    [
        ("G", got.g / want.g - 1.0),
        ("2HG", got.two_hg / want.two_hg - 1.0),
        ("2HG5", got.two_hg5 / want.two_hg5 - 1.0),
    ]
}

/// The fabric with `t` added to its KES G: loaded into a cloth, its cells then carry the whole
/// KES G (the cloth takes the material's share, G − T, `Fabric::material_shear_loop`).
fn cells_with_the_kes_g(f: &Fabric, t: f64) -> Fabric {
    let mut f = f.clone();
    f.shear.as_mut().expect("shear section").stiffness += t;
    f
}

/// Scene 4a, KES-FB1 shear (`kes::shear_test`): the cloth's cells carry the material's share
/// of the KES loop (G − T: KES G includes the pretension's T·tan γ, which the specimen's tilted
/// warp supplies by itself), and the moving clamp's reaction gives back the fabric's KES G, 2HG
/// and 2HG5 within 5 %.
#[test]
fn virtual_kes_shear_test_recovers_g_2hg_2hg5() {
    shear_recovers(&["cotton_broad", "polyester_faille"]);
}

/// The claim of scene 4a on `names`.
fn shear_recovers(names: &[&str]) {
    for &name in names {
        let f = fabric(name);
        let got = shear(name, &f, &ShearProtocol::default());
        for (what, err) in errors(&got, &shear_input(&f)) {
            assert!(
                err.abs() < 0.05,
                "{name} {what}: {:.2} % off the fabric's KES value",
                100.0 * err
            );
        }
    }
}

/// Scene 4a on wool and polyester tropical.
#[test]
fn virtual_kes_shear_test_recovers_the_tropicals() {
    shear_recovers(&["wool_tropical", "polyester_tropical"]);
}

/// Scene 4a on the wet satin, silk and denim.
#[test]
fn virtual_kes_shear_test_recovers_satin_silk_denim() {
    shear_recovers(&["polyester_satin_wet", "silk", "denim"]);
}

/// Scene 4b, why the cells carry G − T: cells resisting with the whole KES G (as they did before
/// `Fabric::material_shear_loop`) report G plus the pretension's term T (10 gf/cm per radian,
/// 0.1745 gf/(cm·deg)) — the term counted twice, once in the KES G and once by the tilted warp;
/// G misses the fabric's by +11 % (cotton) and +35 % (faille). Asserted: G is G_KES + T within
/// 5 %, and the widths (the term is elastic) are the fabric's within 5 %.
#[test]
fn virtual_kes_shear_test_counts_the_pretension_twice_with_the_kes_g_in_the_cells() {
    let t = ShearProtocol::default().tension;
    for name in ["cotton_broad", "polyester_faille"] {
        let f = fabric(name);
        let got = shear(
            name,
            &cells_with_the_kes_g(&f, t),
            &ShearProtocol::default(),
        );
        let want = shear_input(&f);
        eprintln!(
            "KES shear {name}, cells with the KES G: G {:.2} % off the fabric's KES G, {:.2} % off G + T; the \
             excess is {:.4} T",
            100.0 * (got.g / want.g - 1.0),
            100.0 * (got.g / (want.g + t) - 1.0),
            (got.g - want.g) / t
        );
        let double = ShearValues {
            g: want.g + t,
            ..want
        };
        for (what, err) in errors(&got, &double) {
            assert!(err.abs() < 0.05, "{name} {what}: {:.2} %", 100.0 * err);
        }
    }
}

/// Scene 4c: the shear test is quasi-static — halving the rate (twice the steps at the same
/// Δt) changes G, 2HG and 2HG5 by less than 1 %.
#[test]
fn virtual_kes_shear_test_is_quasi_static() {
    let name = "cotton_broad";
    let f = fabric(name);
    let base = ShearProtocol::default();
    let slow = ShearProtocol {
        rate: 0.5 * base.rate,
        ..base
    };
    let (a, b) = (shear(name, &f, &base), shear(name, &f, &slow));
    for (what, err) in errors(&b, &a) {
        eprintln!(
            "KES shear {name}: halving the rate changes {what} by {:.3} %",
            100.0 * err
        );
        assert!(err.abs() < 0.01, "{name} {what}: {:.2} %", 100.0 * err);
    }
}

/// Scene 5, KES-FB1 tensile (`kes::fb1_tensile_test`): pulled to F_m = 500 gf/cm and back at
/// the KES strain rate, the moving clamp's reaction against its displacement gives back the
/// fabric's EMT, LT, WT and RT within 2 %.
///
/// Failed until session 10: the shape stage's Newton iteration started every step from zero
/// multipliers, so it read every loaded edge at zero force, a reversal onto the stiff minor
/// unloading branch, and ended with the edges in compression (the clamp read −47 N/m at 0.2 %
/// strain where the fabric has +4.4). A first pass that ends above the tolerance is now solved
/// again with the rows of loaded edges started at their committed force (`ShapeSolver::solve`).
#[test]
fn virtual_kes_tensile_test_recovers_emt_lt_wt_rt() {
    for (name, direction) in [
        ("cotton_broad", Direction::Warp),
        ("polyester_faille", Direction::Warp),
        ("silk", Direction::Warp),
        ("denim", Direction::Weft),
    ] {
        let f = fabric(name);
        let clock = std::time::Instant::now();
        let curve = kes::fb1_tensile_test(
            &f,
            AnisotropyForm::Thesis,
            direction,
            &kes::TensileProtocol::default(),
        )
        .expect("runs");
        let input = kes::input_values(match direction {
            Direction::Warp => &f.tensile.warp,
            Direction::Weft => &f.tensile.weft,
        });
        let got = curve.kes_values();
        eprintln!(
            "KES tensile {name} {direction:?}: EMT {:.3} % (input {:.3}), LT {:.4} ({:.4}), WT {:.4} \
             ({:.4}) gf·cm/cm², RT {:.2} % ({:.2}); {} steps ({} above the tolerance) in {:.1?}",
            100.0 * got.emt,
            100.0 * input.emt,
            got.lt,
            input.lt,
            units::energy_to_kes(got.wt),
            units::energy_to_kes(input.wt),
            100.0 * got.rt,
            100.0 * input.rt,
            curve.steps,
            curve.stats.shape_unconverged,
            clock.elapsed()
        );
        for (what, a, b) in [
            ("EMT", got.emt, input.emt),
            ("LT", got.lt, input.lt),
            ("WT", got.wt, input.wt),
            ("RT", got.rt, input.rt),
        ] {
            assert!(
                (a / b - 1.0).abs() < 0.02,
                "{name} {what}: {a} vs {b} ({:.2} %)",
                100.0 * (a / b - 1.0)
            );
        }
    }
}

/// The KES-FB2 test on `name` along `direction` with `per_leg` steps per 2.5 cm⁻¹: (B, 2HB)
/// and their inputs, printed.
fn bending(name: &str, direction: Direction, per_leg: usize) -> ((f64, f64), (f64, f64)) {
    let f = fabric(name);
    let clock = std::time::Instant::now();
    let curve = kes::bending_test(&f, AnisotropyForm::Thesis, direction, per_leg).expect("runs");
    let spindle = match direction {
        Direction::Warp => &f.bending.warp,
        Direction::Weft => &f.bending.weft,
    };
    let input = (spindle.rigidity(), 2.0 * spindle.residual_moment());
    eprintln!(
        "KES bending {name} {direction:?}: B {:.4} (input {:.4}) gf·cm²/cm, 2HB {:.4} (input {:.4}) \
         gf·cm/cm; clamp force ≤ {:.1e} N/m; {} steps ({} above the tolerance, worst {:.1e} at \
         {:?}) in {:.1?}",
        units::rigidity_to_kes(curve.rigidity),
        units::rigidity_to_kes(input.0),
        units::moment_to_kes(curve.two_hb),
        units::moment_to_kes(input.1),
        curve.max_clamp_force,
        curve.steps,
        curve.stats.shape_unconverged,
        curve.stats.worst_violation,
        curve.stats.worst,
        clock.elapsed()
    );
    ((curve.rigidity, curve.two_hb), input)
}

/// Scene 6, KES-FB2 bending (`kes::bending_test`): one clamp held, the other turned through
/// 0 → +2.5 → −2.5 → 0 cm⁻¹ with the interior free; the moving clamp's reaction moment gives
/// back B (slope over 0.5–1.5 cm⁻¹) and 2HB (width at ±1 cm⁻¹) within 5 %, every fixture along
/// the warp and, where it differs, the weft.
#[test]
fn virtual_kes_bending_test_recovers_b_and_2hb() {
    for name in FIXTURES {
        let f = fabric(name);
        let mut directions = vec![Direction::Warp];
        let differs = |a: f64, b: f64| (a / b - 1.0).abs() > 1e-9;
        if differs(f.bending.weft.rigidity(), f.bending.warp.rigidity())
            || differs(
                f.bending.weft.residual_moment(),
                f.bending.warp.residual_moment(),
            )
        {
            directions.push(Direction::Weft);
        }
        for direction in directions {
            let ((b, two_hb), (b_in, two_hb_in)) = bending(name, direction, 250);
            assert!(
                (b / b_in - 1.0).abs() < 0.05,
                "{name} {direction:?}: B {b} vs {b_in}"
            );
            assert!(
                (two_hb / two_hb_in - 1.0).abs() < 0.05,
                "{name} {direction:?}: 2HB {two_hb} vs {two_hb_in}"
            );
        }
    }
}

/// Scene 6b: the bending test is quasi-static — halving the rate changes B and 2HB by less
/// than 1 %.
#[test]
fn virtual_kes_bending_test_is_quasi_static() {
    let ((b1, h1), _) = bending("cotton_broad", Direction::Warp, 250);
    let ((b2, h2), _) = bending("cotton_broad", Direction::Warp, 500);
    eprintln!(
        "KES bending cotton_broad: halving the rate changes B by {:.3} %, 2HB by {:.3} %",
        100.0 * (b2 / b1 - 1.0),
        100.0 * (h2 / h1 - 1.0)
    );
    assert!((b2 / b1 - 1.0).abs() < 0.01 && (h2 / h1 - 1.0).abs() < 0.01);
}
