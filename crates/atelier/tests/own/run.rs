//! `atelier::run`: a scenario run into a folder — the report's fields present and sane, the
//! outputs complete, a diverging run still reported with its last good frame, and every fixture
//! scenario readable. Small, short scenes only (the whole file runs in seconds in release mode).

use std::path::{Path, PathBuf};

use atelier::report::Report;
use atelier::run::{RunOptions, outputs, run};
use atelier::scenario::Scenario;

use crate::scratch::Scratch;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .canonicalize()
        .expect("repository root")
}

/// A fresh run folder, removed when the test is done with it.
fn temp_dir(tag: &str) -> Scratch {
    Scratch::new("run", tag)
}

/// The skirt placed around the mannequin and sewn for `sew_limit` s (gravity never starts).
pub fn short_skirt(sew_limit: f64) -> String {
    let r = root();
    format!(
        r#"(
    name: "short_skirt",
    reproduces: "the first steps of sewing the dress skirt (test)",
    kind: Garment(
        garment: "{}/fixtures/patterns/dress/skirt.ron",
        fabric: "{}/fixtures/fabrics/cotton_broad.ron",
        placements: [
            Trunk(facing_deg: 0.0, y0: 0.98),
            Trunk(facing_deg: 180.0, y0: 0.98),
            Trunk(facing_deg: 180.0, y0: 0.98),
        ],
        settings: (sew_limit: {sew_limit}, frame_interval: 0.05),
    ),
    expectations: [(metric: "max_penetration_m", max: 0.01), (metric: "pairs_sewn", min: 1000.0)],
)"#,
        r.display(),
        r.display()
    )
}

/// A small, short drape (24 × 4 nodes, 0.3 s); `step` is inserted into the scene's `step`
/// overrides.
pub fn small_drape(step: &str) -> String {
    format!(
        r#"(
    name: "small_drape",
    reproduces: "a small, short JIS drape (test)",
    kind: Drape(fabric: "{}/fixtures/fabrics/cotton_broad.ron", tester: Jis, n_around: 24,
        n_rings: 4, dt: 0.002, max_time: 0.3, until_rest: false, step: ({step})),
    expectations: [(metric: "drape_coefficient_percent", min: 1.0, max: 100.0)],
)"#,
        root().display()
    )
}

fn run_text(text: &str, out: &Path) -> Report {
    let scenario = Scenario::parse(text, Path::new("test.ron")).expect("scenario");
    run(
        &scenario,
        None,
        Path::new("."),
        out,
        &RunOptions::default(),
        &mut |_| {},
    )
    .expect("runs")
}

fn finite(v: f64) -> bool {
    v.is_finite()
}

