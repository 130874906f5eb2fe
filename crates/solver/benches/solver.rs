//! Benchmarks of the PARTY step (issue 3, "Speed") and of the two baselines.
//!
//! Scene: a square cotton sheet (`fixtures/fabrics/cotton_broad.ron`) of `n × n` nodes at a
//! fixed 2 cm spacing (the thesis grids garments at 2–2.5 cm) from [`StructuredGrid::sheet`], so
//! the sizes are 0.32, 1.02, 1.98 and 3.98 m across; horizontal, pinned along its far edge (it
//! swings down like a flap), with a smooth seeded vertical perturbation of at most 1 mm on the
//! free nodes (so the fall is not perfectly symmetric; smooth, so that it puts no grid-scale
//! curvature into the sheet), advanced by [`WARM_UP_STEPS`] default steps (Δt 0.01 s) so that
//! the cloth is moving. Every bench checks the step from that state before timing it (the step
//! succeeds, the strain error is finite and below [`MAX_STRAIN_ERROR`], the cloth moves).
//!
//! Why a fixed spacing and not a fixed 1 m sheet: at 200² nodes on 1 m (5 mm spacing) the
//! default step is no answer worth timing. Measured while writing this bench: pinned along an
//! edge, with the default caps of 30 iterations, its strain error reaches 27 % and its top speed
//! 3 m/s in the third step (at 1 and 2 cm spacing the same steps stay below 3.4 % and 1.1 %);
//! pinned at two corners, with the earlier caps of 200 and 60, 40 % and 1.8 m/s by the fifth.
//!
//! - `party/<nodes>`: one full [`Solver::step`] from the warmed-up state (each iteration starts
//!   from a clone of the same state, so every iteration does the same work), for 289, 2 704,
//!   10 000 and 40 000 nodes; throughput in nodes, so criterion also prints nodes per second.
//! - After each size, [`stage_medians`] steps on from the warmed-up state and takes the median
//!   of every [`StageTimings`] field, of the iteration counts and of the ns per edge per
//!   constraint iteration; the table goes to stderr and to
//!   `$CARGO_TARGET_DIR/atelier-bench/solver_stages.md` (default `target/`).
//! - `baselines/{party,mass_spring,xpbd}_2704`: the 2 704-node scene with each solver (the
//!   baselines with their bending hinges on, as PARTY computes bending); the mass-spring step is
//!   explicit, so its table row also gives the time per 0.01 s of simulated time.
//!
//! - `scaling` (issue 10): time per step with 1 and 2 threads and resident memory per node from
//!   289 to 100 489 nodes; a table, not a criterion group (see [`scaling`]).
//!
//! `cargo test --benches` runs each bench once (criterion's test mode) with one step per stage
//! median, so CI checks the answers in about 15 s (mostly the 40 000-node warm-up) without
//! timing anything.

use std::fmt::Write as _;
use std::hint::black_box;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use atelier_fabric::{AnisotropyForm, Fabric};
use atelier_grid::{ClothTopology, StructuredGrid};
use atelier_solver::baselines::{MassSpring, MassSpringParams, Xpbd, XpbdParams};
use atelier_solver::{
    Cloth, ClothState, PinMotion, Solver, StageTimings, StepInput, StepParams, StepReport,
};
use criterion::{BatchSize, Criterion, Throughput, criterion_group, criterion_main};
use nalgebra::Vector3;

/// Nodes per side of the benchmarked sheets: 289, 2 704, 10 000 and 40 000 nodes (the last
/// only when measuring).
const SIDES: [usize; 4] = [17, 52, 100, 200];
/// Node spacing, m.
const SPACING: f64 = 0.02;
/// Default steps taken before timing, so that the cloth is moving.
const WARM_UP_STEPS: usize = 4;
/// Amplitude of the seeded vertical perturbation of the free nodes, m.
const PERTURBATION: f64 = 1e-3;
/// Seed of the perturbation's wave numbers and phases.
const SEED: u64 = 3;
/// Number of plane waves in the perturbation.
const WAVES: usize = 4;
/// Largest acceptable `max_strain_error` of the checked step. The default caps do not converge
/// the shape constraints (the error grows step by step while the cloth accelerates), so this is
/// a sanity bound, not a tolerance; the stage table reports the error actually reached.
const MAX_STRAIN_ERROR: f64 = 0.1;

