//! The `atelier` program: `validate` (success, a bad file, a missing file) and `run` (success,
//! a bad file, a missing file, an unwritable folder, a diverging run, a run whose steps do not
//! converge, an interrupted run, determinism, the default scenario) — exit codes, one-line
//! errors, the files written.

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Run the program from the repository root: exit code, stdout, stderr.
fn status(args: &[&str]) -> (Option<i32>, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_atelier"))
        .args(args)
        .current_dir(root())
        .output()
        .expect("runs");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn atelier(args: &[&str]) -> (bool, String, String) {
    let (code, stdout, stderr) = status(args);
    (code == Some(0), stdout, stderr)
}

#[test]
fn every_fixture_validates_and_is_recognised() {
    let (ok, out, err) = atelier(&[
        "validate",
        "fixtures/fabrics/cotton_broad.ron",
        "fixtures/patterns/dress/front_bodice.ron",
        "fixtures/patterns/dress/dress.ron",
        "fixtures/bodies/jis_9ar.ron",
        "fixtures/motions/walk.ron",
    ]);
    assert!(ok, "{out}{err}");
    for kind in [
        "(fabric)",
        "(pattern)",
        "(garment)",
        "(body description)",
        "(motion)",
    ] {
        assert!(out.contains(kind), "{kind} missing in\n{out}");
    }
    assert_eq!(out.lines().count(), 5);
}

#[test]
fn a_bad_file_is_reported_with_its_position_and_field_and_fails() {
    let dir = std::env::temp_dir().join(format!("atelier-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let bad = dir.join("bad_pattern.ron");
    std::fs::write(
        &bad,
        r#"(name: "x", provenance: "x", grain: ((0.0, 0.0), (0.0, 1.0)),
  outline: Quad(start: (0.0, 0.0),
    bottom: [(name: "b", cells: 4, path: [Line(NaN, 0.0)])],
    right: [(name: "r", cells: 4, path: [Line(10.0, 10.0)])],
    top: [(name: "t", cells: 4, path: [Line(0.0, 10.0)])],
    left: [(name: "l", cells: 4, path: [Line(0.0, 0.0)])]))"#,
    )
    .expect("write");
    let missing = dir.join("missing.ron");
    let (ok, out, err) = atelier(&[
        "validate",
        bad.to_str().expect("utf-8"),
        missing.to_str().expect("utf-8"),
        "fixtures/motions/walk.ron",
    ]);
    assert!(!ok, "must fail:\n{out}");
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines.len(), 3, "{out}");
    assert!(
        lines[0].starts_with("error")
            && lines[0].contains("bad_pattern.ron:6:")
            && lines[0].contains("outline.bottom[0].path[0]")
            && lines[0].contains("read as a pattern"),
        "{}",
        lines[0]
    );
    assert!(
        lines[1].contains("missing.ron") && lines[1].contains("cannot read"),
        "{}",
        lines[1]
    );
    assert!(lines[2].starts_with("ok"), "{}", lines[2]);
    assert!(err.contains("2 of 3 files"), "{err}");
    assert!(
        !err.contains("panicked") && !err.contains("backtrace"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

// ---- atelier run -------------------------------------------------------------------------

fn temp_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("atelier-cli-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

fn fabric_path() -> String {
    root()
        .join("fixtures/fabrics/cotton_broad.ron")
        .canonicalize()
        .expect("fixture")
        .display()
        .to_string()
}

/// A JIS drape on an `n × m` grid for `seconds` at Δt 2 ms, never stopping early.
fn drape_scenario(n_around: usize, n_rings: usize, seconds: f64) -> String {
    format!(
        r#"(
    name: "cli_drape",
    reproduces: "a short JIS drape (CLI test)",
    kind: Drape(fabric: "{}", tester: Jis, n_around: {n_around}, n_rings: {n_rings}, dt: 0.002,
        max_time: {seconds}, until_rest: false),
    expectations: [(metric: "drape_coefficient_percent", min: 1.0, max: 100.0)],
)"#,
        fabric_path()
    )
}

/// The dress skirt sewn for 0.1 s (gravity never starts).
fn skirt_scenario() -> String {
    let r = root().canonicalize().expect("root");
    format!(
        r#"(
    name: "cli_skirt",
    reproduces: "the first steps of sewing the dress skirt (CLI test)",
    kind: Garment(
        garment: "{}/fixtures/patterns/dress/skirt.ron",
        fabric: "{}",
        placements: [
            Trunk(facing_deg: 0.0, y0: 0.98),
            Trunk(facing_deg: 180.0, y0: 0.98),
            Trunk(facing_deg: 180.0, y0: 0.98),
        ],
        settings: (sew_limit: 0.1),
    ),
)"#,
        r.display(),
        fabric_path()
    )
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).expect("write scenario");
    p
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

fn no_panic(err: &str) {
    assert!(
        !err.contains("panicked") && !err.contains("backtrace") && !err.contains("RUST_BACKTRACE"),
        "{err}"
    );
}

fn report(dir: &Path) -> atelier::report::Report {
    let text = std::fs::read_to_string(dir.join("report.json")).expect("report.json");
    atelier::report::Report::from_json(&text).expect("a complete report")
}

#[test]
fn run_writes_the_report_and_outputs_and_succeeds() {
    let dir = temp_dir("ok");
    let file = write(&dir, "drape.ron", &drape_scenario(24, 4, 0.2));
    let out = dir.join("out");
    let (ok, stdout, err) = atelier(&["run", s(&file), "--out", s(&out), "--frames", "3"]);
    assert!(ok, "{stdout}{err}");
    assert!(
        stdout.starts_with("ok cli_drape: 100 steps") && stdout.lines().count() == 1,
        "{stdout}"
    );
    assert!(err.is_empty(), "quiet when stderr is not a terminal: {err}");
    let r = report(&out);
    assert!(r.passed());
    assert_eq!(r.scenario.file.as_deref(), Some(s(&file)));
    for name in &r.outputs {
        assert!(out.join(name).is_file(), "{name}");
    }
    assert_eq!(r.outputs.len(), 5, "{:?}", r.outputs);
    // --frames 3: the animation keeps three of the six frames (t = 0 … 0.2 s every 0.04 s).
    let glb = std::fs::read(out.join("run.glb")).expect("glb");
    let json_len = u32::from_le_bytes(glb[12..16].try_into().expect("4 bytes")) as usize;
    let json = String::from_utf8_lossy(&glb[20..20 + json_len]);
    assert_eq!(json.matches("frame ").count(), 2, "two morph targets");
    std::fs::remove_dir_all(&dir).ok();
}

/// A small drape whose solver cannot converge (one shape iteration per pass against 1e-9), with
/// `extra` expectations.
fn unconverged_drape_scenario(extra: &str) -> String {
    format!(
        r#"(
    name: "cli_unconverged",
    reproduces: "a drape whose steps cannot converge (CLI test)",
    kind: Drape(fabric: "{}", tester: Jis, n_around: 24, n_rings: 4, dt: 0.002, max_time: 0.1,
        until_rest: false, step: (shape: (max_iterations: 1, tolerance: 1e-9))),
    expectations: [{extra}],
)"#,
        fabric_path()
    )
}

/// Steps that did not converge make the run fail as a doubtful result does (the try-on's low
/// overlap): exit status 2, one line on stderr naming them, the report written with the
/// warning. A scenario that bounds `unconverged_fraction` itself decides: within the bound exit
/// 0, the summary on stdout and the warning on stderr.
#[test]
fn a_run_whose_steps_do_not_converge_exits_2_and_says_so() {
    let dir = temp_dir("unconverged");
    let file = write(&dir, "u.ron", &unconverged_drape_scenario(""));
    let out = dir.join("out");
    let (code, stdout, err) = status(&["run", s(&file), "--out", s(&out)]);
    no_panic(&err);
    assert_eq!(code, Some(2), "{stdout}{err}");
    assert!(stdout.is_empty(), "{stdout}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.starts_with("atelier: NOT CONVERGED cli_unconverged: 50 steps")
            && err.contains("did not converge")
            && err.contains("not converged results"),
        "{err}"
    );
    let r = report(&out);
    assert!(!r.passed());
    assert!(r.convergence.as_ref().and_then(|c| c.unconverged_steps) > Some(0));
    assert!(r.warnings.iter().any(|w| w.contains("did not converge")));

    let file = write(
        &dir,
        "a.ron",
        &unconverged_drape_scenario(r#"(metric: "unconverged_fraction", max: 1.0)"#),
    );
    let (code, stdout, err) = status(&["run", s(&file), "--out", s(&out)]);
    assert_eq!(code, Some(0), "{stdout}{err}");
    assert!(
        stdout.starts_with("ok cli_unconverged: 50 steps"),
        "{stdout}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.starts_with("atelier: warning: ") && err.contains("did not converge"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn validate_reads_scenarios() {
    let (ok, out, err) = atelier(&[
        "validate",
        "fixtures/scenarios/dress_sewn.ron",
        "fixtures/scenarios/drape_jis_silk.ron",
    ]);
    assert!(ok, "{out}{err}");
    assert_eq!(out.matches("(scenario)").count(), 2, "{out}");
}

#[test]
fn a_bad_scenario_is_reported_with_file_line_column_and_field() {
    let dir = temp_dir("bad");
    let file = write(
        &dir,
        "bad.ron",
        "(\n    name: \"bad\", reproduces: \"x\",\n    kind: Drape(fabric: \"f.ron\", tester: Jiss),\n)",
    );
    let out = dir.join("out");
    let (ok, stdout, err) = atelier(&["run", s(&file), "--out", s(&out)]);
    assert!(!ok);
    assert!(stdout.is_empty(), "{stdout}");
    no_panic(&err);
    assert_eq!(err.lines().count(), 1, "one line: {err}");
    assert!(
        err.contains("bad.ron:3:") && err.contains("field `kind.tester`") && err.contains("Jiss"),
        "{err}"
    );
    assert!(
        !out.exists(),
        "nothing written for a file that does not read"
    );
    // An expectation on a metric the kind does not have: named with its field.
    let file = write(
        &dir,
        "bad_metric.ron",
        &drape_scenario(24, 4, 0.1).replace("drape_coefficient_percent", "drape_coef"),
    );
    let (ok, _, err) = atelier(&["run", s(&file), "--out", s(&out)]);
    assert!(!ok);
    assert!(
        err.contains("bad_metric.ron") && err.contains("expectations[0].metric"),
        "{err}"
    );
    let (ok, stdout, _) = atelier(&["validate", s(&file)]);
    assert!(!ok && stdout.contains("expectations[0].metric"), "{stdout}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_missing_scenario_or_fabric_fails_with_one_line() {
    let dir = temp_dir("missing");
    let out = dir.join("out");
    let missing = dir.join("nowhere.ron");
    let (ok, _, err) = atelier(&["run", s(&missing), "--out", s(&out)]);
    assert!(!ok);
    no_panic(&err);
    assert!(
        err.lines().count() == 1 && err.contains("nowhere.ron") && err.contains("cannot read"),
        "{err}"
    );
    let file = write(
        &dir,
        "no_fabric.ron",
        &drape_scenario(24, 4, 0.1).replace(&fabric_path(), "no_such_fabric.ron"),
    );
    let (ok, _, err) = atelier(&["run", s(&file), "--out", s(&out)]);
    assert!(!ok);
    no_panic(&err);
    assert!(
        err.lines().count() == 1 && err.contains("no_such_fabric.ron"),
        "{err}"
    );
    assert!(!out.join("report.json").exists());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn an_unwritable_output_folder_fails_before_simulating() {
    // Root can write anywhere; a folder below a regular file cannot be made by anyone.
    let dir = temp_dir("unwritable");
    let file = write(&dir, "drape.ron", &drape_scenario(24, 4, 0.1));
    let blocker = dir.join("a_file");
    std::fs::write(&blocker, b"not a folder").expect("write");
    let out = blocker.join("out");
    let (ok, stdout, err) = atelier(&["run", s(&file), "--out", s(&out)]);
    assert!(!ok, "{stdout}");
    no_panic(&err);
    assert!(
        err.lines().count() == 1 && err.contains("cannot write") && err.contains("a_file"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_diverging_run_exits_non_zero_with_a_one_line_summary_and_its_report() {
    let dir = temp_dir("diverge");
    let text = drape_scenario(24, 4, 0.2).replace(
        "until_rest: false",
        "until_rest: false, step: (divergence_strain: 0.0001)",
    );
    let file = write(&dir, "diverge.ron", &text);
    let out = dir.join("out");
    let (ok, stdout, err) = atelier(&["run", s(&file), "--out", s(&out)]);
    assert!(!ok);
    assert!(stdout.is_empty(), "{stdout}");
    no_panic(&err);
    assert!(
        err.lines().count() == 1 && err.contains("FAILED cli_drape") && err.contains("diverging"),
        "{err}"
    );
    let r = report(&out);
    assert!(r.failure.is_some());
    assert!(out.join("final.obj").is_file() && out.join("run.glb").is_file());
    std::fs::remove_dir_all(&dir).ok();
}

/// Killed at any moment — while simulating or while writing — a run leaves every output file
/// whole: either the previous run's or the new one's (the same bytes here: the scene is
/// deterministic with one thread), never a part of one; temporary files it may leave beside
/// them are hidden, and the next run removes them.
#[test]
fn an_interrupted_run_leaves_the_previous_outputs_whole() {
    let dir = temp_dir("interrupt");
    let file = write(&dir, "drape.ron", &drape_scenario(48, 6, 0.6));
    let out = dir.join("out");
    let args = [
        "run",
        s(&file),
        "--out",
        s(&out),
        "--threads",
        "1",
        "--frames",
        "1000",
    ];
    let clock = std::time::Instant::now();
    let (ok, stdout, err) = atelier(&args);
    let full = clock.elapsed();
    assert!(ok, "{stdout}{err}");
    let snapshot = |dir: &Path| -> Vec<(String, Vec<u8>)> {
        let mut files: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
            .expect("list")
            .filter_map(Result::ok)
            .map(|e| {
                (
                    e.file_name().to_string_lossy().into_owned(),
                    std::fs::read(e.path()).expect("read"),
                )
            })
            .collect();
        files.sort();
        files
    };
    let before = snapshot(&out);
    let metrics = report(&out).metrics;
    for k in 0..10 {
        // Kills spread over 10 % … 120 % of a full run's time.
        let delay = full.mul_f64(0.1 + 0.12 * k as f64);
        let mut child = Command::new(env!("CARGO_BIN_EXE_atelier"))
            .args(args)
            .current_dir(root())
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .expect("starts");
        std::thread::sleep(delay);
        let _ = child.kill();
        let _ = child.wait();
        for (name, bytes) in snapshot(&out) {
            if name.starts_with('.') && name.contains(".tmp-") {
                continue; // a write cut short, beside the outputs
            }
            let old = before
                .iter()
                .find(|(n, _)| *n == name)
                .unwrap_or_else(|| panic!("unexpected file {name}"));
            if name == "report.json" {
                let text = String::from_utf8(bytes).expect("utf-8");
                let r = atelier::report::Report::from_json(&text)
                    .unwrap_or_else(|e| panic!("kill after {delay:?}: report cut: {e}"));
                assert_eq!(r.metrics, metrics);
            } else {
                assert!(bytes == old.1, "kill after {delay:?}: {name} differs");
            }
        }
        for (name, _) in &before {
            assert!(out.join(name).is_file(), "{name} lost");
        }
    }
    let (ok, _, err) = atelier(&args);
    assert!(ok, "{err}");
    let after = snapshot(&out);
    assert!(
        after.iter().all(|(n, _)| !n.contains(".tmp-")),
        "temporary files left: {:?}",
        after.iter().map(|(n, _)| n).collect::<Vec<_>>()
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn the_same_scenario_twice_on_one_thread_gives_identical_metrics() {
    let dir = temp_dir("determinism");
    for (name, text) in [
        ("skirt.ron", skirt_scenario()),
        ("drape.ron", drape_scenario(24, 4, 0.2)),
    ] {
        let file = write(&dir, name, &text);
        let metrics: Vec<String> = ["a", "b"]
            .iter()
            .map(|run| {
                let out = dir.join(format!("{name}-{run}"));
                let (_, stdout, err) =
                    atelier(&["run", s(&file), "--out", s(&out), "--threads", "1"]);
                no_panic(&err);
                let text = std::fs::read_to_string(out.join("report.json"))
                    .unwrap_or_else(|e| panic!("{stdout}{err}: {e}"));
                // The metrics object exactly as written.
                let start = text.find("\"metrics\"").expect("metrics");
                let end = start + text[start..].find('}').expect("end of metrics");
                text[start..=end].to_string()
            })
            .collect();
        assert!(metrics[0].len() > 100, "{}", metrics[0]);
        assert_eq!(metrics[0], metrics[1], "{name}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// The README's first command: `atelier` with no arguments, from a folder outside the source
/// tree, runs the built-in `default` scenario in full into ./atelier-out and passes it.
#[test]
fn with_no_arguments_the_default_scenario_runs_from_any_folder() {
    let dir = temp_dir("default");
    let out = Command::new(env!("CARGO_BIN_EXE_atelier"))
        .current_dir(&dir)
        .output()
        .expect("runs");
    let err = String::from_utf8_lossy(&out.stderr);
    no_panic(&err);
    // The run passes: every step converged and every expectation of `default.ron` met (no
    // seam left open, no node deeper than 2 mm in the body) over the whole run. This test is
    // the one that runs `default` in full in `cargo test` (fixtures/scenarios/CI.md).
    let r = report(&dir.join("atelier-out"));
    assert_eq!(r.scenario.name, "default");
    assert!(r.scenario.file.is_none());
    assert_eq!(out.status.code(), Some(0), "{}: {err}", r.summary_line());
    assert!(r.passed(), "{}", r.summary_line());
    assert!(!r.expectations.is_empty());
    assert!(dir.join("atelier-out/final.png").is_file());
    std::fs::remove_dir_all(&dir).ok();
}

/// `atelier fit`: a warp profile sampled from the elastica of cotton broad's own bending length
/// gives back its B (0.118 gf·cm²/cm, printed to four digits) and writes fabric.ron and
/// fit_report.json; a point beyond the overhang fails with exit status 1, the file, the field
/// and nothing written.
#[test]
fn atelier_fit_prints_the_fitted_rigidity_and_refuses_a_bad_profile() {
    let dir = std::env::temp_dir().join(format!("atelier-cli-fit-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("dir");
    let base = root().join("fixtures/fabrics/cotton_broad.ron");
    let f = atelier_fabric::Fabric::load(&base).expect("fabric");
    let c = (f.bending.warp.rigidity() / f.weight_per_area()).cbrt();
    let length = 2.0003 * c;
    let lambda = (length / c).powi(3);
    let e = atelier_fit::cloth::elastica(lambda, 2000);
    let points: Vec<String> = (1..=20)
        .map(|k| {
            let (x, y) = e[k * 100];
            format!(
                "({}, {}, {})",
                k as f64 * length / 20.0,
                x * length,
                y * length
            )
        })
        .collect();
    let write = |name: &str, pts: &str| {
        let path = dir.join(name);
        std::fs::write(
            &path,
            format!(
                r#"ClothObservations(name: "t", provenance: "elastica (test)", base: "{}",
  cantilevers: [(direction: Warp, overhang: {length}, points: [{pts}])])"#,
                base.display()
            ),
        )
        .expect("write");
        path
    };
    let good = write("good.ron", &points.join(", "));
    let out = dir.join("out");
    let (ok, stdout, err) = atelier(&[
        "fit",
        good.to_str().expect("utf-8"),
        "--out",
        out.to_str().expect("utf-8"),
    ]);
    assert!(ok, "{stdout}{err}");
    assert!(stdout.contains("Warp: B = 0.1180 gf·cm²/cm"), "{stdout}");
    assert!(out.join("fabric.ron").is_file() && out.join("fit_report.json").is_file());
    let bad = write(
        "bad.ron",
        &format!("{}, ({}, 0.0, 0.0)", points.join(", "), 2.0 * length),
    );
    let bad_out = dir.join("bad_out");
    let (ok, _, err) = atelier(&[
        "fit",
        bad.to_str().expect("utf-8"),
        "--out",
        bad_out.to_str().expect("utf-8"),
    ]);
    assert!(!ok);
    assert!(
        err.contains("bad.ron") && err.contains("cantilevers[0]"),
        "{err}"
    );
    assert!(!bad_out.exists());
    std::fs::remove_dir_all(&dir).ok();
}

// ---- atelier tryon -----------------------------------------------------------------------

#[test]
fn tryon_runs_the_fixture_and_refuses_a_mask_of_another_picture() {
    let dir = temp_dir("tryon");
    let out = dir.join("out");
    let out_s = out.display().to_string();
    // The README's command: exit 0, one line with the overlap, the outputs written.
    let (code, stdout, stderr) = status(&[
        "tryon",
        "--photo",
        "fixtures/tryon/arms_raised.png",
        "--mask",
        "fixtures/tryon/arms_raised_mask.png",
        "--garment",
        "fixtures/scenarios/skirt_sewn.ron",
        "--yaw",
        "30",
        "--light",
        "-0.5,1,1",
        "--out",
        &out_s,
    ]);
    assert_eq!(code, Some(0), "{stdout}{stderr}");
    assert!(
        stdout.contains("silhouette overlap 0.2") && stdout.contains("→ 0.99"),
        "{stdout}"
    );
    for name in [
        "composite.png",
        "overlay.png",
        "footprint.png",
        "fitted_pose.ron",
        "report.json",
    ] {
        assert!(out.join(name).is_file(), "{name}");
    }
    let report = std::fs::read_to_string(out.join("report.json")).expect("report");
    assert!(report.contains("\"light\": [\n      -0.5,"), "{report}");
    // The other photograph's picture as the mask: not black and white, exit 1, one line, the
    // file named; the earlier outputs untouched.
    let before = std::fs::read(out.join("composite.png")).expect("composite");
    let (code, stdout, stderr) = status(&[
        "tryon",
        "--photo",
        "fixtures/tryon/arms_raised.png",
        "--mask",
        "fixtures/tryon/mid_stride.png",
        "--garment",
        "fixtures/scenarios/skirt_sewn.ron",
        "--out",
        &out_s,
    ]);
    assert_eq!(code, Some(1), "{stdout}{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.contains("mid_stride.png") && stderr.contains("not a mask"),
        "{stderr}"
    );
    assert_eq!(
        std::fs::read(out.join("composite.png")).expect("composite"),
        before
    );
    // A light of zeros is refused by the argument parser: exit 1, as for any run that cannot
    // start (clap's own code would be 2, atelier's "ran but failed").
    let (code, _, stderr) = status(&[
        "tryon",
        "--photo",
        "p.png",
        "--garment",
        "g.ron",
        "--light",
        "0,0,0",
        "--out",
        &out_s,
    ]);
    assert_eq!(code, Some(1), "{stderr}");
    assert!(stderr.contains("not all zero"), "{stderr}");
    // A direction that is neither degrees nor `search` is refused the same way.
    let (code, _, stderr) = status(&[
        "tryon",
        "--photo",
        "p.png",
        "--garment",
        "g.ron",
        "--yaw",
        "north",
        "--out",
        &out_s,
    ]);
    assert_eq!(code, Some(1), "{stderr}");
    assert!(
        stderr.contains("`north`") && stderr.contains("search"),
        "{stderr}"
    );
    // Help is not an error.
    let (code, stdout, _) = status(&["tryon", "--help"]);
    assert_eq!(code, Some(0));
    assert!(
        stdout.contains("--yaw") && stdout.contains("search"),
        "{stdout}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
