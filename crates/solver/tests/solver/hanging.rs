//! Scenes 7 and 8: a long hanging cloth at rest, and stress (stiff and limp fabrics, large Δt,
//! fast clamps, loose tolerances).

use atelier_fabric::AnisotropyForm;
use atelier_grid::{ClothTopology, StructuredGrid};
use atelier_solver::{
    Cloth, ClothState, InternalMethod, PinMotion, Solver, StepError, StepInput, StepParams,
    Tension, TolerancePolicy,
};
use nalgebra::Vector3;

use crate::common::fabric;

/// A 1 m × 1 m sheet, 2.5 cm grid (41 × 41 nodes), hung from its top edge; returns the state
/// after `seconds` and the mean internal-force iterations per step over the last second.
fn hang(method: InternalMethod, seconds: f64, cap: usize) -> (Cloth, ClothState, f64, f64) {
    hang_with(method, seconds, cap, false, Tension::default())
}

/// [`hang`], with or without long-range attachments.
fn hang_with(
    method: InternalMethod,
    seconds: f64,
    cap: usize,
    long_range: bool,
    tension: Tension,
) -> (Cloth, ClothState, f64, f64) {
    let f = fabric("cotton_broad");
    let n = 41;
    let topo =
        ClothTopology::from_structured(&StructuredGrid::sheet(n, n, 1.0, 1.0)).expect("grid");
    let mut cloth = Cloth::new(topo, &f, AnisotropyForm::Thesis).expect("cloth");
    let place = |[x, y]: [f64; 2]| Vector3::new(x, 0.0, y);
    for i in 0..n {
        let node = (n - 1) * n + i;
        let p = place(cloth.topology().rest_positions()[node]);
        cloth.pin(node as u32, p, PinMotion::Fixed).expect("pin");
    }
    let mut state = ClothState::placed(&cloth, place);
    let params = StepParams {
        damping: 1.0,
        internal: atelier_solver::InternalParams {
            method,
            max_iterations: cap,
            tension,
            ..atelier_solver::InternalParams::default()
        },
        shape: atelier_solver::ShapeParams {
            long_range_attachments: long_range,
            ..atelier_solver::ShapeParams::default()
        },
        ..StepParams::default()
    };
    let mut solver = Solver::new();
    let input = StepInput::default();
    let steps = (seconds / input.dt).round() as usize;
    let (mut iterations, mut counted, mut residual) = (0usize, 0usize, 0.0);
    for k in 0..steps {
        let r = solver
            .step(&cloth, &mut state, &params, input)
            .expect("step");
        if k + 100 >= steps {
            iterations += r.internal_iterations;
            counted += 1;
            residual = r.internal_residual;
        }
    }
    (cloth, state, iterations as f64 / counted as f64, residual)
}

/// Scene 7: hanging from one edge, at rest: every edge within 0.5 % of its target strain, and
/// no sag of the rows (each row of nodes level within 1 mm). The internal forces carry the
/// weight (E/E₀ small), so the shape constraints have nothing left to pull back.
#[test]
fn long_hanging_cloth_is_at_its_target_strains_and_rows_stay_level() {
    let (cloth, state, iterations, residual) = hang(InternalMethod::Accelerated, 3.0, 30);
    let mut solver = Solver::new();
    // One more step to read the targets at rest.
    let mut probe = state.clone();
    let r = solver
        .step(
            &cloth,
            &mut probe,
            &StepParams {
                damping: 1.0,
                ..StepParams::default()
            },
            StepInput::default(),
        )
        .expect("step");
    assert!(r.max_speed < 1e-3, "not at rest: {} m/s", r.max_speed);
    assert!(
        r.max_strain_error < 5e-3,
        "max |ε − ε̄| = {}",
        r.max_strain_error
    );
    let n = 41;
    let mut worst_row: f64 = 0.0;
    for j in 0..n {
        let z: Vec<f64> = (0..n).map(|i| probe.positions[j * n + i].z).collect();
        let spread =
            z.iter().cloned().fold(f64::MIN, f64::max) - z.iter().cloned().fold(f64::MAX, f64::min);
        worst_row = worst_row.max(spread);
    }
    eprintln!(
        "hanging 1 m sheet: max |ε − ε̄| {:.2e}, worst row spread {:.2e} m, E/E₀ {residual:.1e}, {iterations:.1} internal iterations per step at rest",
        r.max_strain_error, worst_row
    );
    assert!(worst_row < 1e-3, "rows sag by {worst_row} m");
    assert!(
        residual < 1e-3,
        "internal forces do not carry the weight: E/E₀ = {residual}"
    );
}