/// Whether criterion is measuring (`cargo bench`), not just running each bench once
/// (`cargo test --benches`, or `cargo bench -- --test`).
fn measuring() -> bool {
    let args: Vec<String> = std::env::args().collect();
    args.iter().any(|a| a == "--bench") && !args.iter().any(|a| a == "--test" || a == "--list")
}

fn cotton() -> Fabric {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/fabrics/cotton_broad.ron");
    Fabric::load(&path).expect("fixture")
}

/// SplitMix64 in [0, 1) (Steele et al. 2014), for the seeded perturbation.
fn uniform(n: usize, mut seed: u64) -> Vec<f64> {
    (0..n)
        .map(|_| {
            seed = seed.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = seed;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^= z >> 31;
            (z >> 11) as f64 / (1u64 << 53) as f64
        })
        .collect()
}

/// The benchmark scene before any step: the cloth (its far edge pinned) and its perturbed flat
/// state.
fn sheet_scene(fabric: &Fabric, side: usize) -> (Cloth, ClothState) {
    let size = (side - 1) as f64 * SPACING;
    let grid = StructuredGrid::sheet(side, side, size, size);
    let topology = ClothTopology::from_structured(&grid).expect("grid");
    let mut cloth = Cloth::new(topology, fabric, AnisotropyForm::Thesis).expect("cloth");
    for node in (side - 1) * side..side * side {
        let [x, y] = grid.positions[node];
        cloth
            .pin(node as u32, Vector3::new(x, y, 0.0), PinMotion::Fixed)
            .expect("pin");
    }
    // z = A/WAVES · Σ sin(2π(k_x x + k_y y) + φ) with seeded integer wave numbers of 1–3 per
    // sheet side and phases: a smooth shape, the same on every sheet up to scale.
    let u = uniform(3 * WAVES, SEED);
    let waves: Vec<[f64; 3]> = u
        .chunks(3)
        .map(|w| {
            let k = |x: f64| (1.0 + (3.0 * x).floor()) / size;
            [k(w[0]), k(w[1]), std::f64::consts::TAU * w[2]]
        })
        .collect();
    let mut state = ClothState::flat(&cloth, 0.0);
    for (i, p) in state.positions.iter_mut().enumerate() {
        if !cloth.is_pinned(i) {
            let sum: f64 = waves
                .iter()
                .map(|[kx, ky, phase]| {
                    (std::f64::consts::TAU * (kx * p.x + ky * p.y) + phase).sin()
                })
                .sum();
            p.z += PERTURBATION * sum / WAVES as f64;
        }
    }
    (cloth, state)
}

/// A PARTY sheet after the warm-up, with the solver that took it there.
struct Fixture {
    side: usize,
    cloth: Cloth,
    /// State after [`WARM_UP_STEPS`] steps.
    state: ClothState,
    solver: Solver,
    params: StepParams,
    /// Δt 0.01 s under gravity.
    input: StepInput,
}

impl Fixture {
    fn new(fabric: &Fabric, side: usize) -> Self {
        let (cloth, mut state) = sheet_scene(fabric, side);
        let (params, input) = (StepParams::default(), StepInput::default());
        let mut solver = Solver::new();
        for _ in 0..WARM_UP_STEPS {
            solver
                .step(&cloth, &mut state, &params, input)
                .expect("warm-up step");
        }
        let fixture = Self {
            side,
            cloth,
            state,
            solver,
            params,
            input,
        };
        fixture.check();
        fixture
    }

    fn nodes(&self) -> usize {
        self.cloth.topology().node_count()
    }

    fn edges(&self) -> usize {
        self.cloth.topology().edges().len()
    }

    /// The answer checked before timing: the next step succeeds, its strain error and
    /// residuals are finite and small, and the cloth is moving.
    fn check(&self) {
        let mut solver = Solver::new();
        let mut state = self.state.clone();
        let r = solver
            .step(&self.cloth, &mut state, &self.params, self.input)
            .unwrap_or_else(|e| panic!("{}² sheet: {e}", self.side));
        assert!(
            r.max_strain_error.is_finite() && r.max_strain_error < MAX_STRAIN_ERROR,
            "{}² sheet: strain error {}",
            self.side,
            r.max_strain_error
        );
        assert!(r.violation.is_finite() && r.internal_residual.is_finite());
        assert!(
            r.max_speed > 0.05,
            "{}² sheet: not moving ({} m/s)",
            self.side,
            r.max_speed
        );
        assert!((state.time - (WARM_UP_STEPS + 1) as f64 * self.input.dt).abs() < 1e-9);
    }
}

