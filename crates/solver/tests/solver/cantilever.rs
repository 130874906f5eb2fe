//! Scene 3: the Peirce cantilever (ASTM D1388, JIS L 1096) against the exact heavy elastica
//! (`reference/elastica.md`): a strip overhanging by 2.0003·c, c = (B/w)^(1/3), droops so that the
//! chord from the platform edge to the tip makes 41.5° with the horizontal.

use atelier_fabric::AnisotropyForm;
use atelier_fit::cloth::elastica;
use atelier_grid::{ClothTopology, StructuredGrid};
use atelier_solver::{Cloth, ClothState, PinMotion, Solver, StepParams};
use nalgebra::Vector3;

use crate::common::fabric;

/// The strip of `segments` cells along the warp, 1 cm wide, clamped by its first two rows at
/// ±h/2 about the platform edge, straight: the cloth, its state, h and the nodes along it.
fn strip(name: &str, length: f64, segments: usize) -> (Cloth, ClothState, f64, usize) {
    let f = fabric(name);
    let h = length / (segments as f64 + 0.5);
    let nv = segments + 2;
    let topo =
        ClothTopology::from_structured(&StructuredGrid::sheet(2, nv, 0.01, (nv - 1) as f64 * h))
            .expect("grid");
    let mut cloth = Cloth::new(topo, &f, AnisotropyForm::Thesis).expect("cloth");
    let place = |[x, y]: [f64; 2]| Vector3::new(y - 0.5 * h, x, 0.0);
    for node in 0..4 {
        let p = place(cloth.topology().rest_positions()[node]);
        cloth.pin(node as u32, p, PinMotion::Fixed).expect("pin");
    }
    let state = ClothState::placed(&cloth, place);
    (cloth, state, h, nv)
}

/// One simulated cantilever: a strip of `segments` cells along the warp, two nodes wide (1 cm),
/// clamped by two rows of pinned nodes at ±h/2 about the platform edge x = 0 (the discrete slope
/// between them is zero exactly at the edge, which makes the clamp second order; clamping at
/// x = 0 and −h puts the effective clamp h/2 behind the edge and the angle converges at first
/// order, 47.6° / 44.9° / 43.5° for 10 / 20 / 40 cells), its tip at x = `length`, run to rest.
/// Returns the centreline (x, droop) of the free part and the chord angle from the edge.
fn simulate(
    name: &str,
    length: f64,
    segments: usize,
    hysteresis: bool,
    damping: f64,
) -> (Vec<(f64, f64)>, f64) {
    let (cloth, mut state, h, nv) = strip(name, length, segments);
    // Implicit bending keeps this stable up to about 0.4·h s/m; 0.25·h leaves a margin.
    let dt = 0.25 * h;
    let params = StepParams {
        dt,
        damping,
        hysteresis,
        ..StepParams::default()
    };
    let mut solver = Solver::new();
    let mut t = 0.0;
    loop {
        let r = solver.step(&cloth, &mut state, &params).expect("step");
        t += dt;
        if (t > 1.5 && r.max_speed < 5e-3) || t > 6.0 {
            break;
        }
    }
    let centre: Vec<(f64, f64)> = (1..nv)
        .map(|j| {
            let m = (state.positions[2 * j] + state.positions[2 * j + 1]) * 0.5;
            (m.x, -m.z)
        })
        .collect();
    let tip = centre[centre.len() - 1];
    (centre, tip.1.atan2(tip.0).to_degrees())
}