/// The accelerated internal-force method reaches the same balance with fewer iterations than
/// the thesis's steepest descent (recorded gain).
#[test]
fn accelerated_internal_forces_need_fewer_iterations_than_steepest_descent() {
    // The internal-force phase runs only when the edges' forces come from the balance
    // (`Tension::Balance`); the default takes them implicitly in the shape stage.
    let (_, _, fast, fast_res) = hang_with(
        InternalMethod::Accelerated,
        2.0,
        200,
        false,
        Tension::Balance,
    );
    let (_, _, slow, slow_res) = hang_with(
        InternalMethod::SteepestDescent,
        2.0,
        200,
        false,
        Tension::Balance,
    );
    eprintln!(
        "hanging sheet, last second: accelerated {fast:.1} iterations/step (E/E₀ {fast_res:.1e}), steepest descent {slow:.1} (E/E₀ {slow_res:.1e})"
    );
    assert!(fast < slow, "accelerated {fast} vs steepest {slow}");
}

/// The issue-10 peers' scene: a 1 m cotton sheet of `side × side` nodes pinned at the two
/// corners of one edge, falling from horizontal for `seconds` with the default step (with or
/// without long-range attachments); the largest axial stretch l/l⁰ − 1 over the run and the
/// share of steps that met the shape tolerance.
fn corner_pinned(side: usize, seconds: f64, long_range: bool) -> (f64, f64) {
    let f = fabric("cotton_broad");
    let grid = StructuredGrid::sheet(side, side, 1.0, 1.0);
    let topo = ClothTopology::from_structured(&grid).expect("grid");
    let mut cloth = Cloth::new(topo, &f, AnisotropyForm::Thesis).expect("cloth");
    for node in [(side - 1) * side, side * side - 1] {
        let [x, y] = grid.positions[node];
        cloth
            .pin(node as u32, Vector3::new(x, y, 0.0), PinMotion::Fixed)
            .expect("pin");
    }
    let mut state = ClothState::flat(&cloth, 0.0);
    let params = StepParams {
        shape: atelier_solver::ShapeParams {
            long_range_attachments: long_range,
            ..atelier_solver::ShapeParams::default()
        },
        ..StepParams::default()
    };
    let mut solver = Solver::new();
    let input = StepInput::default();
    let steps = (seconds / input.dt).round() as usize;
    let (mut converged, mut stretch) = (0usize, 0.0f64);
    for _ in 0..steps {
        let r = solver
            .step(&cloth, &mut state, &params, input)
            .expect("step");
        converged += usize::from(r.converged);
        stretch = stretch.max(
            atelier_solver::metrics::axial_strains(&cloth, &state.positions)
                .fold(f64::MIN, f64::max),
        );
    }
    (stretch, converged as f64 / steps as f64)
}

/// A sheet hanging from two corners carries its whole weight through two nodes. Issue 21: at
/// the defaults, without long-range attachments, the steps converge (≥ 99 %) on 50 × 50. (Before
/// the converged step the local iterations left it stretched by 57 % at 50 × 50, and only the
/// attachments held it.) The goal of a largest stretch ≤ 1 % is **not asserted: it is a
/// reported miss** (2.71 % here, 3.58 % on 100 × 100; `docs/validation.md`, "Corner-pinned
/// sheet"): a converged step holds every edge at the strain cotton broad's KES curve gives at the
/// force it carries, and the corners' edges, 1 cm wide, carry the swinging sheet's weight; the
/// goal was taken from peers whose springs are far stiffer than the measured fabric.
#[test]
fn a_sheet_pinned_at_two_corners_converges_without_long_range_attachments() {
    for (side, long_range) in [(50, false), (50, true)] {
        let (stretch, share) = corner_pinned(side, 1.5, long_range);
        eprintln!(
            "corner-pinned {side} × {side} sheet, 1.5 s, defaults, long-range {long_range}: largest stretch {:.3} % (goal ≤ 1 %, a reported miss), {:.1} % of steps converged",
            100.0 * stretch,
            100.0 * share
        );
        assert!(stretch.is_finite());
        assert!(share >= 0.99, "{:.1} % of steps converged", 100.0 * share);
    }
}

/// The same on 100 × 100 (1 cm cells); the stretch is reported, not asserted (above).
#[test]
#[ignore = "long: 10 000 nodes for 1.5 s, twice (over 3 minutes on 2 cores, session 19); the 50 × 50 sheet above is in CI"]
fn a_100x100_sheet_pinned_at_two_corners_converges() {
    let (stretch, share) = corner_pinned(100, 1.0, false);
    eprintln!(
        "corner-pinned 100 × 100 sheet, 1 s, defaults: largest stretch {:.3} % (goal ≤ 1 %, a reported miss), {:.1} % of steps converged",
        100.0 * stretch,
        100.0 * share
    );
    assert!(stretch.is_finite());
    assert!(share >= 0.99, "{:.1} % of steps converged", 100.0 * share);
}