/// Medians of the per-stage wall times of `steps` consecutive steps, and derived rates.
#[derive(Clone, Copy, Debug, Default)]
struct StageMedians {
    nodes: usize,
    edges: usize,
    steps: usize,
    timings: StageTimings,
    total: Duration,
    internal_iterations: f64,
    shape_iterations: f64,
    /// Median over the steps of shape time / (edges × shape iterations), ns.
    ns_per_edge_shape_iteration: f64,
    /// Median over the steps of internal time / (edges × internal iterations of both phases), ns.
    ns_per_edge_internal_iteration: f64,
    max_strain_error: f64,
}

fn median_f64(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => v[n / 2],
        n => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}

fn median_duration(reports: &[StepReport], field: impl Fn(&StageTimings) -> Duration) -> Duration {
    Duration::from_secs_f64(median_f64(
        reports
            .iter()
            .map(|r| field(&r.timings).as_secs_f64())
            .collect(),
    ))
}

/// The stages of [`Solver::step`] are private, but every step reports its wall time per stage
/// ([`StepReport::timings`]). This helper steps a clone of the fixture's warmed-up state with a
/// fresh solver (one untimed step first, to size the scratch and estimate the internal step
/// size), then records `steps` consecutive steps and takes the median of each timing field, of
/// the iteration counts and of the per-step costs per edge and iteration: shape time / (edges ×
/// shape iterations), internal time / (edges × internal iterations, both phases). Medians of
/// the fields are taken separately, so they need not add up to the median total.
fn stage_medians(fixture: &Fixture, steps: usize) -> StageMedians {
    let mut solver = Solver::new();
    let mut state = fixture.state.clone();
    let (cloth, params, input) = (&fixture.cloth, &fixture.params, fixture.input);
    solver.step(cloth, &mut state, params, input).expect("step");
    let reports: Vec<StepReport> = (0..steps)
        .map(|_| solver.step(cloth, &mut state, params, input).expect("step"))
        .collect();
    let edges = fixture.edges();
    let per_edge_iteration = |time: Duration, iterations: usize| {
        if iterations == 0 {
            f64::NAN
        } else {
            time.as_secs_f64() * 1e9 / (edges * iterations) as f64
        }
    };
    StageMedians {
        nodes: fixture.nodes(),
        edges,
        steps,
        timings: StageTimings {
            bending: median_duration(&reports, |t| t.bending),
            internal: median_duration(&reports, |t| t.internal),
            velocity: median_duration(&reports, |t| t.velocity),
            shape: median_duration(&reports, |t| t.shape),
            collision: median_duration(&reports, |t| t.collision),
            transfer: median_duration(&reports, |t| t.transfer),
            update: median_duration(&reports, |t| t.update),
            pressure: median_duration(&reports, |t| t.pressure),
        },
        total: median_duration(&reports, |t| t.total()),
        internal_iterations: median_f64(
            reports
                .iter()
                .map(|r| r.internal_iterations as f64)
                .collect(),
        ),
        shape_iterations: median_f64(reports.iter().map(|r| r.shape_iterations as f64).collect()),
        ns_per_edge_shape_iteration: median_f64(
            reports
                .iter()
                .map(|r| per_edge_iteration(r.timings.shape, r.shape_iterations))
                .collect(),
        ),
        ns_per_edge_internal_iteration: median_f64(
            reports
                .iter()
                .map(|r| per_edge_iteration(r.timings.internal, r.internal_iterations))
                .collect(),
        ),
        max_strain_error: reports
            .iter()
            .map(|r| r.max_strain_error)
            .fold(0.0, f64::max),
    }
}

fn ms(d: Duration) -> String {
    format!("{:.3}", d.as_secs_f64() * 1e3)
}

const STAGE_HEADER: &str = "| nodes | edges | steps | total ms | steps/s | bending ms | internal ms | velocity ms | shape ms | collision ms | update ms | internal it (axial+diag) | shape it | ns/(edge·shape it) | ns/(edge·internal it) | max strain err |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";

impl StageMedians {
    fn row(&self) -> String {
        let t = &self.timings;
        format!(
            "| {} | {} | {} | {} | {:.1} | {} | {} | {} | {} | {} | {} | {:.0} | {:.0} | {:.2} | {:.2} | {:.1e} |\n",
            self.nodes,
            self.edges,
            self.steps,
            ms(self.total),
            1.0 / self.total.as_secs_f64(),
            ms(t.bending),
            ms(t.internal),
            ms(t.velocity),
            ms(t.shape),
            ms(t.collision),
            ms(t.update),
            self.internal_iterations,
            self.shape_iterations,
            self.ns_per_edge_shape_iteration,
            self.ns_per_edge_internal_iteration,
            self.max_strain_error,
        )
    }
}

