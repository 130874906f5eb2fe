//! Probe (not a test): the try-on's garment run for one of the synthetic examples, with the
//! example's true pose and sizes instead of the fit: a line per step (time, iterations,
//! factorisations, convergence, wall time), to see where the try-on's time goes:
//! `cargo run --release -p atelier-tryon --example tryon_probe -- [arms_raised|standing|mid_stride] [GARMENT.ron] [seconds]`
//! (`PROBE_9AR=1`: the 9AR mannequin's sizes instead of the example person's).
use atelier::Simulation;
use atelier::scenario::{Scenario, ScenarioKind};
use atelier_body::Mannequin;
use atelier_body::build::{Sizes, jis_9ar_description};
use atelier_tryon::{HOLD_S, examples::examples, posed_scene};
use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let name = args.get(1).map_or("arms_raised", String::as_str);
    let garment = args
        .get(2)
        .map_or("fixtures/scenarios/dress_sewn.ron", String::as_str);
    let until: f64 = args.get(3).map_or(f64::INFINITY, |s| s.parse().unwrap());
    let e = examples()
        .into_iter()
        .find(|e| e.name == name)
        .expect("example");
    let file = Path::new(garment);
    let sc = Scenario::load(file).expect("scenario");
    let ScenarioKind::Garment(spec) = &sc.kind else {
        panic!("garment")
    };
    let base = file.parent().unwrap();
    let sizes = if std::env::var("PROBE_9AR").is_ok() {
        Sizes::JIS_9AR
    } else {
        e.sizes
    };
    let mannequin = Mannequin::from_description(&jis_9ar_description(), &sizes).expect("body");
    let scene = posed_scene(spec, base, mannequin, &e.angles).expect("scene");
    println!(
        "motion to the pose + hold {HOLD_S} s, {:.2} s in all",
        scene.settings.motion_time
    );
    let mut sim = Simulation::new(scene).expect("sim");
    let wall = std::time::Instant::now();
    let (mut steps, mut bad, mut its, mut facts) = (0usize, 0usize, 0usize, 0usize);
    while sim.time() < until - 1e-9 {
        let t0 = wall.elapsed().as_secs_f64();
        match sim.step() {
            Ok(Some(o)) => {
                steps += 1;
                its += o.report.shape_iterations;
                facts += o.report.factorizations;
                bad += usize::from(!o.report.converged);
                println!(
                    "t={:.2} inside {} sub {} passes {} it {} fact {} conv {} viol {:.1e} worst {:?} pass {:.1e} {:.2}s (+{:.2})",
                    sim.time(),
                    o.inside,
                    o.substeps,
                    o.report.collision_passes,
                    o.report.shape_iterations,
                    o.report.factorizations,
                    o.report.converged,
                    o.report.violation,
                    o.report.worst,
                    o.report.shape_pass_violation,
                    wall.elapsed().as_secs_f64(),
                    wall.elapsed().as_secs_f64() - t0
                );
            }
            Ok(None) => break,
            Err(e) => {
                println!("error {e}");
                break;
            }
        }
    }
    println!(
        "{steps} steps, {bad} unconverged, {its} iterations, {facts} factorisations, {:.1} s wall",
        wall.elapsed().as_secs_f64()
    );
}
