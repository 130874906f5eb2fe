//! End to end on the eight-panel dress (thesis §5.6): sewn around the mannequin, settled,
//! walked, and dressed through the body by one-sided contact. Each run is checked frame by frame
//! against the body by an independent measure (parry's signed distance to each posed part mesh,
//! not the contact's union distance).

use std::path::PathBuf;

use crate::garment_common::{all_finite, deepest_inside_any_frame};
use atelier::pipeline::{GarmentRun, run_garment};
use atelier::report::Report;
use atelier::run::{RunOptions, run};
use atelier::scenario::{Scenario, ScenarioKind};
use atelier::{ClothSolver, Scene, Simulation};
use atelier_solver::show_through::{SHOW_THROUGH_REACH, show_through};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn scenarios() -> PathBuf {
    root().join("fixtures/scenarios")
}

/// A fixture scenario's garment spec with its schedule shortened.
fn spec(name: &str, settle: f64, motion_time: f64) -> atelier::GarmentSpec {
    let s = Scenario::load(&scenarios().join(format!("{name}.ron"))).expect("scenario");
    let ScenarioKind::Garment(mut spec) = s.kind else {
        panic!("{name} is a garment scenario")
    };
    spec.settings.settle = settle;
    spec.settings.motion_time = motion_time;
    spec
}

/// The dress sewn with gravity off and settled for 0.4 s: every one of its 310 pairs sewn, no
/// node inside the body in any frame, nothing non-finite, and the report complete and sane.
#[test]
fn the_dress_is_sewn_on_the_mannequin_without_entering_it() {
    let spec = spec("dress_sewn", 0.4, 0.0);
    let run = run_garment(&spec, &scenarios(), &mut |_| {}).expect("runs");
    assert_eq!(run.failure, None, "{:?}", run.warnings);
    assert_eq!(run.pairs, (310, 310), "{:?}", run.warnings);
    let sewn_at = run.sewn_at.expect("sewn");
    assert!(sewn_at < 1.0, "sewn at {sewn_at} s");
    assert!(all_finite(&run));
    let deepest = deepest_inside_any_frame(&run);
    assert!(
        deepest <= 0.0,
        "a node went {:.2} mm inside the body",
        deepest * 1e3
    );
    assert!(run.max_penetration <= 0.0, "checked after every step");
    assert_eq!(run.steps_with_penetration, 0);
    // Dressed: the bodice rests on the shoulders, the hem hangs 60 cm below the waist.
    let last = &run.frames.last().expect("frames").cloth;
    let top = last.iter().map(|p| p[1]).fold(f64::NEG_INFINITY, f64::max);
    let hem = last.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min);
    assert!((1.28..1.42).contains(&top), "top of the dress at {top} m");
    assert!((0.30..0.45).contains(&hem), "hem at {hem} m");
}