/// Median wall time per step of `step` over `steps` calls (after one untimed call).
fn median_step_time(steps: usize, mut step: impl FnMut()) -> Duration {
    step();
    let times = (0..steps)
        .map(|_| {
            let t0 = Instant::now();
            step();
            t0.elapsed().as_secs_f64()
        })
        .collect();
    Duration::from_secs_f64(median_f64(times))
}

/// Where the tables go: `$CARGO_TARGET_DIR/atelier-bench/`, default the workspace's `target/`.
fn report_path(name: &str) -> PathBuf {
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../target"));
    target.join("atelier-bench").join(name)
}

fn write_report(name: &str, text: &str) {
    let path = report_path(name);
    let written = path
        .parent()
        .map_or(Ok(()), std::fs::create_dir_all)
        .and_then(|()| std::fs::write(&path, text));
    match written {
        Ok(()) => eprintln!("wrote {}", path.display()),
        Err(e) => eprintln!("could not write {}: {e}", path.display()),
    }
}

fn party(c: &mut Criterion) {
    if scaling_child().is_some() {
        return;
    }
    let fabric = cotton();
    let measuring = measuring();
    let mut rows = Vec::new();
    let mut g = c.benchmark_group("party");
    // Criterion's test mode leaves out the 40 000-node sheet (4.9 s a step, six steps there:
    // about 30 s of session 20's `cargo test`); 10 000 nodes already take the large-sheet path.
    let sides = if measuring { &SIDES[..] } else { &SIDES[..3] };
    for &side in sides {
        let nodes = side * side;
        let large = nodes >= 10_000;
        g.throughput(Throughput::Elements(nodes as u64));
        g.sample_size(if large { 10 } else { 20 });
        g.warm_up_time(Duration::from_secs(if large { 2 } else { 1 }));
        g.measurement_time(Duration::from_secs(if large { 15 } else { 5 }));
        // Built on first use, so a filtered run does not pay for the other sizes.
        let mut fixture: Option<Fixture> = None;
        g.bench_function(nodes.to_string(), |b| {
            let fx = fixture.get_or_insert_with(|| Fixture::new(&fabric, side));
            let (cloth, params, input) = (&fx.cloth, &fx.params, fx.input);
            let (start, solver) = (&fx.state, &mut fx.solver);
            b.iter_batched(
                || start.clone(),
                |mut state| solver.step(cloth, &mut state, params, input).expect("step"),
                BatchSize::LargeInput,
            )
        });
        if let Some(fx) = &fixture {
            let steps = if !measuring {
                1
            } else if large {
                10
            } else {
                30
            };
            let m = stage_medians(fx, steps);
            eprintln!("party/{nodes} stage medians:\n{STAGE_HEADER}{}", m.row());
            rows.push(m.row());
        }
    }
    g.finish();
    if !rows.is_empty() {
        let mut text = String::from(
            "# PARTY step: per-stage medians (benches/solver.rs, `stage_medians`)\n\n",
        );
        let _ = writeln!(
            text,
            "Scene: cotton sheet at {SPACING} m spacing pinned along one edge, after {WARM_UP_STEPS} \
             steps of Δt 0.01 s; default StepParams.\n"
        );
        text.push_str(STAGE_HEADER);
        rows.iter().for_each(|r| text.push_str(r));
        write_report("solver_stages.md", &text);
    }
}

