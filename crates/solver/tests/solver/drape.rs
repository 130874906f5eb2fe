//! Drape test (issue 3; `fabric-data.md` §6, thesis §3.9.3): the four Matsudaira fabrics fall
//! from flat onto a circular support and are measured once at rest; drape coefficient (DC) and
//! node count beside the published values. Run with
//! `cargo test -p atelier-solver --release --test solver drape -- --nocapture` to see the
//! tables (recorded in `docs/validation.md`).
//!
//! Choices, each measured (see `docs/validation.md`, "Drape"):
//! - anisotropy form `Compliance`: the thesis form cannot be built for three of the four fixtures
//!   on any annulus (their tensile branches cross between 45.5° and 55°, and 125°–134.5°);
//! - time steps: the largest at which the nodes next to the held rim do not chatter (rim-ring
//!   speed stays below the outer ring's): 1 ms on the JIS 72 × 8 grid, 0.5 ms on 96 × 11,
//!   2.5 ms on the thesis's 60 × 5 grid; the thesis's own Δt 0.01 s is run as well and
//!   reported, not asserted;
//! - a seeded 0.1 mm vertical perturbation of the free nodes (a specimen is never perfectly
//!   flat): without it the grid and the grain keep the drape exactly 2-fold symmetric, which
//!   allows only even node counts;
//! - the fold threshold (5 % of the overhang, σ 5° smoothing) and the rest criterion (RMS speed
//!   below 5 mm/s for 0.2 s, cap 5 s) were fixed before the first run and not tuned.

use std::fmt::Write as _;

use atelier_fabric::AnisotropyForm;
use atelier_solver::scenes::{DrapeRun, DrapeScene, RestCriterion, run_drape};
use atelier_solver::{Solver, StepParams};

use crate::common;

/// One fixture with its published drape.
struct Published {
    /// Fixture file name.
    fixture: &'static str,
    /// Short label.
    label: &'static str,
    /// Matsudaira et al. 2015, DC % (JIS geometry, most likely).
    dc: f64,
    /// Matsudaira et al. 2015, nodes.
    nodes: usize,
    /// The thesis §3.9.4 (Ø 63.5 cm, its own cotton, wool and polyester, real cloth).
    thesis_nodes: usize,
}

/// Ordered from stiff to limp as published: cotton broad, wool tropical, polyester tropical,
/// polyester faille.
const FABRICS: [Published; 4] = [
    Published {
        fixture: "cotton_broad",
        label: "cotton broad",
        dc: 82.9,
        nodes: 2,
        thesis_nodes: 8,
    },
    Published {
        fixture: "wool_tropical",
        label: "wool tropical",
        dc: 49.8,
        nodes: 5,
        thesis_nodes: 8,
    },
    Published {
        fixture: "polyester_tropical",
        label: "polyester tropical",
        dc: 50.7,
        nodes: 5,
        thesis_nodes: 9,
    },
    Published {
        fixture: "polyester_faille",
        label: "polyester faille",
        dc: 28.3,
        nodes: 7,
        thesis_nodes: 9,
    },
];

/// Band within which wool tropical and polyester tropical count as "≈" in DC, points: the
/// spread `fabric-data.md` §3 accepts for repeated drape tests (± 5–8 points), upper end.
const SIMILAR_DC_BAND: f64 = 8.0;

/// Band within which their node counts count as equal: drape is multistable, ± 1–2 nodes.
const SIMILAR_NODES_BAND: usize = 2;

/// Perturbation amplitude of the start, m.
const PERTURBATION: f64 = 1e-4;

fn scene(base: DrapeScene) -> DrapeScene {
    let mut s = DrapeScene {
        perturbation: PERTURBATION,
        ..base
    };
    s.cloth_options.form = AnisotropyForm::Compliance;
    s
}

fn params(dt: f64) -> StepParams {
    StepParams {
        dt,
        ..StepParams::default()
    }
}

fn run_all(scene: &DrapeScene, params: &StepParams, stop: &RestCriterion) -> Vec<DrapeRun> {
    FABRICS
        .iter()
        .map(|f| {
            let fabric = common::fabric(f.fixture);
            let (cloth, mut state) = scene.build(&fabric).expect("drape scene");
            let mut solver = Solver::new();
            let run = run_drape(scene, &cloth, &mut state, &mut solver, params, stop)
                .unwrap_or_else(|e| panic!("{}: {e}", f.fixture));
            assert!(run.measure.drape_coefficient.is_finite());
            assert!((-1.0..=101.0).contains(&run.measure.drape_coefficient));
            run
        })
        .collect()
}

