//! `cargo xtask run-scenarios [--only NAME…] [--skip NAME…] [--out DIR] [--shard I/N]`: run
//! every scenario of `fixtures/scenarios/` (or the named ones, or shard I of N), each into
//! `DIR/NAME/`, then write `DIR/summary.json` and `DIR/summary.md` (scenario, wall time, key
//! metrics, expectations met, failures). A run of every scenario, or of every one but those
//! `--skip` names, also regenerates `docs/results.md` (the table and a gallery of the pictures,
//! copied to `docs/img/results/`); the skipped ones are listed there as not run, and their
//! earlier pictures are left as they were. Returns whether every scenario run ran to its end and
//! met its expectations.
//!
//! Shards: the scenarios sorted by name, shard I (1-based) of N takes every N-th from the I-th,
//! so a batch scheduler can spread a sweep over N machines and merge the summaries.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use atelier::report::Report;
use atelier::run::{RunOptions, base_of, run};
use atelier::scenario::Scenario;
use serde::Serialize;

pub mod ci;

/// One row of the summary.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    /// Scenario name (the file stem when the file could not be read).
    pub name: String,
    /// Scenario file, relative to the repository.
    pub file: String,
    /// Kind of scene.
    pub kind: String,
    /// Wall time of the whole run (setup, steps, outputs), s.
    pub wall_s: f64,
    /// Steps taken.
    pub steps: usize,
    /// Simulated time, s.
    pub simulated_s: f64,
    /// The key metrics in words.
    pub key_metrics: String,
    /// Every expectation met.
    pub expectations_met: bool,
    /// Unmet expectations in words.
    pub unmet: Vec<String>,
    /// Why the run failed or could not start.
    pub failure: Option<String>,
    /// How `cargo test` runs it: "in full", "shortened" or "–" (`fixtures/scenarios/CI.md`).
    pub in_ci: &'static str,
    /// The report, when the run produced one.
    #[serde(skip)]
    pub report: Option<Report>,
}

impl Row {
    /// Ran to its end and passed as `atelier run` judges it (`Report::passed`: every
    /// expectation met, every step converged unless the scenario bounds `unconverged_fraction`).
    pub(crate) fn passed(&self) -> bool {
        self.failure.is_none() && self.report.as_ref().is_some_and(Report::passed)
    }
}

/// The whole summary.
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    /// Scenarios run.
    pub scenarios: usize,
    /// Scenarios that passed ([`Row::passed`]: to their end, expectations met, steps converged).
    pub passed: usize,
    /// Shard run, `I/N`, if any.
    pub shard: Option<String>,
    /// Scenarios left out by `--skip` (not run, not counted).
    pub skipped: Vec<String>,
    /// Total wall time, s.
    pub wall_s: f64,
    /// One row per scenario.
    pub rows: Vec<Row>,
}

impl Summary {
    /// Every scenario run ran to its end and met its expectations.
    pub fn all_passed(&self) -> bool {
        self.passed == self.scenarios
    }

    /// The scenarios that did not run to their end (diverged or could not start).
    pub fn failed(&self) -> Vec<&str> {
        self.rows
            .iter()
            .filter(|r| r.failure.is_some())
            .map(|r| r.name.as_str())
            .collect()
    }
}

/// Parse `I/N` (1 ≤ I ≤ N).
pub fn parse_shard(text: &str) -> Result<(usize, usize)> {
    let (i, n) = text
        .split_once('/')
        .with_context(|| format!("--shard {text}: expected I/N, for example 2/4"))?;
    let (i, n): (usize, usize) = (
        i.trim().parse().context("--shard: I is not a number")?,
        n.trim().parse().context("--shard: N is not a number")?,
    );
    if n == 0 || i == 0 || i > n {
        bail!("--shard {text}: need 1 ≤ I ≤ N");
    }
    Ok((i, n))
}

