//! Scene 3: the Peirce cantilever (ASTM D1388, JIS L 1096) against the exact heavy elastica
//! (`reference/elastica.md`): a strip overhanging by 2.0003·c, c = (B/w)^(1/3), droops so that the
//! chord from the platform edge to the tip makes 41.5° with the horizontal.

use atelier_fabric::AnisotropyForm;
use atelier_grid::{ClothTopology, StructuredGrid};
use atelier_solver::{Cloth, ClothState, PinMotion, Solver, StepParams};
use nalgebra::Vector3;

use crate::common::fabric;

/// The heavy inextensible elastica clamped at σ = 0, free at σ = 1:
/// θ'' = −λ(1 − σ) cos θ, θ(0) = 0, θ'(1) = 0, solved by shooting on θ'(0) with RK4 on `n` steps.
/// Returns the centreline (x, y)/L at the `n + 1` stations, y downwards.
fn elastica(lambda: f64, n: usize) -> Vec<(f64, f64)> {
    let h = 1.0 / n as f64;
    let shoot = |k: f64, keep: bool| -> (f64, Vec<(f64, f64)>) {
        let f = |s: f64, th: f64, w: f64| (w, -lambda * (1.0 - s) * th.cos());
        let (mut th, mut w) = (0.0, k);
        let mut pts = vec![(0.0, 0.0)];
        let (mut x, mut y) = (0.0, 0.0);
        for i in 0..n {
            let s = i as f64 * h;
            let (a1, b1) = f(s, th, w);
            let (a2, b2) = f(s + h / 2.0, th + h / 2.0 * a1, w + h / 2.0 * b1);
            let (a3, b3) = f(s + h / 2.0, th + h / 2.0 * a2, w + h / 2.0 * b2);
            let (a4, b4) = f(s + h, th + h * a3, w + h * b3);
            let th_new = th + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4);
            w += h / 6.0 * (b1 + 2.0 * b2 + 2.0 * b3 + b4);
            if keep {
                // Trapezoidal position update (the stations are fine enough for 1e-6).
                x += 0.5 * h * (th.cos() + th_new.cos());
                y += 0.5 * h * (th.sin() + th_new.sin());
                pts.push((x, y));
            }
            th = th_new;
        }
        (w, pts)
    };
    let (mut lo, mut hi) = (0.0, lambda / 2.0);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if shoot(mid, false).0 > 0.0 {
            hi = mid
        } else {
            lo = mid
        }
    }
    shoot(0.5 * (lo + hi), true).1
}

/// The elastica itself reproduces the reference numbers: λ = 8.0042 gives the 41.5° chord and
/// the tip at (0.7243, 0.6408)·L.
#[test]
fn the_reference_elastica_reproduces_the_published_numbers() {
    let pts = elastica(8.00420, 4000);
    let (x, y) = pts[pts.len() - 1];
    assert!(
        (y.atan2(x).to_degrees() - 41.5).abs() < 1e-3,
        "{}",
        y.atan2(x).to_degrees()
    );
    assert!(
        (x - 0.7243).abs() < 1e-4 && (y - 0.6408).abs() < 1e-4,
        "({x}, {y})"
    );
    let small = elastica(0.01, 2000);
    assert!((small[small.len() - 1].1 - 0.01 / 8.0).abs() < 1e-6);
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
    let f = fabric(name);
    let h = length / (segments as f64 + 0.5);
    let width = 0.01;
    let nv = segments + 2;
    let topo =
        ClothTopology::from_structured(&StructuredGrid::sheet(2, nv, width, (nv - 1) as f64 * h))
            .expect("grid");
    let mut cloth = Cloth::new(topo, &f, AnisotropyForm::Thesis).expect("cloth");
    let place = |[x, y]: [f64; 2]| Vector3::new(y - 0.5 * h, x, 0.0);
    for node in 0..4 {
        let p = place(cloth.topology().rest_positions()[node]);
        cloth.pin(node as u32, p, PinMotion::Fixed).expect("pin");
    }
    let mut state = ClothState::placed(&cloth, place);
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
