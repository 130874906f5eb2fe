//! Benchmarks of the virtual try-on (issue 11): the synthetic `arms_raised` photograph of
//! `atelier_tryon::examples` (420 × 460 px, the person 380 px tall).
//!
//! - `tryon/fit`: the whole pose fit from the standard pose (limb search, then three levels of
//!   Levenberg–Marquardt), as `atelier tryon` runs it.
//! - `tryon/silhouette`: one residual evaluation's render at the finest level — the mannequin
//!   built at a size, posed, its silhouette rendered at 4 × 4 samples per pixel.
//! - `tryon/composite`: the dressed, posed state drawn over the photograph (2 × 2 samples); the
//!   garment is the sewn skirt, as in the README's try-on (the sleeved dress takes minutes to
//!   dress and move there, `docs/performance.md`).
//!
//! `cargo test --benches` runs each once (criterion's test mode). In that mode the fit starts at
//! the photograph's true pose and the skirt is not settled and moved only 0.05 s towards it: the
//! test mode checks that the benches run, and the whole fit and the skirt's settling and move
//! cost CI about 100 s (session 28) repeating what the try-on tests run.

use std::hint::black_box;
use std::path::PathBuf;
use std::time::Duration;

use atelier::run::simulate_scene;
use atelier::scenario::{Scenario, ScenarioKind};
use atelier_body::Mannequin;
use atelier_body::build::jis_9ar_description;
use atelier_tryon::camera::coverage;
use atelier_tryon::composite::composite;
use atelier_tryon::examples::examples;
use atelier_tryon::pose::{FitOptions, PoseFile, fit_pose, posed_mannequin, synthetic_photo};
use atelier_tryon::posed_scene;
use criterion::{Criterion, criterion_group, criterion_main};

/// Whether criterion is measuring (`cargo bench`), not in its test mode (`cargo test --benches`,
/// or `cargo bench -- --test`).
fn measuring() -> bool {
    let args: Vec<String> = std::env::args().collect();
    args.iter().any(|a| a == "--bench") && !args.iter().any(|a| a == "--test" || a == "--list")
}

fn tryon(c: &mut Criterion) {
    let e = examples()
        .into_iter()
        .find(|e| e.name == "arms_raised")
        .expect("example");
    let d = jis_9ar_description();
    let (photo, mask) = synthetic_photo(&d, &e.sizes, &e.angles, &e.camera, e.size).expect("photo");
    let mut g = c.benchmark_group("tryon");
    g.sample_size(10);
    g.measurement_time(Duration::from_secs(60));
    let options = FitOptions {
        description: d.clone(),
        height_cm: e.sizes.height_cm,
        yaw_deg: e.camera.yaw_deg,
        start: if measuring() {
            PoseFile::default()
        } else {
            PoseFile::from_angles(&e.angles, None, None)
        },
    };
    g.bench_function("fit", |b| {
        b.iter(|| black_box(fit_pose(&mask, &options).expect("fit")))
    });
    g.finish();
    let mut g = c.benchmark_group("tryon");
    g.bench_function("silhouette", |b| {
        b.iter(|| {
            let (points, triangles) = posed_mannequin(&d, &e.sizes, &e.angles).expect("posed");
            black_box(coverage(&points, &triangles, &e.camera, e.size, 4))
        })
    });
    // The dressed state: the sewn skirt moved to the example's pose (the truth, not a fit).
    let scenarios = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/scenarios");
    let scenario = Scenario::load(&scenarios.join("skirt_sewn.ron")).expect("scenario");
    let ScenarioKind::Garment(spec) = &scenario.kind else {
        panic!("a garment scenario")
    };
    let mannequin = Mannequin::from_description(&d, &e.sizes).expect("mannequin");
    let mut scene = posed_scene(spec, &scenarios, mannequin, &e.angles).expect("scene");
    if !measuring() {
        scene.settings.settle = 0.0;
        scene.settings.motion_time = 0.05;
    }
    let sim = simulate_scene(scene, &mut |_| {}).expect("simulated");
    let cloth = sim.cloth.frames.last().expect("frame").clone();
    let solid = sim.solid.as_ref().expect("body");
    let body = solid.motion.frames.last().expect("frame").clone();
    g.bench_function("composite", |b| {
        b.iter(|| {
            black_box(composite(
                &photo,
                &e.camera,
                (&cloth, &sim.cloth_triangles),
                (&body, &solid.triangles),
                atelier::picture::CLOTH,
                atelier_tryon::DEFAULT_LIGHT,
            ))
        })
    });
    g.finish();
}

criterion_group! {
    name = benches;
    // No HTML plots: criterion's own plots find no font (see the garment bench).
    config = Criterion::default().without_plots();
    targets = tryon
}
criterion_main!(benches);