#[test]
fn a_garment_run_reports_every_field_and_writes_complete_outputs() {
    let out = temp_dir("garment");
    let report = run_text(&short_skirt(0.1), &out);
    // What was run.
    assert_eq!(report.format, Report::FORMAT);
    assert_eq!(report.scenario.kind, "Garment");
    assert!(report.fabric.contains("cotton"), "{}", report.fabric);
    assert!(report.nodes > 100 && report.triangles > 100, "{report:?}");
    assert_eq!(report.body_triangles, 2832);
    // Cost.
    assert_eq!(report.steps, 10, "0.1 s at Δt 0.01 s");
    assert!((report.dt_s - 0.01).abs() < 1e-15);
    assert!((report.simulated_s - 0.1).abs() < 1e-9);
    assert!(report.wall_s > 0.0 && report.setup_s >= 0.0);
    let st = report.stage_s;
    let sum = st.body
        + st.bending
        + st.internal
        + st.velocity
        + st.transfer
        + st.shape
        + st.collision
        + st.update
        + st.diagnostics;
    assert!(
        (sum - st.total).abs() < 1e-6 && st.total <= report.wall_s + 1e-6,
        "{st:?} / {}",
        report.wall_s
    );
    assert!(st.collision > 0.0, "the body contact was timed");
    assert!(st.diagnostics > 0.0, "the penetration check was timed");
    assert!(st.body == 0.0, "the body stands: no posing");
    // Metrics: every name the kind declares, finite where measured.
    let scenario = Scenario::parse(&short_skirt(0.1), Path::new("t.ron")).expect("scenario");
    for name in scenario.kind.metric_names() {
        assert!(report.metrics.contains_key(*name), "metric {name} missing");
    }
    for (k, v) in &report.metrics {
        if let Some(v) = v {
            assert!(finite(*v), "{k} = {v}");
        }
    }
    let m = |k: &str| report.metrics[k].expect(k);
    assert_eq!(m("nodes") as usize, report.nodes);
    assert!(m("pairs") > 0.0 && m("pairs_sewn") <= m("pairs"));
    assert_eq!(
        m("unsewn_pairs") as usize,
        (m("pairs") - m("pairs_sewn")) as usize
    );
    assert!(report.metrics["sewn_at_s"].is_none(), "not sewn in 0.1 s");
    assert!((0.0..0.01).contains(&m("max_penetration_m")));
    assert!(m("kinetic_energy_j") >= 0.0 && m("max_strain_error") >= 0.0);
    assert_eq!(m("frames") as usize, 3, "t = 0, 0.05, 0.10");
    // Expectations: one met, one (deliberately impossible) not.
    assert_eq!(report.expectations.len(), 2);
    assert!(report.expectations[0].met);
    assert!(!report.expectations[1].met);
    assert!(!report.expectations_met && !report.passed());
    assert!(report.failure.is_none());
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("sewing not finished")),
        "{:?}",
        report.warnings
    );
    // Outputs, complete.
    for name in [
        outputs::REPORT,
        outputs::OBJ,
        outputs::PLY,
        outputs::GLB,
        outputs::PICTURE,
    ] {
        assert!(out.join(name).is_file(), "{name} missing");
    }
    assert!(!report.outputs.iter().any(|o| o == outputs::TOP));
    let written = std::fs::read_to_string(out.join(outputs::REPORT)).expect("report");
    assert_eq!(Report::from_json(&written).expect("parses"), report);
    let glb = std::fs::read(out.join(outputs::GLB)).expect("glb");
    assert_eq!(&glb[..4], b"glTF");
    assert_eq!(
        u32::from_le_bytes(glb[8..12].try_into().expect("4 bytes")) as usize,
        glb.len()
    );
    let png = std::fs::read(out.join(outputs::PICTURE)).expect("png");
    assert_eq!(&png[1..4], b"PNG");
    let obj = std::fs::read_to_string(out.join(outputs::OBJ)).expect("obj");
    let vertices = obj.lines().filter(|l| l.starts_with("v ")).count();
    assert_eq!(
        vertices,
        report.nodes + 1450,
        "cloth and the 9AR body's 1450 vertices"
    );
    let leftovers: Vec<_> = std::fs::read_dir(&out)
        .expect("list")
        .filter_map(Result::ok)
        .filter(|e| e.file_name().to_string_lossy().contains(".tmp-"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
    std::fs::remove_dir_all(&out).ok();
}

#[test]
fn a_diverging_run_still_writes_its_report_and_last_good_frame() {
    // A divergence limit far below the strains of a falling specimen: the run stops at the
    // first step that stretches an edge by more than 0.01 %.
    let out = temp_dir("diverge");
    let report = run_text(&small_drape("divergence_strain: 0.0001"), &out);
    let failure = report.failure.as_deref().expect("diverged");
    assert!(failure.contains("diverging"), "{failure}");
    assert!(!report.passed());
    assert!(report.steps < 150, "stopped early: {}", report.steps);
    // Shape metrics are not measured after a failed step; the expectation on them fails.
    assert!(report.metrics["drape_coefficient_percent"].is_none());
    assert!(!report.expectations_met);
    // Outputs up to the last good frame, and the report.
    for name in [
        outputs::REPORT,
        outputs::OBJ,
        outputs::PLY,
        outputs::GLB,
        outputs::PICTURE,
        outputs::TOP,
    ] {
        assert!(out.join(name).is_file(), "{name} missing");
    }
    let obj = std::fs::read_to_string(out.join(outputs::OBJ)).expect("obj");
    assert!(
        obj.lines()
            .filter(|l| l.starts_with("v "))
            .flat_map(|l| l.split_whitespace().skip(1))
            .all(|v| v.parse::<f64>().is_ok_and(f64::is_finite)),
        "finite final frame"
    );
    std::fs::remove_dir_all(&out).ok();
}

#[test]
fn a_drape_run_measures_its_drape() {
    let out = temp_dir("drape");
    let report = run_text(&small_drape(""), &out);
    assert!(report.passed(), "{}", report.summary_line());
    let m = |k: &str| report.metrics[k].expect(k);
    assert_eq!(report.steps, 150);
    assert!((0.0..=100.0).contains(&m("drape_coefficient_percent")));
    assert!(m("shadow_area_m2") > 0.0);
    assert!(m("min_edge_radius_m") <= m("max_edge_radius_m"));
    // 24 around × 5 rings: the 4 of the scenario and the clamped ring inside the rim.
    assert_eq!(m("nodes") as usize, 120);
    assert!(report.outputs.iter().any(|o| o == outputs::TOP));
    // The top view the viewer draws: the tester of JIS L 1096 (specimen Ø 254 mm on a support
    // Ø 127 mm), the outer ring's 24 points, whose extreme radii are the measured ones, and one
    // outline point per counted node.
    let top = report
        .drape
        .as_ref()
        .expect("a drape run reports its top view");
    assert_eq!(
        (top.specimen_radius_m, top.support_radius_m),
        (0.127, 0.0635)
    );
    assert_eq!(top.outline_m.len(), 24);
    let radii: Vec<f64> = top.outline_m.iter().map(|p| p[0].hypot(p[1])).collect();
    let (lo, hi) = radii.iter().fold((f64::INFINITY, 0.0_f64), |(lo, hi), &r| {
        (lo.min(r), hi.max(r))
    });
    assert!((lo - m("min_edge_radius_m")).abs() < 1e-12);
    assert!((hi - m("max_edge_radius_m")).abs() < 1e-12);
    assert_eq!(top.node_points_m.len(), m("node_count") as usize);
    assert!(top.node_points_m.iter().all(|p| top.outline_m.contains(p)));
    std::fs::remove_dir_all(&out).ok();
}

#[test]
fn every_fixture_scenario_reads_and_names_existing_files() {
    let dir = root().join("fixtures/scenarios");
    let mut count = 0;
    for entry in std::fs::read_dir(&dir).expect("scenarios") {
        let path = entry.expect("entry").path();
        if path.extension().is_none_or(|e| e != "ron") {
            continue;
        }
        let s = Scenario::load(&path).unwrap_or_else(|e| panic!("{e}"));
        s.check_files(&atelier::run::base_of(&path))
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert_eq!(
            path.file_stem().and_then(|x| x.to_str()),
            Some(s.name.as_str()),
            "a scenario's name is its file name"
        );
        count += 1;
    }
    assert!(count >= 20, "{count} scenarios");
}

/// The virtual KES scenarios: each specimen's loop gives back the fabric's values (EMT, LT, WT,
/// RT within 1 %; B and 2HB within 1 %), and its chart is written as the picture.
#[test]
fn virtual_kes_scenarios_give_back_the_fabrics_values() {
    for (name, tolerance) in [
        ("kes_tensile_denim_weft", 0.01),
        ("kes_bending_denim_weft", 0.01),
        ("kes_bending_cotton_broad", 0.01),
    ] {
        let file = root().join(format!("fixtures/scenarios/{name}.ron"));
        let scenario = Scenario::load(&file).expect("scenario");
        let out = temp_dir(name);
        let report = run(
            &scenario,
            Some(&file),
            &atelier::run::base_of(&file),
            &out,
            &RunOptions::default(),
            &mut |_| {},
        )
        .expect("runs");
        assert!(report.passed(), "{}", report.summary_line());
        let err = report.metrics["largest_relative_error"].expect("measured");
        assert!(err < tolerance, "{name}: {err}");
        for k in scenario.kind.metric_names() {
            assert!(report.metrics.contains_key(*k), "{name}: {k}");
        }
        let png = std::fs::read(out.join("final.png")).expect("chart written");
        assert!(png.len() > 10_000 && png.starts_with(b"\x89PNG"));
        std::fs::remove_dir_all(&out).ok();
    }
}

/// A small wet scene (15 × 15 particles over 300 cm³ of air, pinched 1 cm, 0.3 s) on the PARTY
/// step, compared with Yamada's model: every wet metric is reported, the comparison carries
/// the second run's cost, and the series, both pictures and both charts are written.
#[test]
fn a_wet_run_reports_both_solvers_and_writes_its_series() {
    let text = format!(
        r#"(
    name: "small_wet",
    reproduces: "a small wet pinch (test)",
    kind: Wet(
        fabric: "{}/fixtures/fabrics/polyester_satin_wet.ron",
        scene: (
            particles: 15,
            pressure: (air: 3e-4),
            picks: [(at: (0.5, 0.5), by: (0.0, 0.0, 0.01), speed: 0.05)],
            duration: 0.3,
        ),
        solver: Party(dt: 0.005),
        compare: Yamada(),
    ),
    expectations: [(metric: "tent_height_mm", min: 5.0)],
)"#,
        root().display()
    );
    let out = temp_dir("wet");
    let report = run_text(&text, &out);
    assert!(report.passed(), "{}", report.summary_line());
    assert_eq!(report.scenario.kind, "Wet");
    assert_eq!(report.nodes, 225);
    for k in atelier::wet::METRICS {
        assert!(report.metrics.contains_key(*k), "{k}");
    }
    let m = |k: &str| report.metrics[k].expect(k);
    // Boyle's law in the final state, and both runs to the end.
    assert!((m("air_cm3") - 300.0).abs() < 1e-6);
    assert!((m("pressure_difference_pa")).abs() < 50.0);
    assert!(m("compare_failed") < 0.5, "the compared run failed");
    assert!(m("rms_difference_mm") < 5.0, "{}", m("rms_difference_mm"));
    let c = report.comparison.as_ref().expect("comparison");
    assert_eq!(c.solver, "yamada");
    assert!((c.simulated_s - 0.3).abs() < 1e-6 && c.failure.is_none());
    // Convergence: the main run's on PARTY; Yamada's model has none to report (null, not 0).
    let main = report.convergence.as_ref().expect("convergence");
    assert_eq!((main.solver.as_str(), main.steps), ("party", report.steps));
    let yamada = c
        .convergence
        .as_ref()
        .expect("the compared run's convergence");
    assert_eq!((yamada.solver.as_str(), yamada.steps), ("yamada", c.steps));
    assert!(yamada.unconverged_steps.is_none() && yamada.max_violation.is_none());
    for name in [
        outputs::PICTURE,
        outputs::COMPARE,
        outputs::SERIES,
        outputs::TENT,
        outputs::PRESSURE,
    ] {
        assert!(report.outputs.iter().any(|o| o == name), "{name}");
        assert!(out.join(name).is_file(), "{name}");
    }
    let csv = std::fs::read_to_string(out.join(outputs::SERIES)).expect("series");
    let rows: Vec<&str> = csv.lines().collect();
    assert!(rows[0].starts_with("solver,time_s,volume_cm3"));
    assert!(
        rows.iter().any(|r| r.starts_with("party,"))
            && rows.iter().any(|r| r.starts_with("yamada,"))
    );
    std::fs::remove_dir_all(&out).ok();
}

