//! Benchmarks of the garment pipeline (issue 7, "Speed"): the eight-panel dress of
//! `fixtures/scenarios/dress_sewn.ron` (2 558 nodes, cotton broad) on the 9AR mannequin
//! (2 832 triangles, of which the continuous test keeps the exposed ones).
//!
//! - `garment/dress_sewn`: the whole scenario — load, grid, place, sew, settle 1 s — as
//!   [`run_garment`] runs it (the goal: ≤ 2 s on 2 cores).
//! - `garment/setup`: loading, gridding and placing (`Scene::load` + `Simulation::new`).
//! - `garment/step_standing`: one step of the sewn dress standing under gravity.
//! - `garment/step_walking` and `garment/step_walking_self_collision`: one step of the dress
//!   during the walk (the first 5 s of `walk.ron`, cycled), without and with self-collision.
//!
//! - `scan_contact/…`: the nearest-point query against the mannequin and a body scan
//!   ([`scan_contact`]).
//!
//! After the benches, [`stage_table`] steps each scene on and writes the median of every stage
//! per step to stderr and to `$CARGO_TARGET_DIR/atelier-bench/garment_stages.md` (default
//! `target/`), the table `docs/performance.md` quotes.
//!
//! `cargo test --benches` runs each bench once (criterion's test mode) and one step per stage
//! median, so CI checks that the benches still run without timing anything. In that mode the
//! scenes are shortened (no settling, 0.01 s into the standing and the walk), the dress is
//! replaced by its skirt ([`spec`]), the refined scan of `scan_contact` is left out, and the
//! stage table steps the benches' own simulations: on
//! the converged step the full schedule cost CI about 15 minutes, and the four dresses' sewing
//! alone about six on the slower machines of session 19.

use std::fmt::Write as _;
use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use atelier::pipeline::run_garment;
use atelier::scenario::{Scenario, ScenarioKind};
use atelier::simulation::Timings;
use atelier::{GarmentSpec, Phase, Scene, Simulation};
use atelier_body::io::{ExternalBody, load_mesh};
use atelier_body::scan::{ScanOptions, mannequin, prepare, subdivided};
use atelier_body::{Mannequin, V3};
use atelier_collide::parts::RigidParts;
use criterion::{Criterion, criterion_group, criterion_main};

fn scenarios() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/scenarios")
}

fn load(name: &str) -> GarmentSpec {
    let s = Scenario::load(&scenarios().join(format!("{name}.ron"))).expect("scenario");
    let ScenarioKind::Garment(spec) = s.kind else {
        panic!("{name} is a garment scenario")
    };
    spec
}

/// The scenario `name` as the benches run it: measuring, as it is; in the test mode, with the
/// dress replaced by its three-panel skirt (`skirt_sewn`'s pattern and placements), which sews
/// in a tenth of the time — the test mode checks that the benches run, and sewing four dresses
/// cost CI about six minutes on 2 cores.
fn spec(name: &str) -> GarmentSpec {
    let mut s = load(name);
    if !measuring() {
        let skirt = load("skirt_sewn");
        s.garment = skirt.garment;
        s.placements = skirt.placements;
    }
    s
}

/// Whether criterion is measuring (`cargo bench`), not in its test mode (`cargo test --benches`,
/// or `cargo bench -- --test`).
fn measuring() -> bool {
    let args: Vec<String> = std::env::args().collect();
    args.iter().any(|a| a == "--bench") && !args.iter().any(|a| a == "--test" || a == "--list")
}

/// A simulation of `spec` stepped until `phase` has begun (and `extra` s into it).
fn advanced(spec: &GarmentSpec, phase: Phase, extra: f64) -> Simulation {
    let scene = Scene::load(spec, &scenarios()).expect("scene");
    let mut sim = Simulation::new(scene).expect("simulation");
    let mut since = None;
    loop {
        let o = sim.step().expect("step").expect("the schedule goes on");
        if o.phase == phase {
            let start = *since.get_or_insert(sim.time());
            if sim.time() - start >= extra - 1e-9 {
                return sim;
            }
        }
    }
}

/// `measured` when criterion is measuring, else the test mode's shortened `smoke`.
fn lasting(measured: f64, smoke: f64) -> f64 {
    if measuring() { measured } else { smoke }
}

/// The dress standing, sewn and settled for 0.2 s, its settling long enough never to end.
fn standing() -> Simulation {
    let mut s = spec("dress_sewn");
    s.settings.settle = 1e6;
    advanced(&s, Phase::Settling, lasting(0.2, 0.01))
}