/// The baselines on the 2 704-node scene, warmed up for the same simulated time as PARTY.
fn baselines(c: &mut Criterion) {
    if scaling_child().is_some() {
        return;
    }
    const SIDE: usize = 52;
    let fabric = cotton();
    let measuring = measuring();
    let warm_up_time = WARM_UP_STEPS as f64 * StepInput::default().dt;
    let (cloth, start) = sheet_scene(&fabric, SIDE);
    let nodes = cloth.topology().node_count();

    // PARTY, for the ratio on the same scene.
    let party = Fixture::new(&fabric, SIDE);

    // Mass-spring Verlet at 0.9 × its estimated stability limit (a safe lower bound of the
    // true limit), rounded down to a whole number of steps per warm-up.
    let ms_params = MassSpringParams {
        bending: true,
        ..MassSpringParams::default()
    };
    let limit = MassSpring::largest_stable_dt_estimate(&cloth, &ms_params);
    let ms_steps = (warm_up_time / (0.9 * limit)).ceil() as usize;
    let ms_input = StepInput::default().with_dt(warm_up_time / ms_steps as f64);
    let mut ms_state = start.clone();
    let mut ms_solver = MassSpring::new();
    for _ in 0..ms_steps {
        ms_solver
            .step(&cloth, &mut ms_state, &ms_params, ms_input)
            .expect("mass-spring warm-up");
    }
    {
        let (mut s, mut st) = (ms_solver.clone(), ms_state.clone());
        let r = s
            .step(&cloth, &mut st, &ms_params, ms_input)
            .expect("mass-spring step");
        assert!(r.max_strain.is_finite() && r.max_strain < 0.2, "{r:?}");
        assert!(r.max_speed > 0.05, "mass-spring not moving: {r:?}");
    }

    // XPBD, defaults (Δt 0.01 s, 10 substeps × 4 sweeps).
    let xp_params = XpbdParams {
        bending: true,
        ..XpbdParams::default()
    };
    let mut xp_state = start.clone();
    let mut xp_solver = Xpbd::new();
    for _ in 0..WARM_UP_STEPS {
        xp_solver
            .step(&cloth, &mut xp_state, &xp_params, StepInput::default())
            .expect("xpbd warm-up");
    }
    {
        let (mut s, mut st) = (xp_solver.clone(), xp_state.clone());
        let r = s
            .step(&cloth, &mut st, &xp_params, StepInput::default())
            .expect("xpbd step");
        assert!(r.max_strain.is_finite() && r.max_strain < 0.2, "{r:?}");
        assert!(r.max_speed > 0.05, "xpbd not moving: {r:?}");
    }

    let mut g = c.benchmark_group("baselines");
    g.throughput(Throughput::Elements(nodes as u64));
    g.sample_size(20);
    g.measurement_time(Duration::from_secs(5));
    // Whether any of the three matched the command line's filter (then the table is made).
    let mut ran = false;
    {
        let mut solver = Solver::new();
        let params = &party.params;
        g.bench_function(format!("party_{nodes}"), |b| {
            ran = true;
            b.iter_batched(
                || party.state.clone(),
                |mut state| {
                    solver
                        .step(&party.cloth, &mut state, params, party.input)
                        .expect("step")
                },
                BatchSize::LargeInput,
            )
        });
    }
    g.bench_function(format!("mass_spring_{nodes}"), |b| {
        ran = true;
        b.iter_batched(
            || (ms_solver.clone(), ms_state.clone()),
            |(mut s, mut state)| {
                black_box(
                    s.step(&cloth, &mut state, &ms_params, ms_input)
                        .expect("step"),
                );
                (s, state)
            },
            BatchSize::LargeInput,
        )
    });
    g.bench_function(format!("xpbd_{nodes}"), |b| {
        ran = true;
        b.iter_batched(
            || (xp_solver.clone(), xp_state.clone()),
            |(mut s, mut state)| {
                black_box(
                    s.step(&cloth, &mut state, &xp_params, StepInput::default())
                        .expect("step"),
                );
                (s, state)
            },
            BatchSize::LargeInput,
        )
    });
    g.finish();
    if !ran {
        return;
    }

    // Medians per step and per 0.01 s of simulated time, all three on the same scene.
    let steps = if measuring { 50 } else { 1 };
    let party_step = {
        let mut solver = Solver::new();
        let mut state = party.state.clone();
        median_step_time(steps, || {
            black_box(
                solver
                    .step(&party.cloth, &mut state, &party.params, party.input)
                    .expect("step"),
            );
        })
    };
    let ms_step = {
        let (mut s, mut state) = (ms_solver.clone(), ms_state.clone());
        median_step_time(steps * 20, || {
            black_box(
                s.step(&cloth, &mut state, &ms_params, ms_input)
                    .expect("step"),
            );
        })
    };
    let xp_step = {
        let (mut s, mut state) = (xp_solver.clone(), xp_state.clone());
        median_step_time(steps, || {
            black_box(
                s.step(&cloth, &mut state, &xp_params, StepInput::default())
                    .expect("step"),
            );
        })
    };
    let per_centisecond = |step: Duration, dt: f64| step.mul_f64(0.01 / dt);
    let mut text = format!(
        "# Baselines on the {nodes}-node sheet (benches/solver.rs)\n\n\
         Mass-spring Δt = {:.3e} s (estimated stability limit {:.3e} s); XPBD Δt 0.01 s, {} \
         substeps × {} sweeps; PARTY defaults. Medians of {steps} steps.\n\n\
         | solver | Δt s | ms per step | ms per 0.01 s simulated | vs PARTY |\n|---|---|---|---|---|\n",
        ms_input.dt, limit, xp_params.substeps, xp_params.iterations,
    );
    let party_cs = per_centisecond(party_step, party.input.dt);
    for (name, step, dt) in [
        ("PARTY", party_step, party.input.dt),
        ("mass-spring Verlet", ms_step, ms_input.dt),
        ("XPBD", xp_step, StepInput::default().dt),
    ] {
        let cs = per_centisecond(step, dt);
        let _ = writeln!(
            text,
            "| {name} | {dt:.3e} | {} | {} | {:.2} |",
            ms(step),
            ms(cs),
            cs.as_secs_f64() / party_cs.as_secs_f64()
        );
    }
    eprintln!("{text}");
    write_report("solver_baselines.md", &text);
}