/// A string identification (Sudoh et al.) from an observation file: the synthetic rubber
/// string written as RON, its first 4 shapes fitted from the paper's initial values, reproduced
/// within the paper's largest error (1.68 px), the later shapes predicted within 2 px; every
/// metric reported; the fitted model written as `parameters.ron` (it reads back and is valid)
/// and the shapes as `final.png`. Without `initial` a file cannot start.
#[test]
fn a_string_fit_reports_its_errors_and_writes_its_parameters() {
    use atelier_fit::synthetic::{Object, SyntheticOptions, observe};
    let out = temp_dir("fit");
    let (obs, _) = observe(Object::Rubber, &SyntheticOptions::default()).expect("observed");
    let file = out.join("rubber.ron");
    std::fs::write(&file, obs.to_ron()).expect("observations");
    let scenario = |initial: &str| {
        format!(
            r#"(
    name: "small_fit",
    reproduces: "the rubber string fitted from a file (test)",
    kind: StringFit(observations: File("{}"), observed: 4{initial}),
    expectations: [(metric: "max_observed_error_px", max: 1.68)],
)"#,
            file.display()
        )
    };
    let report = run_text(
        &scenario(", initial: (stretch: 0.02, bending: 0.02)"),
        &out.join("run"),
    );
    assert!(report.passed(), "{}", report.summary_line());
    assert_eq!(report.scenario.kind, "StringFit");
    for k in atelier::fit::METRICS {
        assert!(report.metrics.contains_key(*k), "{k}");
    }
    let m = |k: &str| report.metrics[k].expect(k);
    assert!(
        m("mean_unobserved_error_px") < 2.0,
        "{}",
        m("mean_unobserved_error_px")
    );
    assert!(m("initial_unobserved_error_px") > m("mean_unobserved_error_px"));
    assert_eq!(m("observed_shapes") as usize, 4);
    assert_eq!(m("unobserved_shapes") as usize, 10);
    for name in [outputs::PARAMETERS, outputs::PICTURE] {
        assert!(out.join("run").join(name).is_file(), "{name}");
    }
    let text = std::fs::read_to_string(out.join("run").join(outputs::PARAMETERS)).expect("ron");
    let model: atelier_fit::StringModel = ron::from_str(&text).expect("parameters read back");
    model.params.validate().expect("valid parameters");
    assert_eq!(model.particles(), 9);
    // A file needs the initial s and b.
    let s = Scenario::parse(&scenario(""), "s.ron".as_ref()).expect("parses");
    let e = run(
        &s,
        None,
        &root(),
        &out.join("none"),
        &RunOptions::default(),
        &mut |_| {},
    )
    .expect_err("no initial values");
    assert!(e.to_string().contains("initial"), "{e}");
    std::fs::remove_dir_all(&out).ok();
}