/// The dress of the test above with the body-vertex planes (opt-in, docs/collision.md §4c):
/// the faces between the nodes stay outside the body too, measured by a ray test of the final
/// shape (`show_through`). Node contact alone left 13 body vertices showing on `dress_sewn`, up
/// to 4.3 mm (the shoulder points and the bust); the lift's first form left 3 vertices here,
/// up to 0.87 mm, the kept form none (docs/validation.md, "The body through the cloth's
/// faces"). The bound, chosen after the first form's measurement and disclosed there, is a
/// third of the 3 mm skin the lift aims at — a quarter of a pixel in the report's pictures
/// (3.6 mm a pixel) — so the node contact alone fails it.
///
/// Ignored: a missed goal. One of the 63 steps does not converge (issue 21 item 1 asks 99 %).
#[test]
#[ignore = "missed (session 27): with the body-vertex planes 1 of 63 steps is unconverged (a cell row at 0.10 while sewing, 0.22 s; item 1 asks 99 %); no body vertex shows; docs/validation.md"]
fn the_body_vertex_planes_keep_the_dress_faces_outside_the_body() {
    let mut spec = spec("dress_sewn", 0.4, 0.0);
    spec.settings.vertex_planes = true;
    let run = run_garment(&spec, &scenarios(), &mut |_| {}).expect("runs");
    assert_eq!(run.failure, None, "{:?}", run.warnings);
    assert_eq!(run.pairs, (310, 310), "{:?}", run.warnings);
    assert!(deepest_inside_any_frame(&run) <= 0.0);
    let c = &run.convergence;
    let f = run.frames.last().expect("frames");
    let showing = show_through(
        &f.body,
        &run.body_triangles,
        &f.cloth,
        &run.cloth_triangles,
        SHOW_THROUGH_REACH,
    );
    eprintln!(
        "body-vertex planes: {} body vertices showing, up to {:.2} mm; {:?} of {} steps unconverged",
        showing.vertices.len(),
        showing.deepest * 1e3,
        c.unconverged_steps,
        c.steps
    );
    assert!(
        showing.deepest < 1e-3,
        "{} body vertices show through the cloth, up to {:.2} mm: {:?}",
        showing.vertices.len(),
        showing.deepest * 1e3,
        showing
            .vertices
            .iter()
            .map(|&v| f.body[v as usize])
            .collect::<Vec<_>>()
    );
    // Issue 21, item 1: at least 99 % of the steps converged. Missed: 1 of 63 did not (a cell
    // row at 0.10 while sewing, 0.22 s).
    let unconverged = c.unconverged_steps.expect("reported") as f64 / c.steps as f64;
    assert!(unconverged <= 0.01, "{c:?}");
}