/// Every scenario file, sorted by name.
pub(crate) fn scenario_files(root: &Path) -> Result<Vec<PathBuf>> {
    let dir = root.join("fixtures/scenarios");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .with_context(|| format!("cannot list {}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .collect();
    files.sort();
    Ok(files)
}

pub(crate) fn stem(p: &Path) -> String {
    p.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// Run the selection; returns its summary ([`Summary::all_passed`]).
pub fn run_all(
    root: &Path,
    only: &[String],
    skip: &[String],
    out: &Path,
    shard: Option<(usize, usize)>,
) -> Result<Summary> {
    let all = scenario_files(root)?;
    for (flag, names) in [("--only", only), ("--skip", skip)] {
        for name in names {
            if !all.iter().any(|f| stem(f) == *name) {
                bail!(
                    "{flag} {name}: no fixtures/scenarios/{name}.ron (have: {})",
                    all.iter().map(|f| stem(f)).collect::<Vec<_>>().join(", ")
                );
            }
        }
    }
    let selected: Vec<&PathBuf> = all
        .iter()
        .filter(|f| only.is_empty() || only.contains(&stem(f)))
        .filter(|f| !skip.contains(&stem(f)))
        .enumerate()
        .filter(|(k, _)| shard.is_none_or(|(i, n)| k % n == i - 1))
        .map(|(_, f)| f)
        .collect();
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    // The commit the results come from, read before this run writes into docs/.
    let revision = commit(root);
    let lists = ci::lists(root)?;
    let clock = Instant::now();
    let mut rows = Vec::new();
    for (k, file) in selected.iter().enumerate() {
        eprintln!("[{}/{}] {}", k + 1, selected.len(), stem(file));
        let mut row = run_one(root, file, out);
        row.in_ci = lists.in_ci(&stem(file));
        eprintln!("    {}", row_line(&row));
        rows.push(row);
    }
    let summary = Summary {
        scenarios: rows.len(),
        passed: rows.iter().filter(|r| r.passed()).count(),
        shard: shard.map(|(i, n)| format!("{i}/{n}")),
        skipped: skip.to_vec(),
        wall_s: clock.elapsed().as_secs_f64(),
        rows,
    };
    let json = serde_json::to_string_pretty(&summary)? + "\n";
    atelier_files::files::write_atomic(&out.join("summary.json"), json.as_bytes())?;
    atelier_files::files::write_atomic(
        &out.join("summary.md"),
        summary_markdown(&summary, None).as_bytes(),
    )?;
    eprintln!(
        "{} of {} scenarios passed; {} and {}",
        summary.passed,
        summary.scenarios,
        out.join("summary.json").display(),
        out.join("summary.md").display()
    );
    if only.is_empty() && shard.is_none() {
        write_results(root, out, &summary, &revision)?;
        eprintln!("regenerated docs/results.md");
    } else {
        eprintln!("docs/results.md left as it was (not every scenario ran)");
    }
    Ok(summary)
}

/// Run one scenario file into `out/NAME/`.
pub(crate) fn run_one(root: &Path, file: &Path, out: &Path) -> Row {
    match Scenario::load(file) {
        Ok(scenario) => run_scenario(blank_row(file, root), &scenario, file, out),
        Err(e) => Row {
            failure: Some(e.to_string()),
            ..blank_row(file, root)
        },
    }
}

/// The row of `file` before its run.
pub(crate) fn blank_row(file: &Path, root: &Path) -> Row {
    let rel = file
        .strip_prefix(root)
        .unwrap_or(file)
        .display()
        .to_string();
    Row {
        name: stem(file),
        file: rel,
        kind: String::new(),
        wall_s: 0.0,
        steps: 0,
        simulated_s: 0.0,
        key_metrics: String::new(),
        expectations_met: false,
        unmet: Vec::new(),
        failure: None,
        in_ci: "–",
        report: None,
    }
}

/// Run a scenario read from `file` (or derived from it: [`ci`]'s shortened forms) into
/// `out/NAME/`, filling in `row`.
pub(crate) fn run_scenario(mut row: Row, scenario: &Scenario, file: &Path, out: &Path) -> Row {
    row.name = scenario.name.clone();
    row.kind = scenario.kind.name().into();
    let clock = Instant::now();
    let result = run(
        scenario,
        Some(file),
        &base_of(file),
        &out.join(&scenario.name),
        &RunOptions::default(),
        &mut |_| {},
    );
    row.wall_s = clock.elapsed().as_secs_f64();
    match result {
        Ok(report) => {
            row.steps = report.steps;
            row.simulated_s = report.simulated_s;
            row.key_metrics = key_metrics(&report);
            row.expectations_met = report.expectations_met;
            row.unmet = report
                .expectations
                .iter()
                .filter(|e| !e.met)
                .map(|e| {
                    format!(
                        "{} = {} (want {})",
                        e.metric,
                        e.value.map_or("not measured".into(), number),
                        bound(e.min, e.max)
                    )
                })
                .collect();
            row.failure = report.failure.clone();
            row.report = Some(report);
        }
        Err(e) => row.failure = Some(e.to_string()),
    }
    row
}

/// A value in words: integers without decimals, others to four significant digits.
fn number(v: f64) -> String {
    if v.fract() == 0.0 && v.abs() < 1e15 {
        format!("{v:.0}")
    } else {
        format!("{v:.4e}")
            .parse::<f64>()
            .map_or(format!("{v}"), |r| format!("{r}"))
    }
}

fn bound(min: Option<f64>, max: Option<f64>) -> String {
    match (min, max) {
        (Some(a), Some(b)) => format!("{a} … {b}"),
        (Some(a), None) => format!("≥ {a}"),
        (None, Some(b)) => format!("≤ {b}"),
        (None, None) => "any".into(),
    }
}

/// The metrics that say most about each kind of scene, in words.
fn key_metrics(r: &Report) -> String {
    let m = |k: &str| r.metrics.get(k).copied().flatten();
    let f = |v: Option<f64>, digits: usize, unit: &str| {
        v.map_or("–".to_string(), |v| format!("{v:.digits$}{unit}"))
    };
    match r.scenario.kind.as_str() {
        "Garment" => {
            format!(
                "sewn {}/{} pairs{}, deepest inside body {}, final strain error {}",
                f(m("pairs_sewn"), 0, ""),
                f(m("pairs"), 0, ""),
                m("sewn_at_s").map_or(String::new(), |t| format!(" at {t:.2} s")),
                f(m("max_penetration_m").map(|v| v * 1e3), 1, " mm"),
                f(m("final_strain_error"), 3, ""),
            ) + &m("hem_width_m")
                .zip(m("hem_depth_m"))
                .map_or(String::new(), |(w, d)| {
                    format!(", hem {:.1} × {:.1} cm", w * 100.0, d * 100.0)
                })
        }
        "Drape" => format!(
            "DC {}, {} nodes, {}",
            f(m("drape_coefficient_percent"), 1, " %"),
            f(m("node_count"), 0, ""),
            if m("settled") == Some(1.0) {
                "at rest"
            } else {
                "not at rest"
            }
        ),
        "Cantilever" => format!(
            "chord angle {} (elastica 41.5°), c = {}",
            f(m("chord_angle_deg"), 2, "°"),
            f(m("bending_length_m").map(|v| v * 100.0), 2, " cm")
        ),
        "Catenary" => format!(
            "max deviation {} of the span",
            f(m("max_deviation_percent_span"), 3, " %")
        ),
        "KesTensile" => format!(
            "EMT {} ({}), LT {} ({}), RT {} ({})",
            f(m("emt_percent"), 3, " %"),
            f(m("input_emt_percent"), 3, " %"),
            f(m("lt"), 4, ""),
            f(m("input_lt"), 4, ""),
            f(m("rt_percent"), 2, " %"),
            f(m("input_rt_percent"), 2, " %"),
        ),
        "KesBending" => format!(
            "B {} ({}) gf·cm²/cm, 2HB {} ({}) gf·cm/cm",
            f(m("b_gf_cm2_cm"), 4, ""),
            f(m("input_b_gf_cm2_cm"), 4, ""),
            f(m("two_hb_gf_cm_cm"), 4, ""),
            f(m("input_two_hb_gf_cm_cm"), 4, ""),
        ),
        "Wet" => format!(
            "tent {}, lifted {}, {} fold(s), P_b − P_a {}{}",
            f(m("tent_height_mm"), 1, " mm"),
            f(m("lifted_area_cm2"), 0, " cm²"),
            f(m("folds"), 0, ""),
            f(m("pressure_difference_pa"), 1, " Pa"),
            match (m("compare_failed"), m("rms_difference_mm")) {
                (Some(f), _) if f > 0.0 => format!(
                    "; compared run stopped at {}",
                    m("compare_simulated_s").map_or("–".into(), |t| format!("{t:.3} s"))
                ),
                (Some(_), Some(rms)) => format!("; {rms:.2} mm RMS from the compared run"),
                _ => String::new(),
            }
        ),
        "StringFit" => format!(
            "J = {}: observed shapes reproduced to {} px (max {}), unobserved {} px, initial values {} px; {} iterations",
            f(m("observed_shapes"), 0, ""),
            f(m("mean_observed_error_px"), 2, ""),
            f(m("max_observed_error_px"), 2, ""),
            f(m("mean_unobserved_error_px"), 2, ""),
            f(m("initial_unobserved_error_px"), 1, ""),
            f(m("iterations"), 0, ""),
        ),
        _ => String::new(),
    }
}

fn row_line(r: &Row) -> String {
    let outcome = if let Some(f) = &r.failure {
        format!("FAILED: {f}")
    } else if !r.expectations_met {
        format!("EXPECTATION NOT MET: {}", r.unmet.join("; "))
    } else if !r.passed() {
        "NOT PASSED (unconverged steps or a doubtful try-on: see its report)".into()
    } else {
        "ok".into()
    };
    format!(
        "{:.1} s wall, {} steps, {:.2} s simulated; {}; {outcome}",
        r.wall_s, r.steps, r.simulated_s, r.key_metrics
    )
}

/// The summary as a markdown table; `pictures` (a folder relative to the document) adds a
/// gallery.
fn summary_markdown(s: &Summary, pictures: Option<&str>) -> String {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "{} of {} scenarios passed (ran to their end, met their expectations, every step \
         converged){}; {:.0} s wall in all.\n",
        s.passed,
        s.scenarios,
        s.shard
            .as_ref()
            .map_or(String::new(), |x| format!(" (shard {x})")),
        s.wall_s
    );
    if !s.skipped.is_empty() {
        let _ = writeln!(
            md,
            "Not run (left out with `--skip`; why: docs/validation.md): {}.\n",
            s.skipped
                .iter()
                .map(|n| format!("`{n}`"))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    let _ = writeln!(
        md,
        "The column \"in CI\" says how `cargo test` runs the scenario \
         (`fixtures/scenarios/CI.md`): in full, every expectation asserted; shortened, its time \
         cut and held to the expectations that mean the same at any time of a run; or not at all \
         (a known miss).\n"
    );
    let _ = writeln!(
        md,
        "| scenario | kind | wall s | steps | simulated s | key metrics | expectations | in CI | failure |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|");
    for r in &s.rows {
        let expectations = if r.unmet.is_empty() {
            if r.report.as_ref().is_some_and(|x| x.expectations.is_empty()) {
                "none".to_string()
            } else if r.report.is_some() && !r.passed() {
                "met, **not passed**: steps above the tolerance (its report's convergence)"
                    .to_string()
            } else if r.report.is_some() {
                "met".to_string()
            } else {
                "–".to_string()
            }
        } else {
            format!("**not met**: {}", r.unmet.join("; "))
        };
        let _ = writeln!(
            md,
            "| {} | {} | {:.1} | {} | {:.2} | {} | {} | {} | {} |",
            r.name,
            r.kind,
            r.wall_s,
            r.steps,
            r.simulated_s,
            r.key_metrics,
            expectations,
            r.in_ci,
            r.failure
                .as_deref()
                .map_or("–".to_string(), |f| f.replace('|', "\\|"))
        );
    }
    if let Some(dir) = pictures {
        let _ = writeln!(md, "\n## Gallery\n");
        for r in &s.rows {
            if r.report
                .as_ref()
                .is_some_and(|x| x.outputs.iter().any(|o| o == "final.png"))
            {
                let reproduces = r
                    .report
                    .as_ref()
                    .map(|x| x.scenario.reproduces.clone())
                    .unwrap_or_default();
                let top = if r
                    .report
                    .as_ref()
                    .is_some_and(|x| x.outputs.iter().any(|o| o == "top.png"))
                {
                    format!(" ![{} from above]({dir}/{}-top.png)", r.name, r.name)
                } else {
                    String::new()
                };
                let _ = writeln!(
                    md,
                    "### {}\n\n{}\n\n![{}]({dir}/{}.png){top}\n",
                    r.name, reproduces, r.name, r.name
                );
            }
        }
    }
    md
}

/// The repository's commit, marked when tracked files had uncommitted changes (the results
/// then come from code no commit holds).
pub(crate) fn commit(root: &Path) -> String {
    let git = |args: &[&str]| {
        std::process::Command::new("git")
            .args(args)
            .current_dir(root)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
    };
    match git(&["rev-parse", "--short", "HEAD"]) {
        Some(hash) => {
            let dirty = git(&["status", "--porcelain", "--untracked-files=no"])
                .is_some_and(|s| !s.is_empty());
            if dirty {
                format!("`{hash}` with uncommitted changes")
            } else {
                format!("`{hash}`")
            }
        }
        None => "unknown (not a git checkout)".into(),
    }
}

/// Regenerate `docs/results.md` and copy each scenario's picture to `docs/img/results/`.
fn write_results(root: &Path, out: &Path, s: &Summary, revision: &str) -> Result<()> {
    let img = root.join("docs/img/results");
    std::fs::create_dir_all(&img)?;
    for r in &s.rows {
        let from = out.join(&r.name).join("final.png");
        if r.report
            .as_ref()
            .is_some_and(|x| x.outputs.iter().any(|o| o == "final.png"))
        {
            let bytes =
                std::fs::read(&from).with_context(|| format!("cannot read {}", from.display()))?;
            atelier_files::files::write_atomic(&img.join(format!("{}.png", r.name)), &bytes)?;
        }
        if r.report
            .as_ref()
            .is_some_and(|x| x.outputs.iter().any(|o| o == "top.png"))
        {
            let from = out.join(&r.name).join("top.png");
            let bytes =
                std::fs::read(&from).with_context(|| format!("cannot read {}", from.display()))?;
            atelier_files::files::write_atomic(&img.join(format!("{}-top.png", r.name)), &bytes)?;
        }
    }
    let mut md = String::from(
        "# Results: every scenario\n\n\
         Generated by `cargo xtask run-scenarios` (do not edit by hand): every scenario of\n\
         `fixtures/scenarios/` run once on the 2-core machine, in release mode, one after the\n\
         other. Each row is the scenario's `report.json` (schema: [report.md](report.md)) in short;\n\
         a failed run still wrote its report and its outputs up to the last good frame, and its\n\
         picture below shows that frame. Wall times include loading, gridding and writing.\n\n",
    );
    let _ = writeln!(md, "Run at commit {revision}.\n");
    md.push_str(&summary_markdown(s, Some("img/results")));
    atelier_files::files::write_atomic(&root.join("docs/results.md"), md.as_bytes())?;
    Ok(())
}