// ---- convergence (issue 21) ----------------------------------------------------------------

/// The kinds of constraint a step can name as its worst.
const CONSTRAINTS: [&str; 5] = ["edge", "cell", "bend", "tie", "plane"];

/// `small_drape` with `extra` expectations before its own.
fn small_drape_expecting(step: &str, extra: &str) -> String {
    small_drape(step).replace("expectations: [", &format!("expectations: [{extra}, "))
}

/// A solver that cannot converge — one shape iteration per pass against a tolerance of 1e-9 —
/// is reported: every step counted in `convergence`, the largest violation and where it was,
/// the metric `unconverged_fraction`, a warning that says the numbers are not converged
/// results, and the run does not pass (`NOT CONVERGED`), all of it in the written report.
#[test]
fn a_run_that_cannot_converge_reports_its_unconverged_steps_and_warns() {
    let out = temp_dir("unconverged");
    let report = run_text(
        &small_drape("shape: (max_iterations: 1, tolerance: 1e-9)"),
        &out,
    );
    assert!(report.failure.is_none(), "{:?}", report.failure);
    let c = report.convergence.as_ref().expect("convergence reported");
    assert_eq!(c.solver, "party");
    assert_eq!(c.steps, report.steps);
    assert_eq!(c.steps, 150);
    let unconverged = c.unconverged_steps.expect("counted");
    let shape = c.shape_unconverged_steps.expect("counted");
    assert!(unconverged > 0 && unconverged <= c.steps, "{c:?}");
    assert!(shape > 0 && shape <= unconverged, "{c:?}");
    assert_eq!(c.tolerance, Some(1e-9));
    let largest = c.max_violation.expect("measured");
    assert!(largest > 1e-9 && largest.is_finite(), "{c:?}");
    let worst = c.worst.as_ref().expect("the worst step");
    assert!(
        CONSTRAINTS.contains(&worst.constraint.as_str()),
        "{worst:?}"
    );
    assert_eq!(worst.violation.to_bits(), largest.to_bits());
    assert!(worst.time_s >= 0.0 && worst.time_s < report.simulated_s);
    assert!(worst.phase.is_none(), "a drape has no phases");
    let fraction = report.metrics["unconverged_fraction"].expect("measured");
    assert!((fraction - unconverged as f64 / c.steps as f64).abs() < 1e-15);
    let warning = report
        .warnings
        .iter()
        .find(|w| w.contains("did not converge"))
        .expect("a warning");
    assert!(
        warning.starts_with(&format!("{unconverged} of 150 party steps"))
            && warning.contains("above the shape tolerance 1e-9")
            && warning.ends_with("numbers from those steps are not converged results"),
        "{warning}"
    );
    assert_eq!(report.convergence_warning().as_ref(), Some(warning));
    // The drape's own expectation is met; the run does not pass all the same.
    assert!(report.expectations_met);
    assert!(report.unconverged() && !report.passed());
    let line = report.summary_line();
    assert!(
        line.starts_with("NOT CONVERGED small_drape: 150 steps") && line.contains(warning),
        "{line}"
    );
    // The written report holds the same.
    let written = std::fs::read_to_string(out.join(outputs::REPORT)).expect("report");
    for field in [
        "\"convergence\"",
        "\"unconverged_steps\"",
        "\"shape_unconverged_steps\"",
        "\"max_violation\"",
        "\"tolerance\"",
        "\"worst\"",
        "\"unconverged_fraction\"",
    ] {
        assert!(written.contains(field), "{field} missing");
    }
    assert_eq!(Report::from_json(&written).expect("parses"), report);
    std::fs::remove_dir_all(&out).ok();
}