/// Whether the table `name` is wanted: no criterion filter on the command line, or one that
/// `name` contains (`cargo bench … -- scaling`).
fn selected(name: &str) -> bool {
    let filters: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with('-'))
        .collect();
    filters.is_empty() || filters.iter().any(|f| name.contains(f.as_str()))
}

/// A field of `/proc/self/status` in bytes (`VmRSS`, `VmHWM`; 0 where there is none).
fn status_bytes(field: &str) -> usize {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            let line = s.lines().find(|l| l.starts_with(field))?;
            line.split_whitespace().nth(1)?.parse::<usize>().ok()
        })
        .map_or(0, |kb| kb * 1024)
}

/// Environment variables of a scaling child process: the sheet's side, and the file its table
/// row goes to.
const SCALING_SIDE_VAR: &str = "ATELIER_SCALING_SIDE";
const SCALING_ROW_VAR: &str = "ATELIER_SCALING_ROW";

/// The side this process measures when it is a scaling child.
fn scaling_child() -> Option<usize> {
    std::env::var(SCALING_SIDE_VAR).ok()?.parse().ok()
}

/// Sides of the scaling sheets: 289 to 100 489 nodes.
const SCALING_SIDES: [usize; 7] = [17, 32, 71, 100, 158, 224, 317];

/// Scaling (issue 10): wall time per step with 1 and 2 rayon threads and memory per node, from
/// 289 to 100 489 nodes (the sheet of [`Fixture`]). Each size runs in a child process of this
/// bench (`ATELIER_SCALING_SIDE`), so that sizes share no allocator state: it builds the scene,
/// warms it up, takes per thread count the median of at least three steps (until 2 s) from
/// clones of the same warmed-up state, and reports its peak resident memory (`VmHWM`) less its
/// resident memory before the scene was built — the cloth, state, solver, scratch and the
/// gridding's temporaries, at 4 kB resolution. Table: stderr and
/// `$CARGO_TARGET_DIR/atelier-bench/scaling.md`, with the slope of log time against log nodes
/// from 10 000 nodes up. `cargo test --benches` runs the smallest size only, in process.
fn scaling(_c: &mut Criterion) {
    if let Some(side) = scaling_child() {
        let row = scaling_row(side);
        let path = std::env::var(SCALING_ROW_VAR).expect("the row's file");
        std::fs::write(
            &path,
            format!("{} {} {} {} {}", row.0, row.1, row.2, row.3, row.4),
        )
        .expect("writing the row");
        return;
    }
    if !selected("scaling") {
        return;
    }
    let sides: &[usize] = if measuring() {
        &SCALING_SIDES
    } else {
        &SCALING_SIDES[..1]
    };
    let mut table = String::from(
        "| nodes | edges | 1 thread, ms/step | 2 threads, ms/step | speed-up | µs per node (2 threads) | peak resident bytes per node |\n|---|---|---|---|---|---|---|\n",
    );
    let mut points = Vec::new();
    for &side in sides {
        let (nodes, edges, one, two, memory) = if measuring() {
            let path = report_path(&format!("scaling_row_{side}.txt"));
            if let Some(dir) = path.parent() {
                std::fs::create_dir_all(dir).expect("report folder");
            }
            let status = std::process::Command::new(std::env::current_exe().expect("this bench"))
                .args(["--bench", "scaling"])
                .env(SCALING_SIDE_VAR, side.to_string())
                .env(SCALING_ROW_VAR, &path)
                .status()
                .expect("starting the scaling child");
            assert!(status.success(), "the scaling child for side {side} failed");
            let text = std::fs::read_to_string(&path).expect("the child's row");
            let _ = std::fs::remove_file(&path);
            let v: Vec<f64> = text
                .split_whitespace()
                .map(|x| x.parse().expect("a number"))
                .collect();
            (v[0] as usize, v[1] as usize, v[2], v[3], v[4])
        } else {
            // In process (criterion's test mode): the peak includes everything run before.
            let r = scaling_row(side);
            (r.0, r.1, r.2, r.3, f64::NAN)
        };
        points.push((nodes as f64, two));
        let _ = writeln!(
            table,
            "| {nodes} | {edges} | {:.2} | {:.2} | {:.2} | {:.2} | {} |",
            one * 1e3,
            two * 1e3,
            one / two,
            two * 1e6 / nodes as f64,
            if memory.is_finite() {
                format!("{memory:.0}")
            } else {
                "— (in process)".to_string()
            }
        );
    }
    let large: Vec<(f64, f64)> = points.iter().copied().filter(|p| p.0 >= 10_000.0).collect();
    if large.len() >= 2 {
        let n = large.len() as f64;
        let (mx, my) = large
            .iter()
            .fold((0.0, 0.0), |a, p| (a.0 + p.0.ln() / n, a.1 + p.1.ln() / n));
        let (num, den) = large.iter().fold((0.0, 0.0), |a, p| {
            (
                a.0 + (p.0.ln() - mx) * (p.1.ln() - my),
                a.1 + (p.0.ln() - mx).powi(2),
            )
        });
        let _ = writeln!(
            table,
            "\nSlope of log(time per step) against log(nodes), 10 000 nodes and up, 2 threads: {:.3}",
            num / den
        );
    }
    eprintln!("{table}");
    write_report("scaling.md", &table);
}