/// Scene 3: for three published fabrics, refinement h, h/2, h/4: the chord angle converges to
/// the elastica's 41.5° (finest grid or Richardson within 1°), the observed order is reported, and
/// the finest centreline lies within 2 % of the length of the elastica's.
#[test]
fn cantilever_droops_to_the_elastica() {
    let reference = elastica(8.00420, 4000);
    for name in ["cotton_broad", "wool_tropical", "polyester_faille"] {
        let f = fabric(name);
        let c = (f.bending.warp.rigidity() / f.weight_per_area()).cbrt();
        let length = 2.0003 * c;
        let runs: Vec<(Vec<(f64, f64)>, f64)> = [10, 20, 40]
            .iter()
            .map(|&n| simulate(name, length, n, false, 1.0))
            .collect();
        let angles: Vec<f64> = runs.iter().map(|r| r.1).collect();
        let order = ((angles[0] - angles[1]) / (angles[1] - angles[2])).log2();
        let richardson = angles[2] + (angles[2] - angles[1]) / (2f64.powf(order) - 1.0);
        eprintln!(
            "cantilever {name}: c = {:.4} cm, chord angle {:.2}° / {:.2}° / {:.2}° (10/20/40 cells), order {order:.2}, Richardson {richardson:.2}°",
            c * 100.0,
            angles[0],
            angles[1],
            angles[2]
        );
        assert!(
            (angles[2] - 41.5).abs() < 1.0 || (richardson - 41.5).abs() < 1.0,
            "{name}: {angles:?}, Richardson {richardson}"
        );
        // Centreline of the finest run against the elastica at the same arclength: the free
        // node j lies at arclength (j − ½)h from the edge, h = L/(n + ½).
        let (centre, _) = &runs[2];
        let n = centre.len() - 1;
        let h = length / (n as f64 + 0.5);
        let mut worst: f64 = 0.0;
        for (k, &(x, y)) in centre.iter().enumerate() {
            let sigma = ((k as f64 + 0.5) * h / length).min(1.0);
            let idx = (sigma * (reference.len() - 1) as f64).round() as usize;
            let (ex, ey) = reference[idx];
            worst = worst.max(((x - ex * length).powi(2) + (y - ey * length).powi(2)).sqrt());
        }
        eprintln!(
            "cantilever {name}: centreline within {:.2} % of the length",
            100.0 * worst / length
        );
        assert!(
            worst < 0.02 * length,
            "{name}: centreline off by {:.2} % of L",
            100.0 * worst / length
        );
        // Bending hysteresis, 20 cells, for the report. Released and swinging (light damping),
        // the strip overshoots, turns back onto the falling branch (M lower by 2M₀) and can end
        // more drooped; lowered slowly it stays nearer the initial curve, stiffer than the
        // elastic line at small curvature (reference/fabric-data.md §5).
        let (_, swinging) = simulate(name, length, 20, true, 1.0);
        let (_, slow) = simulate(name, length, 20, true, 20.0);
        let (_, slow_elastic) = simulate(name, length, 20, false, 20.0);
        eprintln!(
            "cantilever {name}: with bending hysteresis (20 cells) {swinging:.2}° released, {slow:.2}° lowered slowly; elastic {:.2}° / {slow_elastic:.2}°",
            angles[1]
        );
        // Reported, not asserted: with hysteresis the rest shape depends on the path (measured:
        // cotton 39.7° lowered slowly against 41.9° elastic, wool 42.6° against 42.1°).
        assert!(swinging.is_finite() && slow.is_finite());
    }
}

/// With bending hysteresis the strip comes to rest. The curve after a turning point is steeper
/// than B (the regularised stick slope, 4·B); the implicit bending term linearised with B alone
/// left 3·B explicit, and a 10-cell wool tropical strip chattered node by node at 7 cm/s
/// (period two steps) for as long as it ran. Linearised with the stick slope, every node is
/// slower than 1 mm/s within 2 s, and the loaded strip droops less than the elastic one (the
/// loading curve lies above Bη).
#[test]
fn a_hysteretic_strip_comes_to_rest() {
    let f = fabric("wool_tropical");
    let length = 2.0003 * (f.bending.warp.rigidity() / f.weight_per_area()).cbrt();
    let segments = 10;
    let (cloth, mut state, h, nv) = strip("wool_tropical", length, segments);
    let params = StepParams {
        dt: 0.25 * h,
        damping: 5.0,
        shape_tolerance: 1e-8,
        implicit_stick_slope: true,
        ..StepParams::default()
    };
    let mut solver = Solver::new();
    while state.time < 2.0 {
        solver.step(&cloth, &mut state, &params).expect("step");
    }
    let fastest = state
        .velocities
        .iter()
        .map(|v| v.norm())
        .fold(0.0, f64::max);
    let droop = -(state.positions[2 * nv - 1].z + state.positions[2 * nv - 2].z) / 2.0;
    let (centre, _) = simulate("wool_tropical", length, segments, false, 1.0);
    let elastic_droop = centre[centre.len() - 1].1;
    eprintln!(
        "hysteretic wool strip: fastest node {fastest:.2e} m/s at 2 s, tip droop {:.2} mm (elastic {:.2} mm)",
        droop * 1e3,
        elastic_droop * 1e3
    );
    assert!(fastest < 1e-3, "still moving at {fastest} m/s");
    assert!(
        droop < elastic_droop,
        "droop {droop} against {elastic_droop}"
    );
}