/// The table of one geometry, with the published values and errors (markdown).
fn table(title: &str, scene: &DrapeScene, params: &StepParams, runs: &[DrapeRun]) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "\n### {title}: Ø {:.1} cm on Ø {:.1} cm, {} × {} cells, Δt {} ms",
        scene.specimen_diameter * 100.0,
        scene.support_diameter * 100.0,
        scene.n_around,
        scene.n_rings - 1,
        params.dt * 1e3
    );
    let _ = writeln!(
        out,
        "| fabric | DC % | Matsudaira DC % | error (points) | nodes | Matsudaira | thesis (Ø 63.5) | fold prominences mm | settled | t s | steps | wall s | ms/step | max axial strain | max diag. strain |"
    );
    let _ = writeln!(
        out,
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    );
    for (f, r) in FABRICS.iter().zip(runs) {
        let prominences: Vec<String> = r
            .measure
            .folds
            .iter()
            .map(|p| format!("{:.0}", p.prominence * 1e3))
            .collect();
        let _ = writeln!(
            out,
            "| {} | {:.1} | {:.1} | {:+.1} | {} | {} | {} | {} | {} | {:.2} | {} | {:.1} | {:.2} | {:.2e} | {:.2e} |",
            f.label,
            r.measure.drape_coefficient,
            f.dc,
            r.measure.drape_coefficient - f.dc,
            r.measure.nodes,
            f.nodes,
            f.thesis_nodes,
            prominences.join(" "),
            if r.settled { "yes" } else { "no (cap)" },
            r.time,
            r.steps,
            r.wall.as_secs_f64(),
            r.wall.as_secs_f64() * 1e3 / r.steps.max(1) as f64,
            r.max_axial_strain,
            r.max_diagonal_strain,
        );
    }
    let _ = writeln!(out, "DC over time (every 0.5 s):");
    for (f, r) in FABRICS.iter().zip(runs) {
        let history: Vec<String> = r
            .trace
            .iter()
            .filter(|s| ((s.time * 2.0).round() - s.time * 2.0).abs() < 1e-6 || (s.time - r.time).abs() < 1e-9)
            .map(|s| format!("{:.1}s {:.1}%/{}n", s.time, s.drape_coefficient, s.nodes))
            .collect();
        let _ = writeln!(out, "  {}: {}", f.label, history.join(", "));
    }
    out
}

/// cotton broad > polyester tropical ≈ wool tropical > polyester faille in DC, and the reverse
/// in node count with ties allowed (the counts are small integers and drape is multistable).
fn assert_published_ordering(runs: &[DrapeRun], what: &str) {
    let dc: Vec<f64> = runs.iter().map(|r| r.measure.drape_coefficient).collect();
    let n: Vec<usize> = runs.iter().map(|r| r.measure.nodes).collect();
    let (cotton, wool, poly, faille) = (0, 1, 2, 3);
    assert!(
        dc[cotton] > dc[wool].max(dc[poly]),
        "{what}: cotton broad's DC {:.1} must exceed both tropicals' {:.1}, {:.1}",
        dc[cotton],
        dc[wool],
        dc[poly]
    );
    assert!(
        dc[wool].min(dc[poly]) > dc[faille],
        "{what}: the tropicals' DC {:.1}, {:.1} must exceed faille's {:.1}",
        dc[wool],
        dc[poly],
        dc[faille]
    );
    assert!(
        (dc[wool] - dc[poly]).abs() <= SIMILAR_DC_BAND,
        "{what}: wool and polyester tropical differ by {:.1} DC points (band {SIMILAR_DC_BAND})",
        (dc[wool] - dc[poly]).abs()
    );
    assert!(
        n[cotton] <= n[wool].min(n[poly]) && n[wool].max(n[poly]) <= n[faille],
        "{what}: node counts {n:?} must not fall from cotton broad to the tropicals to faille"
    );
    assert!(
        n[wool].abs_diff(n[poly]) <= SIMILAR_NODES_BAND,
        "{what}: tropicals' node counts {} and {} differ by more than {SIMILAR_NODES_BAND}",
        n[wool],
        n[poly]
    );
    assert!(
        n[cotton] < n[faille],
        "{what}: cotton broad must have fewer nodes than faille ({n:?})"
    );
}