/// One size of [`scaling`]: nodes, edges, the median step with 1 and with 2 threads (s), and
/// the peak resident bytes per node added by the scene.
fn scaling_row(side: usize) -> (usize, usize, f64, f64, f64) {
    let fabric = cotton();
    let before = status_bytes("VmRSS:");
    let mut fx = Fixture::new(&fabric, side);
    let (nodes, edges) = (fx.nodes(), fx.edges());
    let per_thread: Vec<f64> = [1, 2]
        .into_iter()
        .map(|threads| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("thread pool");
            pool.install(|| {
                let mut times = Vec::new();
                let budget = Instant::now();
                while times.len() < 3
                    || (measuring() && budget.elapsed().as_secs_f64() < 2.0 && times.len() < 50)
                {
                    let mut state = fx.state.clone();
                    let t0 = Instant::now();
                    fx.solver
                        .step(&fx.cloth, &mut state, &fx.params, fx.input)
                        .expect("step");
                    times.push(t0.elapsed().as_secs_f64());
                    black_box(&state);
                }
                median_f64(times)
            })
        })
        .collect();
    let memory = status_bytes("VmHWM:").saturating_sub(before) as f64 / nodes as f64;
    (nodes, edges, per_thread[0], per_thread[1], memory)
}

/// Steps of the peers' scene: 2 s at Δt 0.01 s under `cargo bench`; 0.2 s in criterion's test
/// mode, which checks that the scene runs (the 200 steps took 75 s there in session 20).
fn peer_steps() -> usize {
    if measuring() { 200 } else { 20 }
}

