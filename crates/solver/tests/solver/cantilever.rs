//! Scene 3: the Peirce cantilever (ASTM D1388, JIS L 1096) against the exact heavy elastica
//! (`reference/elastica.md`), refined: a strip overhanging by L = (λ·B/w)^(1/3) droops so that the
//! chord from the platform edge to the tip makes the elastica's angle for λ = wL³/B. The test
//! solves the elastica itself (a shooting solve below, checked against the reference table), so
//! the reference is independent of the library.

use atelier_fabric::{AnisotropyForm, Fabric, Spindle, units};
use atelier_grid::{ClothTopology, StructuredGrid};
use atelier_solver::{Cloth, ClothState, PinMotion, Solver, StepInput, StepParams};
use nalgebra::Vector3;

use crate::common::fabric;

/// The heavy elastica, non-dimensional (σ = s/L): θ'' = −λ(1 − σ) cos θ, θ(0) = 0, θ'(1) = 0,
/// θ the tangent's angle below the horizontal. Shooting on θ'(0) by bisection, RK4 on `n` steps,
/// the centreline by the trapezoidal rule. Returns the points (x, y)/L from the clamp.
fn heavy_elastica(lambda: f64, n: usize) -> Vec<(f64, f64)> {
    let h = 1.0 / n as f64;
    let shoot = |k: f64, keep: bool| -> (f64, Vec<(f64, f64)>) {
        let rhs = |s: f64, th: f64, w: f64| (w, -lambda * (1.0 - s) * th.cos());
        let (mut th, mut w, mut x, mut y) = (0.0f64, k, 0.0, 0.0);
        let mut points = vec![(0.0, 0.0)];
        for i in 0..n {
            let s = i as f64 * h;
            let (a1, b1) = rhs(s, th, w);
            let (a2, b2) = rhs(s + h / 2.0, th + h / 2.0 * a1, w + h / 2.0 * b1);
            let (a3, b3) = rhs(s + h / 2.0, th + h / 2.0 * a2, w + h / 2.0 * b2);
            let (a4, b4) = rhs(s + h, th + h * a3, w + h * b3);
            let next = th + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4);
            w += h / 6.0 * (b1 + 2.0 * b2 + 2.0 * b3 + b4);
            if keep {
                x += 0.5 * h * (th.cos() + next.cos());
                y += 0.5 * h * (th.sin() + next.sin());
                points.push((x, y));
            }
            th = next;
        }
        (w, points)
    };
    // θ'(1) rises with θ'(0) = k; the root lies in (0, λ/2].
    let (mut lo, mut hi) = (0.0, 0.5 * lambda);
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if shoot(mid, false).0 > 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    shoot(0.5 * (lo + hi), true).1
}

/// Chord angle of the elastica at λ, degrees.
fn chord_angle(lambda: f64) -> f64 {
    let tip = *heavy_elastica(lambda, 4000).last().expect("points");
    tip.1.atan2(tip.0).to_degrees()
}