/// The attachments' bound is implied by the converged constraints: the sheet hanging at rest
/// from its top edge (where the internal forces carry the weight and the constraints are met)
/// takes the same shape with them, within 0.1 mm.
#[test]
fn long_range_attachments_change_no_shape_at_rest() {
    let (_, without, ..) = hang_with(
        InternalMethod::Accelerated,
        3.0,
        30,
        false,
        Tension::default(),
    );
    let (_, with, ..) = hang_with(
        InternalMethod::Accelerated,
        3.0,
        30,
        true,
        Tension::default(),
    );
    let worst = without
        .positions
        .iter()
        .zip(&with.positions)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    eprintln!(
        "edge-hung sheet at rest: largest node distance with/without attachments {worst:.2e} m"
    );
    assert!(worst < 1e-4, "the attachments moved a node by {worst} m");
}

/// A cloth without pins: the attachments have nothing to hold, and the step is bit-identical.
#[test]
fn long_range_attachments_without_pins_change_nothing() {
    let f = fabric("cotton_broad");
    let grid = StructuredGrid::sheet(11, 11, 0.3, 0.3);
    let topo = ClothTopology::from_structured(&grid).expect("grid");
    let cloth = Cloth::new(topo, &f, AnisotropyForm::Thesis).expect("cloth");
    let run = |long_range| {
        let mut state = ClothState::flat(&cloth, 0.0);
        let input = StepInput {
            gravity: [1.0, 0.0, -9.8],
            ..StepInput::default()
        };
        let params = StepParams {
            shape: atelier_solver::ShapeParams {
                long_range_attachments: long_range,
                ..atelier_solver::ShapeParams::default()
            },
            ..StepParams::default()
        };
        let mut solver = Solver::new();
        for _ in 0..20 {
            solver
                .step(&cloth, &mut state, &params, input)
                .expect("step");
        }
        state.positions
    };
    assert_eq!(run(true), run(false));
}

/// The stress scene: a 0.5 m sheet (21 × 21 nodes) hanging from its top edge, which oscillates
/// sideways with amplitude 0.3 m at up to 5 m/s. Returns the cloth, its initial state and the
/// larger of the fabric's warp and weft EMT.
fn stress_scene(name: &str) -> (Cloth, ClothState, f64) {
    let f = fabric(name);
    let emt = f
        .tensile
        .warp
        .apex_strain()
        .max(f.tensile.weft.apex_strain());
    let n = 21;
    let topo =
        ClothTopology::from_structured(&StructuredGrid::sheet(n, n, 0.5, 0.5)).expect("grid");
    let mut cloth = Cloth::new(topo, &f, AnisotropyForm::Thesis).expect("cloth");
    let place = |[x, y]: [f64; 2]| Vector3::new(x, 0.0, y);
    let frequency = 5.0 / (2.0 * std::f64::consts::PI * 0.3);
    for i in 0..n {
        let node = (n - 1) * n + i;
        let p = place(cloth.topology().rest_positions()[node]);
        let motion = PinMotion::Oscillate {
            amplitude: [0.0, 0.3, 0.0],
            frequency,
        };
        cloth.pin(node as u32, p, motion).expect("pin");
    }
    let state = ClothState::placed(&cloth, place);
    (cloth, state, emt)
}

/// Scene 8: denim and silk, Δt up to 0.05 s, a clamped edge moving at 5 m/s, loosest
/// tolerances: never a non-finite value in the state; either the strain stays bounded
/// (< 3·EMT), or the step reports an error (and keeps the state), or every step that ends
/// beyond the bound says it did not meet its tolerance (issue 21: a step's report says whether
/// it converged; five iterations of the Newton step cannot follow a clamp that moves two
/// spacings per step, and silk at Δt 10 ms ends such steps 40 % stretched, flagged).
#[test]
fn stress_never_produces_non_finite_state() {
    for name in ["denim", "silk"] {
        let emt = stress_scene(name).2;
        for dt in [0.01, 0.02, 0.05] {
            let (cloth, mut state, _) = stress_scene(name);
            let input = StepInput::new(dt);
            let params = StepParams {
                tolerance_policy: TolerancePolicy::Adaptive {
                    loose_factor: 1.5,
                    fast_speed: 1.0,
                    slow_speed: 0.1,
                },
                internal: atelier_solver::InternalParams {
                    tolerance: 0.5,
                    max_iterations: 5,
                    ..atelier_solver::InternalParams::default()
                },
                shape: atelier_solver::ShapeParams {
                    tolerance: 1e-3,
                    max_iterations: 5,
                    collision_passes: 1,
                    ..atelier_solver::ShapeParams::default()
                },
                ..StepParams::default()
            };
            let mut solver = Solver::new();
            let mut outcome = "bounded";
            let mut worst: f64 = 0.0;
            // The largest strain at the end of a step that said it converged.
            let mut worst_converged: f64 = 0.0;
            for _ in 0..(1.0 / dt) as usize {
                let before = state.clone();
                match solver.step(&cloth, &mut state, &params, input) {
                    Ok(report) => {
                        assert!(
                            state
                                .positions
                                .iter()
                                .all(|p| p.iter().all(|x| x.is_finite()))
                        );
                        let strain = state.strains(&cloth).iter().cloned().fold(0.0, f64::max);
                        worst = worst.max(strain);
                        if report.converged {
                            worst_converged = worst_converged.max(strain);
                        }
                    }
                    Err(e) => {
                        assert!(
                            matches!(e, StepError::NonFinite { .. } | StepError::Diverged { .. }),
                            "{e}"
                        );
                        assert_eq!(state, before, "a failed step must keep the state");
                        outcome = "error";
                        break;
                    }
                }
            }
            if outcome == "bounded" && worst >= 3.0 * emt {
                outcome = "flagged";
            }
            eprintln!(
                "stress {name} Δt {dt}: {outcome}, max strain {worst:.3}, after converged steps {worst_converged:.3} (3·EMT = {:.3})",
                3.0 * emt
            );
            assert!(
                outcome == "error" || worst_converged < 3.0 * emt,
                "{name} Δt {dt}: strain {worst_converged} unbounded after a step that said it converged"
            );
        }
    }
}