/// The dress walking, 0.1 s into the walk (the walk's first 0.3 s are still), its walk long
/// enough never to end (`walked` restarts it before the fixture's last keyframe).
fn walking(self_collision: bool) -> Simulation {
    let mut s = spec("dress_walk");
    s.settings.settle = lasting(0.2, 0.0);
    s.settings.motion_time = 1e6;
    s.settings.self_collision = self_collision;
    advanced(&s, Phase::Motion, lasting(0.4, 0.01))
}

/// Step a walking simulation `n` times (timed), restarting it (untimed) before the walk
/// fixture's end at 6 s of motion.
fn walked(sim: &mut Simulation, n: u64, self_collision: bool) -> Duration {
    let mut timed = Duration::ZERO;
    for _ in 0..n {
        if sim.time() > 0.2 + 0.2 + 5.0 {
            *sim = walking(self_collision);
        }
        let t = Instant::now();
        black_box(sim.step().expect("step"));
        timed += t.elapsed();
    }
    timed
}

fn garment(c: &mut Criterion) {
    let mut g = c.benchmark_group("garment");
    g.sample_size(10);
    g.measurement_time(Duration::from_secs(20));
    let mut sewn = spec("dress_sewn");
    sewn.settings.settle = lasting(sewn.settings.settle, 0.0);
    g.bench_function("dress_sewn", |b| {
        b.iter(|| {
            let run = run_garment(&sewn, &scenarios(), &mut |_| {}).expect("runs");
            assert_eq!(run.pairs.0, run.pairs.1);
            black_box(run.steps)
        })
    });
    g.bench_function("setup", |b| {
        b.iter(|| {
            let scene = Scene::load(&sewn, &scenarios()).expect("scene");
            black_box(Simulation::new(scene).expect("simulation"))
        })
    });
    g.finish();
    let mut g = c.benchmark_group("garment");
    g.sample_size(30);
    let mut sims = vec![standing()];
    g.bench_function("step_standing", |b| {
        b.iter(|| black_box(sims[0].step().expect("step")))
    });
    for self_collision in [false, true] {
        let mut sim = walking(self_collision);
        let name = if self_collision {
            "step_walking_self_collision"
        } else {
            "step_walking"
        };
        g.bench_function(name, |b| {
            b.iter_custom(|n| walked(&mut sim, n, self_collision))
        });
        sims.push(sim);
    }
    g.finish();
    // Measuring: the table from fresh scenes; in the test mode, from the benches' own.
    stage_table((!measuring()).then_some(sims));
}