/// λ = wL³/B whose elastica has the chord angle `degrees` (bisection).
fn lambda_for_chord(degrees: f64) -> f64 {
    let (mut lo, mut hi) = (1e-3, 50.0);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if chord_angle(mid) < degrees {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The test's own elastica against `reference/elastica.md`: λ for 41.5° and 45.0°, the tip of the
/// 41.5° strip, and the small-deflection limit y/L = λ/8.
#[test]
fn the_shooting_elastica_reproduces_the_reference_table() {
    let l415 = lambda_for_chord(41.5);
    let l45 = lambda_for_chord(45.0);
    assert!((l415 / 8.00420 - 1.0).abs() < 1e-5, "41.5°: λ {l415}");
    assert!((l45 / 9.25381 - 1.0).abs() < 1e-5, "45°: λ {l45}");
    let tip = *heavy_elastica(8.00420, 4000).last().expect("tip");
    assert!(
        (tip.0 - 0.7243).abs() < 1e-4 && (tip.1 - 0.6408).abs() < 1e-4,
        "{tip:?}"
    );
    let small = heavy_elastica(0.01, 4000).last().expect("tip").1;
    assert!((small / (0.01 / 8.0) - 1.0).abs() < 1e-3, "{small}");
}

/// Which grain direction runs along the strip.
#[derive(Clone, Copy, Debug)]
enum Along {
    Warp,
    Weft,
}

/// The strip of `segments` cells along `along`, 1 cm wide (two nodes across), clamped by its
/// first two rows pinned at ±h/2 about the platform edge x = 0, straight and horizontal: the
/// cloth, its state, h and the nodes along it. The tip is at x = `length`.
fn strip(f: &Fabric, along: Along, length: f64, segments: usize) -> (Cloth, ClothState, usize) {
    let h = length / (segments as f64 + 0.5);
    let nv = segments + 2;
    let mut grid = StructuredGrid::sheet(2, nv, 0.01, (nv - 1) as f64 * h);
    // The sheet's warp runs along v (the strip); turn the grain for a weft strip.
    if let Along::Weft = along {
        grid.grain_angle = 0.0;
    }
    let topo = ClothTopology::from_structured(&grid).expect("grid");
    let mut cloth = Cloth::new(topo, f, AnisotropyForm::Thesis).expect("cloth");
    let place = |[x, y]: [f64; 2]| Vector3::new(y - 0.5 * h, x, 0.0);
    for node in 0..4 {
        let p = place(cloth.topology().rest_positions()[node]);
        cloth.pin(node as u32, p, PinMotion::Fixed).expect("pin");
    }
    let state = ClothState::placed(&cloth, place);
    (cloth, state, nv)
}

/// The outcome of one strip lowered into the elastica.
#[derive(Debug)]
struct Rest {
    /// Chord angle from the platform edge to the tip, degrees.
    chord: f64,
    /// Whether every node was slower than `REST_SPEED` for `REST_HOLD` and the chord moved by
    /// less than `REST_CHORD` over that time.
    at_rest: bool,
    /// Simulated time, s.
    time: f64,
    /// Steps, and those that did not meet the step's tolerances.
    steps: usize,
    unconverged: usize,
}

/// Rest: every node slower than 1 mm/s for 0.5 s (above the tolerance's noise floor,
/// ε^e·h/Δt ≤ 4e-5 m/s here), and the chord still by 0.005° over that time.
const REST_SPEED: f64 = 1e-3;
const REST_HOLD: f64 = 0.5;
const REST_CHORD: f64 = 5e-3;

/// Lower the strip into its elastica at the default step (Δt 10 ms for every refinement) with
/// elastic bending (the elastica has no hysteresis) and light damping (it shortens the run; the
/// rest shape of an elastic strip does not depend on it), until at rest or 20 s.
fn simulate(f: &Fabric, along: Along, length: f64, segments: usize, tolerance: f64) -> Rest {
    let (cloth, mut state, nv) = strip(f, along, length, segments);
    let params = StepParams {
        damping: 1.0,
        hysteresis: false,
        shape: atelier_solver::ShapeParams {
            tolerance,
            ..atelier_solver::ShapeParams::default()
        },
        ..StepParams::default()
    };
    let mut solver = Solver::new();
    let chord = |s: &ClothState| {
        let tip = (s.positions[2 * nv - 1] + s.positions[2 * nv - 2]) * 0.5;
        (-tip.z).atan2(tip.x).to_degrees()
    };
    let (mut steps, mut unconverged) = (0, 0);
    let mut calm: Option<(f64, f64)> = None;
    let mut at_rest = false;
    while state.time < 20.0 {
        let r = solver
            .step(&cloth, &mut state, &params, StepInput::default())
            .unwrap_or_else(|e| panic!("{segments} cells: {e}"));
        steps += 1;
        unconverged += usize::from(!r.converged);
        if r.max_speed < REST_SPEED {
            let (since, from) = *calm.get_or_insert((state.time, chord(&state)));
            if state.time - since >= REST_HOLD {
                at_rest = (chord(&state) - from).abs() < REST_CHORD;
                if at_rest {
                    break;
                }
                calm = None;
            }
        } else {
            calm = None;
        }
    }
    Rest {
        chord: chord(&state),
        at_rest,
        time: state.time,
        steps,
        unconverged,
    }
}

/// A fabric outside the fixtures (issue 21's probe): B 0.25 gf·cm²/cm along the warp, 0.15 along
/// the weft, W 19 mg/cm², elastic; the rest from the cotton broad fixture.
fn heavy_fabric() -> Fabric {
    let mut f = fabric("cotton_broad");
    f.name = "B 0.25/0.15 gf·cm²/cm, W 19 mg/cm²".into();
    f.mass_per_area = units::mass_per_area_from_kes(19.0);
    let spindle = |b: f64| Spindle::new(units::rigidity_from_kes(b), 0.0).expect("spindle");
    f.bending.warp = spindle(0.25);
    f.bending.weft = spindle(0.15);
    f.bending.bias45 = spindle((0.25f64 * 0.15).sqrt());
    f.bending.bias135 = f.bending.bias45.clone();
    f
}

/// Issue 21, item 2: 10, 20, 40, 80 and 160 cells at the default Δt — every run stable and at
/// rest when measured, at least 99 % of its steps converged, the chord error falling with
/// refinement (or already within 0.02°), and within 0.3° of the elastica from 80 cells; at the
/// 41.5° overhang (cotton broad, warp) and at overhangs whose angle the test computes itself:
/// 30° (cotton broad) and 45° along the warp and the weft of a fabric outside the fixtures (the
/// weft strip of the issue diverged at 80 cells before). Also: a ten times tighter tolerance
/// moves the 40-cell chord by at most 0.1° (item 1).
#[test]
fn cantilever_refined_converges_to_the_elastica() {
    let cases: [(Fabric, Along, f64, &str); 4] = [
        (
            fabric("cotton_broad"),
            Along::Warp,
            41.5,
            "cotton broad, warp",
        ),
        (
            fabric("cotton_broad"),
            Along::Warp,
            30.0,
            "cotton broad, warp",
        ),
        (heavy_fabric(), Along::Warp, 45.0, "B 0.25, W 19, warp"),
        (heavy_fabric(), Along::Weft, 45.0, "B 0.15, W 19, weft"),
    ];
    for (f, along, angle, label) in &cases {
        let lambda = lambda_for_chord(*angle);
        let b = match along {
            Along::Warp => f.bending.warp.rigidity(),
            Along::Weft => f.bending.weft.rigidity(),
        };
        let length = (lambda * b / f.weight_per_area()).cbrt();
        let mut errors = Vec::new();
        for segments in [10, 20, 40, 80, 160] {
            let rest = simulate(f, *along, length, segments, 1e-4);
            let error = rest.chord - angle;
            eprintln!(
                "cantilever {label} at {angle}° (λ {lambda:.5}, L {:.2} cm), {segments} cells: chord {:.3}°, error {error:+.3}°, at rest {} at {:.2} s, {} of {} steps unconverged",
                length * 100.0,
                rest.chord,
                rest.at_rest,
                rest.time,
                rest.unconverged,
                rest.steps
            );
            assert!(
                rest.at_rest,
                "{label}, {segments} cells: not at rest: {rest:?}"
            );
            assert!(
                rest.unconverged * 100 <= rest.steps,
                "{label}, {segments} cells: {rest:?}"
            );
            if let Some(&last) = errors.last() {
                let last: f64 = last;
                assert!(
                    error.abs() <= last.abs() || error.abs() <= 0.02,
                    "{label}: error {error} at {segments} cells after {last}"
                );
            }
            if segments >= 80 {
                assert!(error.abs() <= 0.3, "{label}, {segments} cells: {error}°");
            }
            errors.push(error);
        }
    }
    // Tolerance ten times tighter, 40 cells, 41.5°.
    let f = fabric("cotton_broad");
    let length = (lambda_for_chord(41.5) * f.bending.warp.rigidity() / f.weight_per_area()).cbrt();
    let (loose, tight) = (
        simulate(&f, Along::Warp, length, 40, 1e-4),
        simulate(&f, Along::Warp, length, 40, 1e-5),
    );
    eprintln!(
        "cantilever tolerance 1e-4 → 1e-5 (40 cells): {:.4}° → {:.4}°",
        loose.chord, tight.chord
    );
    assert!(
        (loose.chord - tight.chord).abs() <= 0.1,
        "{loose:?} {tight:?}"
    );
}

/// With bending hysteresis (the default) the wool strip comes to rest, and it droops less than
/// the elastic strip: its loading curve lies above Bη (`reference/fabric-data.md` §5).
#[test]
fn a_hysteretic_strip_comes_to_rest_above_the_elastic_one() {
    let f = fabric("wool_tropical");
    let length = (lambda_for_chord(41.5) * f.bending.warp.rigidity() / f.weight_per_area()).cbrt();
    let (cloth, mut state, nv) = strip(&f, Along::Warp, length, 20);
    let params = StepParams {
        damping: 1.0,
        ..StepParams::default()
    };
    let mut solver = Solver::new();
    let mut fastest = f64::INFINITY;
    while state.time < 5.0 {
        fastest = solver
            .step(&cloth, &mut state, &params, StepInput::default())
            .expect("step")
            .max_speed;
    }
    let tip = (state.positions[2 * nv - 1] + state.positions[2 * nv - 2]) * 0.5;
    let chord = (-tip.z).atan2(tip.x).to_degrees();
    let elastic = simulate(&f, Along::Warp, length, 20, 1e-4).chord;
    eprintln!(
        "hysteretic wool strip: fastest node {fastest:.2e} m/s at 5 s, chord {chord:.2}° (elastic {elastic:.2}°)"
    );
    assert!(fastest < REST_SPEED, "still moving at {fastest} m/s");
    assert!(chord < elastic, "chord {chord} against {elastic}");
}