/// A scenario that bounds `unconverged_fraction` itself decides: within the bound the run
/// passes (the warning stays), beyond it the expectation is not met.
#[test]
fn a_scenario_bounding_unconverged_fraction_decides_whether_the_run_passes() {
    let step = "shape: (max_iterations: 1, tolerance: 1e-9)";
    let out = temp_dir("unconverged-accepted");
    let accepted = run_text(
        &small_drape_expecting(step, r#"(metric: "unconverged_fraction", max: 1.0)"#),
        &out,
    );
    assert!(accepted.convergence_warning().is_some());
    assert!(
        accepted
            .warnings
            .iter()
            .any(|w| w.contains("did not converge")),
        "{:?}",
        accepted.warnings
    );
    assert!(!accepted.unconverged());
    assert!(accepted.passed(), "{}", accepted.summary_line());
    assert!(accepted.summary_line().starts_with("ok small_drape"));
    let refused = run_text(
        &small_drape_expecting(step, r#"(metric: "unconverged_fraction", max: 0.01)"#),
        &out,
    );
    assert!(!refused.expectations[0].met, "{:?}", refused.expectations);
    assert!(!refused.passed());
    assert!(
        refused
            .summary_line()
            .starts_with("EXPECTATION NOT MET small_drape")
            && refused.summary_line().contains("unconverged_fraction = "),
        "{}",
        refused.summary_line()
    );
    std::fs::remove_dir_all(&out).ok();
}

/// A normal quick run converges: zero unconverged steps, its largest violation within the
/// tolerance, no warning, `unconverged_fraction` 0, and it passes.
#[test]
fn a_converged_run_reports_zero_unconverged_steps_and_no_warning() {
    let out = temp_dir("converged");
    let report = run_text(
        &small_drape_expecting("", r#"(metric: "unconverged_fraction", max: 0.0)"#),
        &out,
    );
    let c = report.convergence.as_ref().expect("convergence reported");
    assert_eq!((c.solver.as_str(), c.steps), ("party", report.steps));
    assert_eq!(c.unconverged_steps, Some(0), "{c:?}");
    assert_eq!(c.shape_unconverged_steps, Some(0), "{c:?}");
    assert_eq!(c.tolerance, Some(1e-4));
    let largest = c.max_violation.expect("measured");
    assert!((0.0..=1e-4).contains(&largest), "{largest}");
    assert_eq!(report.metrics["unconverged_fraction"], Some(0.0));
    assert!(report.convergence_warning().is_none());
    assert!(
        !report.warnings.iter().any(|w| w.contains("converge")),
        "{:?}",
        report.warnings
    );
    assert!(report.passed(), "{}", report.summary_line());
    std::fs::remove_dir_all(&out).ok();
}

/// A garment run counts its steps through the phases: the worst step names its phase, and a
/// run with unconverged steps warns and does not pass (whatever else happened to it).
#[test]
fn a_garment_run_reports_its_convergence_with_the_phase() {
    let out = temp_dir("garment-convergence");
    let report = run_text(&short_skirt(0.05), &out);
    let c = report.convergence.as_ref().expect("convergence reported");
    assert_eq!((c.solver.as_str(), c.steps), ("party", report.steps));
    assert_eq!(c.tolerance, Some(1e-4));
    let unconverged = c.unconverged_steps.expect("counted");
    assert!(c.shape_unconverged_steps.expect("counted") <= unconverged);
    assert!(c.max_violation.is_some_and(|v| v >= 0.0), "{c:?}");
    if let Some(w) = &c.worst {
        assert!(CONSTRAINTS.contains(&w.constraint.as_str()), "{w:?}");
        assert_eq!(w.phase.as_deref(), Some("Sewing"), "{w:?}");
    }
    assert_eq!(
        report.metrics["unconverged_fraction"],
        Some(unconverged as f64 / c.steps as f64)
    );
    let warned = report
        .warnings
        .iter()
        .any(|w| w.contains("did not converge"));
    assert_eq!(warned, unconverged > 0, "{:?}", report.warnings);
    if unconverged > 0 {
        assert!(!report.passed());
    }
    std::fs::remove_dir_all(&out).ok();
}

/// A baseline has no tolerance to meet: its convergence is `null`, not 0 (the solver and its
/// steps are given), so is `unconverged_fraction`, and an expectation on it is never met.
#[test]
fn a_baseline_run_does_not_report_convergence() {
    let text = short_skirt(0.05)
        .replace(
            "settings: (sew_limit: 0.05,",
            "settings: (solver: Xpbd(substeps: 10), sew_limit: 0.05,",
        )
        .replace(
            "expectations: [",
            r#"expectations: [(metric: "unconverged_fraction", max: 1.0), "#,
        );
    assert!(text.contains("Xpbd"));
    let out = temp_dir("baseline-convergence");
    let report = run_text(&text, &out);
    let c = report.convergence.as_ref().expect("convergence given");
    assert_eq!((c.solver.as_str(), c.steps), ("xpbd", report.steps));
    assert!(c.steps > 0);
    assert_eq!(
        (
            c.unconverged_steps,
            c.shape_unconverged_steps,
            c.max_violation,
            c.tolerance,
            &c.worst
        ),
        (None, None, None, None, &None)
    );
    assert_eq!(report.metrics["unconverged_fraction"], None);
    assert!(!report.expectations[0].met && report.expectations[0].value.is_none());
    assert!(report.convergence_warning().is_none() && !report.unconverged());
    let written = std::fs::read_to_string(out.join(outputs::REPORT)).expect("report");
    assert!(
        written.contains("\"unconverged_steps\": null"),
        "null, not 0"
    );
    std::fs::remove_dir_all(&out).ok();
}

/// `unconverged_fraction` is a metric of every kind that steps a cloth (`atelier validate`
/// accepts an expectation on it) and not of the string identification.
#[test]
fn unconverged_fraction_is_a_metric_of_every_kind_that_steps_a_cloth() {
    let dir = root().join("fixtures/scenarios");
    for entry in std::fs::read_dir(&dir).expect("scenarios") {
        let path = entry.expect("entry").path();
        if path.extension().is_none_or(|e| e != "ron") {
            continue;
        }
        let s = Scenario::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let listed = s.kind.metric_names().contains(&"unconverged_fraction");
        assert_eq!(listed, s.kind.name() != "StringFit", "{}", path.display());
    }
    Scenario::parse(
        &small_drape_expecting("", r#"(metric: "unconverged_fraction", max: 0.01)"#),
        Path::new("d.ron"),
    )
    .expect("a drape may bound it");
    let fit = r#"(name: "f", reproduces: "test", kind: StringFit(observations: Synthetic(Rubber), observed: 4),
        expectations: [(metric: "unconverged_fraction", max: 0.01)])"#;
    let e = Scenario::parse(fit, Path::new("f.ron")).expect_err("no solver steps");
    assert_eq!(e.field, "expectations[0].metric", "{e}");
}

/// What every counted run's `convergence` holds, checked against the report: the PARTY step,
/// `steps` simulated steps, counts within them, a finite largest violation, the warning and
/// the exit status following the count.
fn assert_counted(report: &Report, steps: usize, tolerance: f64) {
    let c = report.convergence.as_ref().expect("convergence reported");
    assert_eq!(c.solver, "party");
    assert_eq!(c.steps, steps, "{c:?}");
    assert_eq!(report.steps, steps);
    let unconverged = c.unconverged_steps.expect("counted, not null");
    let shape = c.shape_unconverged_steps.expect("counted, not null");
    assert!(shape <= unconverged && unconverged <= steps, "{c:?}");
    assert!(c.max_violation.is_some_and(f64::is_finite), "{c:?}");
    assert_eq!(c.tolerance, Some(tolerance));
    if let Some(w) = &c.worst {
        assert!(CONSTRAINTS.contains(&w.constraint.as_str()), "{w:?}");
        assert!(w.phase.is_none() && w.time_s < report.simulated_s, "{w:?}");
    }
    assert_eq!(
        report.metrics["unconverged_fraction"],
        Some(unconverged as f64 / steps as f64)
    );
    assert_eq!(report.convergence_warning().is_some(), unconverged > 0);
    if unconverged > 0 {
        assert!(!report.passed());
        assert!(
            report.summary_line().contains("did not converge"),
            "{}",
            report.summary_line()
        );
    }
}

/// The virtual KES tests count their steps: a short FB2 bending test (100 steps per leg of
/// 2.5 cm⁻¹ at the KES rate 0.5 cm⁻¹/s: four legs' worth, 20 s, at Δt 5 s / 100 = 0.05 s, is
/// 400 steps) and an FB1 tensile test to 20 gf/cm (at the instrument's Δt 0.01 s, as many steps
/// as its simulated time holds) both report a counted `convergence`, held to the
/// instruments' shape tolerance 1e-7.
#[test]
fn virtual_kes_runs_report_their_convergence() {
    let fabric = root().join("fixtures/fabrics/cotton_broad.ron");
    let bending = format!(
        r#"(name: "short_kes_bending", reproduces: "a short KES-FB2 bending test (test)",
    kind: KesBending(fabric: "{}", direction: Warp, steps_per_leg: 100))"#,
        fabric.display()
    );
    let out = temp_dir("kes-convergence");
    let report = run_text(&bending, &out);
    let (duration, dt) = (4.0 * 2.5 / 0.5, 5.0 / 100.0);
    assert!(
        (report.simulated_s - duration).abs() < 1e-6,
        "{}",
        report.simulated_s
    );
    assert!((report.dt_s - dt).abs() < 1e-12, "{}", report.dt_s);
    assert_counted(&report, (duration / dt).round() as usize, 1e-7);
    let tensile = format!(
        r#"(name: "short_kes_tensile", reproduces: "a KES-FB1 tensile test to 20 gf/cm (test)",
    kind: KesTensile(fabric: "{}", direction: Warp, max_force_gf_cm: 20.0))"#,
        fabric.display()
    );
    let report = run_text(&tensile, &out);
    assert_eq!(report.dt_s.to_bits(), 0.01_f64.to_bits());
    let steps = (report.simulated_s / 0.01).round() as usize;
    assert!(steps > 10, "{steps}");
    assert_counted(&report, steps, 1e-7);
    let written = std::fs::read_to_string(out.join(outputs::REPORT)).expect("report");
    assert_eq!(Report::from_json(&written).expect("parses"), report);
    std::fs::remove_dir_all(&out).ok();
}

/// A wet scene on the PARTY step counts its steps (0.1 s at Δt 5 ms: 20), and so does a
/// compared PARTY run (at Δt 10 ms: 10), in `comparison.convergence`; its unconverged steps
/// warn and make the run not pass as the main run's do.
#[test]
fn wet_party_runs_report_their_convergence() {
    let text = format!(
        r#"(
    name: "short_wet",
    reproduces: "a short wet pinch on the PARTY step, compared with itself at twice the step (test)",
    kind: Wet(
        fabric: "{}/fixtures/fabrics/polyester_satin_wet.ron",
        scene: (
            particles: 10,
            pressure: (air: 3e-4),
            picks: [(at: (0.5, 0.5), by: (0.0, 0.0, 0.01), speed: 0.05)],
            duration: 0.1,
        ),
        solver: Party(dt: 0.005),
        compare: Party(dt: 0.01),
    ),
)"#,
        root().display()
    );
    let out = temp_dir("wet-convergence");
    let report = run_text(&text, &out);
    assert!(report.failure.is_none(), "{:?}", report.failure);
    let (duration, dt, compared_dt): (f64, f64, f64) = (0.1, 0.005, 0.01);
    assert_counted(&report, (duration / dt).round() as usize, 1e-4);
    let compared = report.comparison.as_ref().expect("comparison");
    let c = compared.convergence.as_ref().expect("its convergence");
    assert_eq!(c.solver, "party");
    assert_eq!(c.steps, (duration / compared_dt).round() as usize);
    assert_eq!(compared.steps, c.steps);
    let unconverged = c.unconverged_steps.expect("counted, not null");
    assert!(c.shape_unconverged_steps.expect("counted") <= unconverged);
    assert!(c.max_violation.is_some_and(f64::is_finite), "{c:?}");
    let warned = report
        .warnings
        .iter()
        .any(|w| w.starts_with("the compared party run: ") && w.contains("did not converge"));
    assert_eq!(warned, unconverged > 0, "{:?}", report.warnings);
    if unconverged > 0 {
        assert!(report.unconverged() && !report.passed());
    }
    std::fs::remove_dir_all(&out).ok();
}

