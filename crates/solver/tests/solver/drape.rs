//! probe
use atelier_fabric::AnisotropyForm;
use atelier_solver::scenes::{DrapeScene, RestCriterion, Support, run_drape};
use atelier_solver::{Solver, StepParams};
use crate::common;

fn env_f(name: &str, d: f64) -> f64 { std::env::var(name).ok().and_then(|s| s.parse().ok()).unwrap_or(d) }
fn env_u(name: &str, d: usize) -> usize { std::env::var(name).ok().and_then(|s| s.parse().ok()).unwrap_or(d) }

#[test]
fn probe_run() {
    let names = std::env::var("FABRICS").unwrap_or("cotton_broad".into());
    for name in names.split(',') {
        let f = common::fabric(name);
        let mut scene = if std::env::var("GEOM").as_deref() == Ok("jis") { DrapeScene::jis(env_u("NA", 72), env_u("NR", 8)) } else { DrapeScene::thesis() };
        scene.n_around = env_u("NA", scene.n_around);
        scene.n_rings = env_u("NR", scene.n_rings);
        scene.form = AnisotropyForm::Compliance;
        scene.perturbation = env_f("PERT", 0.0);
        if std::env::var("CLAMP").is_ok() { scene.support = Support::Clamped; }
        let (cloth, mut state) = scene.build(&f).unwrap();
        let mut params = StepParams { dt: env_f("DT", 0.01), ..StepParams::default() };
        match std::env::var("SHAPE").as_deref() {
            Ok("gs") => params.shape_method = atelier_solver::ShapeMethod::GaussSeidel { omega: 1.0 },
            Ok("newton") => params.shape_method = atelier_solver::ShapeMethod::Newton { cg_iterations: 50, cg_tolerance: 1e-3 },
            Ok("jacobi") => params.shape_method = atelier_solver::ShapeMethod::Jacobi,
            _ => {}
        }
        if std::env::var("DIAG").is_ok() { params.diagonal_constraint = atelier_solver::ConstraintKind::StretchOnly; }
        if std::env::var("AXIAL").is_ok() { params.axial_constraint = atelier_solver::ConstraintKind::StretchOnly; }
        if std::env::var("NOHYST").is_ok() { params.hysteresis = false; }
        params.shape_max_iterations = env_u("SHAPEIT", params.shape_max_iterations);
        let stop = RestCriterion { max_time: env_f("TMAX", 6.0), sample_interval: env_f("SAMPLE", 0.25), ..RestCriterion::default() };
        let mut solver = Solver::new();
        let run = run_drape(&scene, &cloth, &mut state, &mut solver, &params, &stop);
        let run = match run { Ok(r) => r, Err(e) => { eprintln!("{name}: error {e}"); continue; } };
        eprintln!("{name}: n={} DC {:.1} nodes {} settled {} t {:.2} steps {} wall {:.2?} ({:.2} ms/step) rms {:.2e} axial {:.3e} diag {:.3e} strain_err {:.2e} shape_it {:.1} capped {}",
            cloth.topology().node_count(), run.measure.drape_coefficient, run.measure.nodes, run.settled, run.time, run.steps, run.wall,
            run.wall.as_secs_f64()*1e3/run.steps as f64, run.rms_speed, run.max_axial_strain, run.max_diagonal_strain, run.max_strain_error, run.mean_shape_iterations, run.capped_steps);
        eprintln!("   folds {:?}", run.measure.folds.iter().map(|p| (p.index, (p.prominence*1e3).round())).collect::<Vec<_>>());
        eprintln!("   edge r {:.4}..{:.4} lowest {:.4}", run.measure.min_edge_radius, run.measure.max_edge_radius, run.measure.lowest);
        for s in &run.trace { eprintln!("   t {:.2} rms {:.3e} DC {:.2} nodes {} axial {:.2e}", s.time, s.rms_speed, s.drape_coefficient, s.nodes, s.max_axial_strain); }
    }
}

#[test]
fn probe_diag() {
    let f = common::fabric(&std::env::var("FABRICS").unwrap_or("cotton_broad".into()));
    let mut scene = if std::env::var("GEOM").as_deref() == Ok("jis") { DrapeScene::jis(env_u("NA", 72), env_u("NR", 8)) } else { DrapeScene::thesis() };
    scene.n_around = env_u("NA", scene.n_around);
    scene.n_rings = env_u("NR", scene.n_rings);
    scene.form = AnisotropyForm::Compliance;
    if std::env::var("CLAMP").is_ok() { scene.support = Support::Clamped; }
    let (cloth, mut state) = scene.build(&f).unwrap();
    let mut params = StepParams { dt: env_f("DT", 0.01), ..StepParams::default() };
    if std::env::var("NOBEND").is_ok() { params.bending_off = true; }
    if std::env::var("EXPL").is_ok() { params.implicit_bending = false; }
    params.damping = env_f("DAMP", params.damping);
    params.shape_max_iterations = env_u("SHAPEIT", params.shape_max_iterations);
    let mut solver = Solver::new();
    let nsteps = (env_f("TMAX", 1.0) / params.dt).round() as usize;
    let na = scene.n_around;
    let rings = scene.grid_rings();
    for k in 0..nsteps {
        let r = solver.step(&cloth, &mut state, &params).unwrap();
        if k % (nsteps / 10).max(1) == 0 || k + 1 == nsteps {
            let mut ring_v = vec![0.0f64; rings];
            for j in 0..rings { for i in 0..na { ring_v[j] = ring_v[j].max(state.velocities[j*na+i].norm()); } }
            eprintln!("t {:.3} it {:?} res {:.2e} shape {} sres {:.2e} serr {:.2e} maxv {:.3} ke {:.2e} ringmaxv {:?}", state.time, r.internal_iterations, r.internal_residual, r.shape_iterations, r.shape_residual, r.max_strain_error, r.max_speed, r.kinetic_energy, ring_v.iter().map(|v| (v*1000.0).round()/1000.0).collect::<Vec<_>>());
        }
    }
    // velocity pattern on outer ring: print signs of consecutive nodes' vertical velocity
    let j = rings - 1;
    let vz: Vec<i32> = (0..na).map(|i| (state.velocities[j*na+i].z * 100.0).round() as i32).collect();
    eprintln!("outer vz cm/s {:?}", vz);
    let z: Vec<i32> = (0..na).map(|i| (state.positions[j*na+i].z * 1000.0).round() as i32).collect();
    eprintln!("outer z mm {:?}", z);
}