/// Median of each stage per step over `steps` steps of each scene (standing, walking, walking
/// with self-collision): `given`, or built afresh.
fn stage_table(given: Option<Vec<Simulation>>) {
    let steps = if measuring() { 200 } else { 1 };
    let mut given = given.map(Vec::into_iter);
    let mut out = String::new();
    let _ = writeln!(
        out,
        "| scene | nodes | steps | body | bending | internal | velocity | transfer | shape | collision | update | diagnostics | total (ms per step, medians) |"
    );
    let _ = writeln!(out, "|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    let scenes: [(&str, Option<bool>); 3] = [
        ("dress standing", None),
        ("dress walking", Some(false)),
        ("dress walking, self-collision", Some(true)),
    ];
    let garment = if measuring() { "dress" } else { "skirt" };
    for (name, walk) in scenes {
        let name = name.replacen("dress", garment, 1);
        let mut sim = match given.as_mut().and_then(Iterator::next) {
            Some(sim) => sim,
            None => walk.map_or_else(standing, walking),
        };
        let nodes = sim.state().positions.len();
        let mut samples: Vec<Timings> = Vec::with_capacity(steps);
        for _ in 0..steps {
            let o = sim.step().expect("step").expect("goes on");
            samples.push(o.timings);
        }
        let median = |f: &dyn Fn(&Timings) -> Duration| {
            let mut v: Vec<f64> = samples.iter().map(|t| f(t).as_secs_f64() * 1e3).collect();
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        let cols: [&dyn Fn(&Timings) -> Duration; 10] = [
            &|t| t.body,
            &|t| t.solver.bending,
            &|t| t.solver.internal,
            &|t| t.solver.velocity,
            &|t| t.solver.transfer,
            &|t| t.solver.shape,
            &|t| t.solver.collision,
            &|t| t.solver.update,
            &|t| t.diagnostics,
            &|t| t.total(),
        ];
        let cells: Vec<String> = cols.iter().map(|f| format!("{:.2}", median(*f))).collect();
        let _ = writeln!(
            out,
            "| {name} | {nodes} | {steps} | {} |",
            cells.join(" | ")
        );
    }
    eprintln!("\n{out}");
    let dir = std::env::var_os("CARGO_TARGET_DIR")
        .map_or_else(
            || PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../target"),
            PathBuf::from,
        )
        .join("atelier-bench");
    if std::fs::create_dir_all(&dir).is_ok() {
        let _ = std::fs::write(dir.join("garment_stages.md"), out);
    }
}

/// The body's parts as rigid colliders, and query points 5 mm outside its trunk.
fn setup(m: &Mannequin) -> (RigidParts, Vec<V3>) {
    let meshes: Vec<(&[V3], &[[u32; 3]])> = m
        .parts
        .iter()
        .map(|p| (p.vertices.as_slice(), p.triangles.as_slice()))
        .collect();
    let parts = RigidParts::new(&meshes).expect("closed parts");
    // Four points on every triangle of the trunk band, 5 mm out along the face's normal,
    // kept where they are outside the body (not under another part).
    let mut points = Vec::new();
    for p in &m.parts {
        for t in &p.triangles {
            let [a, b, c] = t.map(|k| p.vertices[k as usize]);
            let Some(n) = (b - a).cross(&(c - a)).try_normalize(0.0) else {
                continue;
            };
            for w in [
                [1.0, 1.0, 1.0],
                [4.0, 1.0, 1.0],
                [1.0, 4.0, 1.0],
                [1.0, 1.0, 4.0],
            ] {
                let q = (a * w[0] + b * w[1] + c * w[2]) / (w[0] + w[1] + w[2]) + n * 0.005;
                if (0.5..1.15).contains(&q.y)
                    && parts
                        .nearest(&q, 0.01, false)
                        .is_some_and(|h| h.distance > 0.0)
                {
                    points.push(q);
                }
            }
        }
    }
    let stride = (points.len() / 2000).max(1);
    let points: Vec<V3> = points.into_iter().step_by(stride).take(2000).collect();
    (parts, points)
}

/// The cost of contact against a body scan (issue 24, "Docs and speed"): the nearest-point query
/// every cloth node makes each step (`RigidParts::nearest`, parry's projection on each part's
/// mesh), against the 9AR mannequin (2 832 triangles), the MakeHuman scan articulated by
/// `atelier_body::scan` (26 756 triangles and the caps of its cuts) and the same scan refined
/// 1-to-4 (107 024 triangles and caps). Each body is queried at 2 000 points 5 mm outside its
/// own trunk (points on its triangles between 0.5 and 1.15 m high, moved along the normals), with the 1 cm
/// search radius of contact; one iteration queries all 2 000.
fn scan_contact(c: &mut Criterion) {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/tryon/makehuman/mh_rest.obj");
    let mesh = load_mesh(&path).expect("mh_rest.obj");
    // The refined scan only when measuring: the test mode checks that the query runs, and
    // refining and articulating 107 024 triangles is most of this bench's setup.
    let fine = measuring().then(|| {
        let (vertices, triangles) = subdivided(&mesh.vertices, &mesh.triangles);
        ExternalBody {
            vertices,
            triangles,
            ..ExternalBody::default()
        }
    });
    let opts = ScanOptions::default();
    let articulated = |m| mannequin(&prepare(m, &opts, None).expect("scan")).expect("articulated");
    let mut bodies = vec![
        ("mannequin_2832", atelier_body::build::jis_9ar()),
        ("scan_26756", articulated(mesh)),
    ];
    if let Some(fine) = fine {
        bodies.push(("scan_107024", articulated(fine)));
    }
    let mut group = c.benchmark_group("scan_contact");
    group.sample_size(20);
    for (name, body) in &bodies {
        let (parts, points) = setup(body);
        assert!(
            points.len() >= 1500,
            "{name}: {} query points",
            points.len()
        );
        group.bench_function(*name, |b| {
            b.iter(|| {
                points
                    .iter()
                    .filter(|p| parts.nearest(black_box(p), 0.01, false).is_some())
                    .count()
            });
        });
    }
    group.finish();
}

criterion_group! {
    name = benches;
    // No HTML plots: with the workspace's plotters (ab_glyph, no system fonts) criterion's own
    // plots find no font; the tables above are the output.
    config = Criterion::default().without_plots();
    targets = garment, scan_contact
}
criterion_main!(benches);