/// The peers' scene (issue 10): a 1 m square sheet of `side × side` nodes pinned at its two
/// far corners, falling from horizontal for `peer_steps()` steps of Δt 0.01 s (2 s when
/// measuring) with the default step but
/// `shape_cap` shape iterations per pass (default 30) and long-range attachments on or off.
/// Returns the mean wall time per step and the largest axial stretch (l/l⁰ − 1) at the end and
/// over the run (checked every 0.1 s), or the step's error and when it came.
fn peer_scene(
    fabric: &Fabric,
    side: usize,
    shape_cap: usize,
    long_range: bool,
) -> Result<(f64, f64, f64), (String, f64)> {
    let grid = StructuredGrid::sheet(side, side, 1.0, 1.0);
    let topology = ClothTopology::from_structured(&grid).expect("grid");
    let mut cloth = Cloth::new(topology, fabric, AnisotropyForm::Thesis).expect("cloth");
    for node in [(side - 1) * side, side * side - 1] {
        let [x, y] = grid.positions[node];
        cloth
            .pin(node as u32, Vector3::new(x, y, 0.0), PinMotion::Fixed)
            .expect("pin");
    }
    let stretch = |state: &ClothState| {
        atelier_solver::metrics::axial_strains(&cloth, &state.positions).fold(f64::MIN, f64::max)
    };
    let mut state = ClothState::flat(&cloth, 0.0);
    let params = StepParams {
        shape: atelier_solver::ShapeParams {
            max_iterations: shape_cap,
            long_range_attachments: long_range,
            ..atelier_solver::ShapeParams::default()
        },
        ..StepParams::default()
    };
    let mut solver = Solver::new();
    let (mut wall, mut worst) = (0.0, 0.0f64);
    let steps = peer_steps();
    for k in 1..=steps {
        let t0 = Instant::now();
        solver
            .step(&cloth, &mut state, &params, StepInput::default())
            .map_err(|e| (format!("step {k}: {e}"), state.time))?;
        wall += t0.elapsed().as_secs_f64();
        if k % 10 == 0 {
            worst = worst.max(stretch(&state));
        }
    }
    Ok((wall / steps as f64, stretch(&state), worst))
}

/// The peers' scene at 50 × 50 and 100 × 100 nodes, with the plain shape iterations at 30
/// (default), 100 and 300 per pass and with long-range attachments at 5, 10 and 30 (2 threads);
/// table to stderr and `$CARGO_TARGET_DIR/atelier-bench/peers.md`, the rows also as
/// `peers_party.json` in the peers' schema (`benches/peers/README.md`) for the bench report. A
/// failed run is a row saying so. `cargo test --benches` runs the 50 × 50 sheet with the
/// attachments only, for 0.2 s (`peer_steps`).
fn peers(_c: &mut Criterion) {
    if !selected("peers") || scaling_child().is_some() {
        return;
    }
    let fabric = cotton();
    let cases: &[(usize, usize, bool)] = if measuring() {
        &[
            (50, 30, false),
            (50, 100, false),
            (50, 300, false),
            (50, 5, true),
            (50, 10, true),
            (50, 30, true),
            (100, 30, false),
            (100, 300, false),
            (100, 5, true),
            (100, 10, true),
            (100, 30, true),
        ]
    } else {
        &[(50, 10, true)]
    };
    let steps = peer_steps();
    let mut table = format!(
        "| sheet | nodes | setting | ms/step (mean of {steps}) | largest stretch at {} s | largest stretch over the run |\n|---|---|---|---|---|---|\n",
        steps as f64 * StepInput::default().dt
    );
    let mut rows = Vec::new();
    for &(side, cap, long_range) in cases {
        let setting = if long_range {
            format!("shape_max_iterations={cap}, long_range_attachments")
        } else if cap == StepParams::default().shape.max_iterations {
            "defaults".to_string()
        } else {
            format!("shape_max_iterations={cap}")
        };
        let nodes = side * side;
        let outcome = peer_scene(&fabric, side, cap, long_range);
        match &outcome {
            Ok((per_step, end, worst)) => {
                let _ = writeln!(
                    table,
                    "| {side} × {side} | {nodes} | {setting} | {:.2} | {:.2} % | {:.2} % |",
                    per_step * 1e3,
                    100.0 * end,
                    100.0 * worst
                );
            }
            Err((e, _)) => {
                let _ = writeln!(
                    table,
                    "| {side} × {side} | {nodes} | {setting} | failed: {e} | | |"
                );
            }
        }
        let (ms, end, worst, diverged, note) = match outcome {
            Ok((per_step, end, worst)) => {
                (Some(per_step * 1e3), Some(end), Some(worst), None, None)
            }
            Err((e, t)) => (None, None, None, Some(t), Some(e)),
        };
        rows.push(serde_json::json!({
            "scene": "sheet", "side": side, "nodes": nodes, "setting": setting,
            "ms_per_step": ms, "stretch_end": end, "stretch_max": worst,
            "diverged_at_s": diverged, "drape_coefficient": null, "note": note,
        }));
    }
    eprintln!("{table}");
    write_report("peers.md", &table);
    let threads = rayon::current_num_threads();
    let json = serde_json::json!({
        "peer": "atelier PARTY",
        "threads": threads,
        "rows": rows,
        "differences": [],
    });
    write_report(
        "peers_party.json",
        &serde_json::to_string_pretty(&json).expect("json"),
    );
}

criterion_group!(benches, party, baselines, scaling, peers);
criterion_main!(benches);