#[test]
fn drape_jis_72x8_orders_the_matsudaira_fabrics() {
    // 72 around × 8 rings: 9.1 mm radially, 5.5–11.1 mm around (cells within 1:1.6 of square
    // over the overhang), ≥ 6 nodes per fold up to 12 folds; Δt 1 ms is the largest step at
    // which the rim ring does not chatter (2 ms does).
    let scene = scene(DrapeScene::jis(72, 8));
    let params = params(1e-3);
    let stop = RestCriterion {
        max_time: 5.0,
        ..RestCriterion::default()
    };
    let runs = run_all(&scene, &params, &stop);
    eprintln!("{}", table("JIS L 1096", &scene, &params, &runs));
    assert_published_ordering(&runs, "JIS 72 × 8");
}

#[test]
fn drape_jis_96x11_finer_grid() {
    // 0.75 of the spacing of the 72 × 8 grid (6.4 mm radially, 4.2–8.3 mm around); the stable
    // step scales with the square of the smallest spacing: 0.5 ms.
    let scene = scene(DrapeScene::jis(96, 11));
    let params = params(5e-4);
    let stop = RestCriterion {
        max_time: 5.0,
        ..RestCriterion::default()
    };
    let runs = run_all(&scene, &params, &stop);
    eprintln!("{}", table("JIS L 1096, finer grid", &scene, &params, &runs));
    assert_published_ordering(&runs, "JIS 96 × 11");
}

#[test]
fn drape_thesis_63_5cm_60x5() {
    // The thesis's specimen and grid; Δt 2.5 ms (the rim ring chatters at 10 ms).
    let scene = scene(DrapeScene::thesis());
    let params = params(2.5e-3);
    let stop = RestCriterion {
        max_time: 6.0,
        ..RestCriterion::default()
    };
    let runs = run_all(&scene, &params, &stop);
    eprintln!(
        "{}",
        table("Thesis §3.9.3 geometry", &scene, &params, &runs)
    );
}

#[test]
fn drape_thesis_protocol_dt_10ms_2s() {
    // The thesis's own protocol: Δt 0.01 s for 2 s, measured at 2 s whatever the motion.
    let scene = scene(DrapeScene::thesis());
    let params = params(1e-2);
    let runs = run_all(&scene, &params, &RestCriterion::fixed(2.0));
    eprintln!(
        "{}",
        table(
            "Thesis protocol (Δt 0.01 s, 2 s, not at rest)",
            &scene,
            &params,
            &runs
        )
    );
}

#[test]
fn probe_timing() {
    let na: usize = std::env::var("NA").ok().and_then(|s| s.parse().ok()).unwrap_or(72);
    let nr: usize = std::env::var("NR").ok().and_then(|s| s.parse().ok()).unwrap_or(8);
    let dt: f64 = std::env::var("DT").ok().and_then(|s| s.parse().ok()).unwrap_or(1e-3);
    let imax: usize = std::env::var("IMAX").ok().and_then(|s| s.parse().ok()).unwrap_or(200);
    let sc = scene(DrapeScene::jis(na, nr));
    let fabric = common::fabric("cotton_broad");
    let (cloth, mut state) = sc.build(&fabric).unwrap();
    let p = StepParams { dt, internal_max_iterations: imax, ..StepParams::default() };
    let mut solver = Solver::new();
    let mut tot = atelier_solver::StageTimings::default();
    let mut it = [0usize; 2];
    let mut sh = 0;
    let t0 = std::time::Instant::now();
    let n = 1000;
    for _ in 0..n {
        let r = solver.step(&cloth, &mut state, &p).unwrap();
        tot.bending += r.timings.bending; tot.internal += r.timings.internal; tot.velocity += r.timings.velocity;
        tot.shape += r.timings.shape; tot.update += r.timings.update;
        it[0] += r.internal_iterations[0]; it[1] += r.internal_iterations[1]; sh += r.shape_iterations;
    }
    let w = t0.elapsed();
    eprintln!("{na}x{nr} dt {dt}: {:.3} ms/step; bending {:.3} internal {:.3} shape {:.3} update {:.3} ms; internal it {:?} shape it {:.1}",
        w.as_secs_f64() * 1e3 / n as f64, tot.bending.as_secs_f64()*1e3/n as f64, tot.internal.as_secs_f64()*1e3/n as f64,
        tot.shape.as_secs_f64()*1e3/n as f64, tot.update.as_secs_f64()*1e3/n as f64, [it[0]/n, it[1]/n], sh as f64 / n as f64);
}

mod probe {
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
        if std::env::var("THESISFORM").is_err() { scene.cloth_options.form = AnisotropyForm::Compliance; }
        scene.perturbation = env_f("PERT", 0.0); scene.seed = env_u("SEED", 1) as u64;
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
    if std::env::var("THESISFORM").is_err() { scene.cloth_options.form = AnisotropyForm::Compliance; }
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

}
