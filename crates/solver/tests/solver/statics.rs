//! Scenes with exact answers: free fall with linear drag (1), the catenary (2), and the thread
//! count independence of the step.

use atelier_fabric::AnisotropyForm;
use atelier_grid::{ClothTopology, StructuredGrid};
use atelier_solver::{Cloth, ClothState, PinMotion, Solver, StepInput, StepParams};
use nalgebra::Vector3;

use crate::common::fabric;

/// Scene 1: an unpinned horizontal sheet falls with linear drag; every node follows
/// v(t) = (μg/c)(1 − e^{−ct/μ}) with c/μ = damping/m_A. The step (18) is backward Euler in the
/// drag and forward in position, so the error must shrink at first order in Δt.
#[test]
fn free_fall_with_linear_drag_converges_at_first_order() {
    let f = fabric("cotton_broad");
    let topo =
        ClothTopology::from_structured(&StructuredGrid::sheet(6, 5, 0.5, 0.4)).expect("grid");
    let cloth = Cloth::new(topo, &f, AnisotropyForm::Thesis).expect("cloth");
    let damping = 0.5; // kg/(m²·s)
    let g = atelier_fabric::STANDARD_GRAVITY;
    let k = damping / f.mass_per_area; // c/μ, 1/s
    let t_end = 1.0;
    let exact_v = g / k * (1.0 - (-k * t_end).exp());
    let exact_z = -(g / k) * (t_end - (1.0 - (-k * t_end).exp()) / k);
    let mut errors = Vec::new();
    for dt in [0.01, 0.005, 0.0025] {
        let mut state = ClothState::flat(&cloth, 0.0);
        let params = StepParams {
            damping,
            ..StepParams::default()
        };
        let mut solver = Solver::new();
        for _ in 0..(t_end / dt).round() as usize {
            solver
                .step(&cloth, &mut state, &params, StepInput::new(dt))
                .expect("step");
        }
        // Rigid fall: every node has the same velocity and drop; no edge stretched.
        for (p, v) in state.positions.iter().zip(&state.velocities) {
            assert!(
                (v - state.velocities[0]).norm() < 1e-9 * exact_v,
                "{v:?} vs {:?}",
                state.velocities[0]
            );
            assert!((p - state.positions[0]).z.abs() < 1e-9);
        }
        let (v, z) = (-state.velocities[0].z, state.positions[0].z);
        errors.push((
            (v - exact_v).abs() / exact_v,
            (z - exact_z).abs() / exact_z.abs(),
        ));
    }
    eprintln!("free fall: relative errors (v, z) at Δt 0.01/0.005/0.0025: {errors:?}");
    for w in errors.windows(2) {
        let order_v = (w[0].0 / w[1].0).log2();
        let order_z = (w[0].1 / w[1].1).log2();
        assert!(
            (order_v - 1.0).abs() < 0.1,
            "velocity order {order_v} ({errors:?})"
        );
        assert!(
            (order_z - 1.0).abs() < 0.1,
            "position order {order_z} ({errors:?})"
        );
    }
    // At Δt = 0.0025 s both are within 0.2 % of the closed form.
    assert!(errors[2].0 < 2e-3 && errors[2].1 < 2e-3, "{errors:?}");
}

/// The inextensible catenary with span `d` and length `l`: parameter a from l = 2a sinh(d/2a).
fn catenary_parameter(d: f64, l: f64) -> f64 {
    let (mut lo, mut hi): (f64, f64) = (1e-4, 1e4);
    for _ in 0..200 {
        let a = (lo * hi).sqrt();
        if 2.0 * a * (d / (2.0 * a)).sinh() > l {
            lo = a
        } else {
            hi = a
        }
    }
    (lo * hi).sqrt()
}