/// A one-sided push cut short: the skirt, laid out and sewn in front of the body, pushed through
/// it at 2 m/s² for at most 0.4 s (16 cm: into the body, not through it, which is ~25 cm deep at
/// the hips). The run ends at the push limit with the nodes inside, which `max_penetration_m`
/// does not count (the push goes through the body by design); `nodes_inside_at_end` does, so
/// the scenario's expectation on it is missed and the run does not pass. The same skirt sewn
/// around the body ends with none inside.
#[test]
fn a_push_that_does_not_get_through_leaves_nodes_inside_at_the_end() {
    let r = root();
    let text = format!(
        r#"(
    name: "short_push",
    reproduces: "a one-sided push cut short (test)",
    kind: Garment(
        garment: "{}/fixtures/patterns/dress/skirt.ron",
        fabric: "{}/fixtures/fabrics/cotton_broad.ron",
        placements: [
            Flat(at: (0.0, 0.98, 0.20)),
            Flat(at: (0.0, 0.98, 0.19), back: true),
            Flat(at: (0.0, 0.98, 0.19), back: true),
        ],
        settings: (dressing: OneSided(push: 2.0, push_time: 0.4, push_limit: 0.4), settle: 0.1),
    ),
    expectations: [(metric: "nodes_inside_at_end", max: 0)],
)"#,
        r.display(),
        r.display()
    );
    let pushed = run_text(&text, &temp_dir("short_push"));
    let inside = pushed.metrics["nodes_inside_at_end"].expect("measured");
    eprintln!("pushed 0.4 s: {inside} nodes inside at the end");
    assert!(
        inside >= 10.0,
        "{inside} nodes inside; {:?}",
        pushed.warnings
    );
    assert!(
        pushed
            .warnings
            .iter()
            .any(|w| w.contains("did not get the garment through")),
        "{:?}",
        pushed.warnings
    );
    assert!(!pushed.expectations_met && !pushed.passed());
    // Pushing is not counted in the running penetration metrics.
    assert_eq!(pushed.metrics["max_penetration_m"], Some(0.0));
    let sewn = run_text(&short_skirt(0.1), &temp_dir("short_skirt_inside"));
    assert_eq!(sewn.metrics["nodes_inside_at_end"], Some(0.0));
}