/// Which solver the stability map runs.
#[derive(Clone, Copy, Debug)]
enum Which {
    Party,
    MassSpring,
    Xpbd,
}

/// Outcome of one stress run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Outcome {
    /// Every edge within 3·EMT for 1 s.
    Bounded,
    /// No error, but some edge beyond 3·EMT.
    LargeStrain,
    /// The solver stopped with an error (non-finite or diverging).
    Error,
}

/// Run the stress scene (0.5 m sheet, top edge oscillating at up to 5 m/s) for 0.5 s with one
/// solver at `dt`.
fn stress_run(name: &str, which: Which, dt: f64) -> Outcome {
    use atelier_solver::baselines::{MassSpring, MassSpringParams, Xpbd, XpbdParams};
    let (cloth, mut state, emt) = stress_scene(name);
    let steps = (0.5 / dt).round() as usize;
    let (mut party, mut ms, mut xp) = (Solver::new(), MassSpring::new(), Xpbd::new());
    let (party_params, ms_params, xp_params) = (
        StepParams::default(),
        MassSpringParams::default(),
        XpbdParams::default(),
    );
    let input = StepInput::new(dt);
    let mut outcome = Outcome::Bounded;
    for _ in 0..steps {
        let ok = match which {
            Which::Party => party.step(&cloth, &mut state, &party_params, input).is_ok(),
            Which::MassSpring => ms.step(&cloth, &mut state, &ms_params, input).is_ok(),
            Which::Xpbd => xp.step(&cloth, &mut state, &xp_params, input).is_ok(),
        };
        if !ok {
            return Outcome::Error;
        }
        assert!(
            state
                .positions
                .iter()
                .all(|p| p.iter().all(|x| x.is_finite()))
        );
        if state.strains(&cloth).iter().any(|s| s.abs() > 3.0 * emt) {
            outcome = Outcome::LargeStrain;
        }
    }
    outcome
}

/// The stability map of the stress scene with default settings: per fabric and solver, the
/// largest Δt (ladder 5e-4 … 5e-2 s, 0.5 s of motion) at which the run stays bounded (every edge within 3·EMT),
/// and the largest at which it ends without an error (recorded in docs/validation.md).
/// Asserted: PARTY is bounded somewhere on the ladder; a failed step never leaves non-finite
/// values (`stress_run`).
#[test]
fn largest_stable_time_step_per_solver() {
    let ladder = [5e-4, 1e-3, 2e-3, 5e-3, 1e-2, 2e-2, 5e-2];
    for name in ["denim", "silk"] {
        for which in [Which::Party, Which::MassSpring, Which::Xpbd] {
            let outcomes: Vec<(f64, Outcome)> = ladder
                .iter()
                .map(|&dt| (dt, stress_run(name, which, dt)))
                .collect();
            let bounded = outcomes
                .iter()
                .rev()
                .find(|o| o.1 == Outcome::Bounded)
                .map(|o| o.0);
            let no_error = outcomes
                .iter()
                .rev()
                .find(|o| o.1 != Outcome::Error)
                .map(|o| o.0);
            eprintln!(
                "stability {name} {which:?}: largest bounded Δt {bounded:?}, largest without error {no_error:?}; {outcomes:?}"
            );
            if matches!(which, Which::Party) {
                assert!(bounded.is_some(), "{name}: PARTY unbounded at every Δt");
            }
        }
    }
}