/// Scene 2: a 1 m strip (2 nodes wide, 1 cm) hung from both ends 0.8 m apart, bending off; at
/// rest every node lies within 0.5 % of the span of the inextensible catenary
/// z = a (cosh(x/a) − cosh(d/2a)).
#[test]
fn hanging_strip_matches_the_catenary() {
    let f = fabric("cotton_broad");
    let (length, span, segments) = (1.0, 0.8, 50);
    let topo =
        ClothTopology::from_structured(&StructuredGrid::sheet(segments + 1, 2, length, 0.01))
            .expect("grid");
    let mut cloth = Cloth::new(topo, &f, AnisotropyForm::Thesis).expect("cloth");
    // Start on a circular arc of the strip's length through both supports (no initial stretch).
    let a = catenary_parameter(span, length);
    let (mut lo, mut hi) = (1e-6_f64, std::f64::consts::PI - 1e-9); // half-angle of the arc
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if span / (2.0 * mid.sin()) * 2.0 * mid > length {
            hi = mid
        } else {
            lo = mid
        }
    }
    let half = 0.5 * (lo + hi);
    let radius = span / (2.0 * half.sin());
    let place = |[x, y]: [f64; 2]| {
        let phi = -half + 2.0 * half * x / length;
        Vector3::new(radius * phi.sin(), y, -radius * (phi.cos() - half.cos()))
    };
    let n_u = segments + 1;
    for j in 0..2 {
        for i in [0, segments] {
            let node = j * n_u + i;
            let p = place(cloth.topology().rest_positions()[node]);
            cloth.pin(node as u32, p, PinMotion::Fixed).expect("pin");
        }
    }
    let mut state = ClothState::placed(&cloth, place);
    let input = StepInput::new(0.005);
    let params = StepParams {
        damping: 2.0,
        bending: atelier_solver::BendingParams {
            off: true,
            ..atelier_solver::BendingParams::default()
        },
        ..StepParams::default()
    };
    let mut solver = Solver::new();
    let mut report = None;
    for _ in 0..2000 {
        report = Some(
            solver
                .step(&cloth, &mut state, &params, input)
                .expect("step"),
        );
    }
    let report = report.expect("ran");
    assert!(
        report.max_speed < 1e-3,
        "not at rest: {} m/s",
        report.max_speed
    );
    let mut worst: f64 = 0.0;
    for p in &state.positions {
        let exact = a * ((p.x / a).cosh() - (span / (2.0 * a)).cosh());
        worst = worst.max((p.z - exact).abs());
    }
    eprintln!(
        "catenary: max deviation {:.3e} m = {:.3} % of the span",
        worst,
        100.0 * worst / span
    );
    assert!(
        worst < 0.005 * span,
        "max deviation {worst} m = {:.3} % of the span",
        100.0 * worst / span
    );
}

/// The step's results do not depend on the number of threads (deterministic chunked
/// reductions, gathers in fixed order): 1 and 2 threads give identical positions.
#[test]
fn results_do_not_depend_on_the_thread_count() {
    let f = fabric("polyester_faille");
    let n = 70; // 4 900 nodes: above the parallel threshold
    let topo =
        ClothTopology::from_structured(&StructuredGrid::sheet(n, n, 1.0, 1.0)).expect("grid");
    let mut cloth = Cloth::new(topo, &f, AnisotropyForm::Thesis).expect("cloth");
    let start = ClothState::flat(&cloth, 0.0);
    for node in [(n - 1) * n, n * n - 1] {
        cloth
            .pin(node as u32, start.positions[node], PinMotion::Fixed)
            .expect("pin");
    }
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        pool.install(|| {
            let mut state = ClothState::flat(&cloth, 0.0);
            let mut solver = Solver::new();
            let params = StepParams::default();
            for _ in 0..10 {
                solver
                    .step(&cloth, &mut state, &params, StepInput::default())
                    .expect("step");
            }
            state
        })
    };
    let (one, two) = (run(1), run(2));
    assert_eq!(one.positions, two.positions);
    assert_eq!(one.axial_force, two.axial_force);
}
