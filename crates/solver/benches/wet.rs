//! Benches of the wet-cloth stages (`docs/performance.md`, "Wet cloth"), on the thesis's scene:
//! a 30 cm square of wet satin (`fixtures/fabrics/polyester_satin_wet.ron`), 50 × 50 nodes, over
//! 400 cm³ of air, pinched at its centre and being lifted at 2 cm/s (started 0.3 s before the
//! timing, then stepping on).
//!
//! - `wet/pressure_forces`: the pressure force alone (volume (Y3.10), normals, Boyle);
//! - `wet/pressure_projection`: one backward-Euler projection of the PARTY step;
//! - `wet/yamada_step`: one step of Yamada's mass-spring model with its wet forces (Δt 1/12 000 s);
//! - `wet/party_step`: one PARTY step with the pressure stage and the plane (Δt 5 ms).
//!
//! `cargo test --benches` runs each once (criterion's test mode) and checks the steps succeed.

use std::path::PathBuf;

use atelier_fabric::Fabric;
use atelier_solver::baselines::{MassSpring, MassSpringParams};
use atelier_solver::wet::scene::{WetScene, YamadaParams, yamada_springs};
use atelier_solver::wet::{PlaneHook, YamadaExtras};
use atelier_solver::{ClothState, Solver, StepInput, StepParams};
use criterion::{Criterion, criterion_group, criterion_main};

fn satin() -> Fabric {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/fabrics/polyester_satin_wet.ron");
    Fabric::load(&path).expect("the wet satin fixture")
}

fn scene() -> WetScene {
    WetScene::thesis_pinch(1, Some(4e-4))
}

fn wet(c: &mut Criterion) {
    let fabric = satin();
    let scene = scene();
    let (cloth, start) = scene.build(&fabric).expect("scene");
    let contact = scene.contact(&fabric);

    // Yamada: 0.3 s of warm-up, then stepping on.
    let yp = YamadaParams::default();
    let y_input = StepInput::new(yp.dt);
    let params = MassSpringParams {
        damping: yp.damping,
        ..MassSpringParams::default()
    };
    let mut yamada = MassSpring::with_stiffness(yamada_springs(&cloth, yp.springs));
    let mut extras = YamadaExtras::new(Some(contact), scene.pressure_stage(&cloth));
    let mut ys: ClothState = start.clone();
    for _ in 0..3600 {
        yamada
            .step_with_extras(&cloth, &mut ys, &params, y_input, &mut extras)
            .expect("yamada warm-up");
    }

    // PARTY: 0.3 s of warm-up at 5 ms.
    let (pp, p_input) = (StepParams::default(), StepInput::new(0.005));
    let mut party = Solver::new();
    party.pressure = scene.pressure_stage(&cloth);
    let mut hook = PlaneHook { contact };
    let mut ps = start.clone();
    for _ in 0..60 {
        party
            .step_with(&cloth, &mut ps, &pp, p_input, &mut hook)
            .expect("party warm-up");
    }

    let mut g = c.benchmark_group("wet");
    g.sample_size(20);
    {
        let stage = extras.pressure.as_mut().expect("pressure on");
        let mut forces = vec![nalgebra::Vector3::zeros(); ys.positions.len()];
        g.bench_function("pressure_forces", |b| {
            b.iter(|| stage.add_forces(&ys.positions, yp.dt, &mut forces));
        });
    }
    {
        let stage = party.pressure.as_mut().expect("pressure on");
        let mut v = ps.velocities.clone();
        g.bench_function("pressure_projection", |b| {
            b.iter(|| stage.project(&ps.positions, cloth.inverse_masses(), p_input.dt, &mut v));
        });
    }
    g.bench_function("yamada_step", |b| {
        b.iter(|| {
            yamada
                .step_with_extras(&cloth, &mut ys, &params, y_input, &mut extras)
                .expect("yamada step")
        });
    });
    g.bench_function("party_step", |b| {
        b.iter(|| {
            party
                .step_with(&cloth, &mut ps, &pp, p_input, &mut hook)
                .expect("party step")
        });
    });
    g.finish();
}

criterion_group!(benches, wet);
criterion_main!(benches);