/// The same dress through `atelier run`: the report's fields, and every output written.
#[test]
fn the_dress_report_is_complete_and_sane() {
    let mut scenario = Scenario::load(&scenarios().join("dress_sewn.ron")).expect("scenario");
    if let ScenarioKind::Garment(spec) = &mut scenario.kind {
        spec.settings.settle = 0.2;
    }
    let out = std::env::temp_dir().join(format!("atelier-dress-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let report = run(
        &scenario,
        None,
        &scenarios(),
        &out,
        &RunOptions::default(),
        &mut |_| {},
    )
    .expect("runs");
    assert!(report.passed(), "{}", report.summary_line());
    assert_eq!((report.nodes, report.body_triangles), (2558, 2832));
    assert!(report.triangles > 4000);
    let steps = (report.simulated_s / report.dt_s).round() as usize;
    assert_eq!(report.steps, steps);
    let m = |k: &str| report.metrics[k].unwrap_or_else(|| panic!("{k} measured"));
    assert!(m("unsewn_pairs") < 0.5);
    assert!(m("max_penetration_m") <= 0.0);
    assert!(m("sewn_at_s") > 0.0 && m("sewn_at_s") < report.simulated_s);
    assert!(m("max_strain_error") < 1.0 && m("final_strain_error") < 0.5);
    assert!(m("kinetic_energy_j") >= 0.0 && m("kinetic_energy_j") < 0.1);
    let st = report.stage_s;
    assert!(st.shape > 0.0 && st.collision > 0.0 && st.transfer > 0.0);
    assert!(st.total <= report.wall_s + 1e-6);
    for name in [
        "report.json",
        "final.obj",
        "final.ply",
        "run.glb",
        "final.png",
    ] {
        let len = std::fs::metadata(out.join(name))
            .unwrap_or_else(|e| panic!("{name}: {e}"))
            .len();
        assert!(len > 1000, "{name} has {len} bytes");
    }
    let back = Report::from_json(&std::fs::read_to_string(out.join("report.json")).expect("read"))
        .expect("parses");
    assert_eq!(back.metrics, report.metrics);
    std::fs::remove_dir_all(&out).ok();
}

/// The dress worn for a second of the walk: no node inside the moving body in any frame, the
/// cloth moves with it (kinetic energy during the walk), nothing non-finite.
#[test]
fn the_dress_walks_without_entering_the_body() {
    let spec = spec("dress_walk", 0.2, 1.0);
    let run = run_garment(&spec, &scenarios(), &mut |_| {}).expect("runs");
    assert_eq!(run.failure, None, "{:?}", run.warnings);
    assert_eq!(run.pairs.0, run.pairs.1);
    assert!(all_finite(&run));
    let deepest = deepest_inside_any_frame(&run);
    assert!(
        deepest <= 0.0,
        "a node went {:.2} mm inside the body",
        deepest * 1e3
    );
    assert!(run.max_penetration <= 0.0);
    assert!(
        run.max_motion_energy > 1e-3,
        "the dress moves with the body"
    );
    // The body moved: its last frame differs from its first.
    let (first, last) = (
        &run.frames[0].body,
        &run.frames.last().expect("frames").body,
    );
    assert!(
        first
            .iter()
            .zip(last)
            .any(|(a, b)| (a[2] - b[2]).abs() > 0.05)
    );
}

/// One-sided dressing: the sleeveless dress sewn in front of the body and pushed through it
/// ends on the body — nothing inside after the push, the back panels behind the body.
///
/// Ignored since the converged step landed (session 8): a regression, not a pass. The
/// inextensible dress is caught at the abdomen — from 1.5 s on the same ~130 nodes stay inside
/// (abdomen, 79.5 mm deep) until the 2 s push limit, the cloth around them at 3.9–4.3 % strain
/// under the push. The unconverged step let the cloth stretch past the body. Session 9 (extra
/// collision passes, every step converged): 198 nodes inside at 2 s (chest 160, abdomen 38).
/// Measured and open in docs/validation.md ("Every scenario on the converged step").
#[test]
#[ignore = "regression on the converged step: the dress stays caught in the body (session 9: 198 nodes inside after the 2 s push, chest and abdomen); docs/validation.md"]
fn the_dress_is_dressed_through_the_body_by_one_sided_contact() {
    let spec = spec("dress_one_sided", 0.2, 0.5);
    let run = run_garment(&spec, &scenarios(), &mut |_| {}).expect("runs");
    assert_eq!(run.failure, None, "{:?}", run.warnings);
    assert!(run.warnings.is_empty(), "{:?}", run.warnings);
    assert_eq!(run.pairs.0, run.pairs.1);
    assert!(all_finite(&run));
    // Once pushed through, no node is inside the body (the push's own steps are not counted).
    assert!(run.max_penetration <= 0.0);
    let last = run.frames.last().expect("frames");
    assert!(last.phase != atelier::Phase::Sewing);
    // The back panels ended behind the body: some node is behind the mannequin's back
    // (z < −0.12 m at the shoulder blades), some in front of its chest (z > 0.12 m).
    assert!(last.cloth.iter().any(|p| p[2] < -0.10 && p[1] > 1.0));
    assert!(last.cloth.iter().any(|p| p[2] > 0.10 && p[1] > 1.0));
    let deepest = {
        let after: Vec<_> = run
            .frames
            .iter()
            .filter(|f| f.phase != atelier::Phase::Pushing && f.phase != atelier::Phase::Sewing)
            .cloned()
            .collect();
        deepest_inside_any_frame(&GarmentRun {
            frames: after,
            ..run.clone()
        })
    };
    assert!(
        deepest <= 0.0,
        "{:.2} mm inside after the push",
        deepest * 1e3
    );
}

/// `Simulation::set_shape_tolerance`: a value outside `settings.step.shape.tolerance`'s range
/// (0, 0.1] is refused naming the field, and nothing changes; a PARTY scene takes the new value
/// (true), a baseline has no tolerance (false).
#[test]
fn a_shape_tolerance_out_of_range_is_refused_and_changes_nothing() {
    let spec = spec("skirt_sewn", 0.1, 0.0);
    let mut sim = Simulation::new(Scene::load(&spec, &scenarios()).expect("scene")).expect("sim");
    let before = sim.scene().settings.step.shape.tolerance;
    for bad in [0.0, -1e-4, 0.5, f64::NAN, f64::INFINITY] {
        let e = sim.set_shape_tolerance(bad).expect_err("refused");
        assert_eq!(e.field, "settings.step.shape.tolerance", "{bad}: {e}");
        assert_eq!(sim.scene().settings.step.shape.tolerance, before);
    }
    assert_eq!(sim.set_shape_tolerance(before / 10.0), Ok(true));
    assert_eq!(sim.scene().settings.step.shape.tolerance, before / 10.0);
    let mut xpbd = spec.clone();
    xpbd.settings.solver = ClothSolver::Xpbd(Default::default());
    let mut sim = Simulation::new(Scene::load(&xpbd, &scenarios()).expect("scene")).expect("sim");
    assert_eq!(sim.set_shape_tolerance(1e-5), Ok(false));
}

/// Issue 21, item 1 on the sewn dress: the same sewn state settled 3 s at the default shape
/// tolerance and at a ten times tighter one ends within 2 mm RMS. Two runs from the start
/// cannot tell the tolerance from the path (their pairs are sewn at different steps, and
/// friction then holds each where it came to rest: 5.4 mm apart, `docs/validation.md`, "Item 1
/// on the dress at rest"); here both runs take the same steps until every pair is sewn
/// (asserted bit for bit) and only then does one of them tighten its tolerance. Every step of
/// both meets its tolerance.
#[test]
#[ignore = "long: two dresses settled 3 s each, one at a tenth of the tolerance (about 4 min on 2 cores)"]
fn the_sewn_dress_settled_at_a_tenth_of_the_tolerance_ends_within_2_mm() {
    let spec = spec("dress_sewn", 3.0, 0.0);
    let make = || Simulation::new(Scene::load(&spec, &scenarios()).expect("scene")).expect("sim");
    let (mut loose, mut tight) = (make(), make());
    let sew = |s: &mut Simulation| {
        while s.sewn_at().is_none() {
            s.step()
                .expect("steps")
                .expect("sewn before the schedule ends");
        }
    };
    std::thread::scope(|scope| {
        scope.spawn(|| sew(&mut loose));
        sew(&mut tight);
    });
    assert_eq!(loose.time(), tight.time());
    assert!(
        loose.state().positions == tight.state().positions,
        "the two runs took different steps before the switch"
    );
    let tolerance = loose.scene().settings.step.shape.tolerance;
    assert_eq!(tight.set_shape_tolerance(tolerance / 10.0), Ok(true));
    let settle = |s: &mut Simulation| {
        let (mut steps, mut missed) = (0usize, 0usize);
        while let Some(o) = s.step().expect("steps") {
            steps += 1;
            missed += usize::from(!o.report.converged);
        }
        (steps, missed)
    };
    let ((loose_steps, loose_missed), (tight_steps, tight_missed)) = std::thread::scope(|scope| {
        let h = scope.spawn(|| settle(&mut loose));
        let t = settle(&mut tight);
        (h.join().expect("settled"), t)
    });
    let (a, b) = (&loose.state().positions, &tight.state().positions);
    let n = a.len() as f64;
    let rms = (a
        .iter()
        .zip(b)
        .map(|(p, q)| (p - q).norm_squared())
        .sum::<f64>()
        / n)
        .sqrt();
    let (largest, at) = a
        .iter()
        .zip(b)
        .map(|(p, q)| (p - q).norm())
        .enumerate()
        .fold((0.0f64, 0), |m, (i, d)| if d > m.0 { (d, i) } else { m });
    let speed = |s: &Simulation| {
        let v = &s.state().velocities;
        (v.iter().map(|v| v.norm_squared()).sum::<f64>() / v.len() as f64).sqrt()
    };
    println!(
        "sewn at {:.2} s; tolerance {tolerance:e}: {loose_steps} steps, {loose_missed} above it, RMS speed at the end {:.2} mm/s; {:e}: {tight_steps} steps, {tight_missed} above it, {:.2} mm/s; apart at {:.2} s: RMS {:.3} mm, largest {:.2} mm (node {at})",
        loose.sewn_at().expect("sewn"),
        speed(&loose) * 1e3,
        tolerance / 10.0,
        speed(&tight) * 1e3,
        loose.time(),
        rms * 1e3,
        largest * 1e3,
    );
    assert_eq!((loose_missed, tight_missed), (0, 0));
    assert!(rms <= 2e-3, "{:.3} mm RMS apart (goal ≤ 2 mm)", rms * 1e3);
}
