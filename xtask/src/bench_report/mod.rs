//! `cargo xtask bench-report`: run every criterion bench, the time-against-error studies, the
//! stability map, the peers and the benchmark scenarios, and regenerate `docs/performance.md`
//! from its template `xtask/performance.md.in`.
//!
//! Every step first removes its earlier output, so whatever the template refers to was produced
//! by this run (a step given to `--skip` reuses the output of an earlier run, for re-rendering
//! after a template edit). The report is written only when everything the template names is
//! there; otherwise the command fails listing what is missing and the old report stays.
//!
//! Template directives, each on a line of its own:
//! - `@@machine` — the machine: CPU, cores, caches, memory, OS, compiler, commit, date;
//! - `@@benches` … `@@end` — a table of criterion results, one bench per line as
//!   `group/function | what it times`: median and the 95 % confidence interval of the median,
//!   per element where the bench declares a throughput;
//! - `@@include PATH` — a markdown file from the run (`bench/…` = the benches' own tables in
//!   `$CARGO_TARGET_DIR/atelier-bench`, `figures/SET/…`, `scenarios/…`, `peers/…` in the output
//!   folder);
//! - `@@figure SET/NAME.png | caption` — copy a figure of the run into `docs/img/SET/` and show it;
//! - `@@peers SIDE` — the peers' table for the sheet of SIDE × SIDE nodes, all solvers;
//! - `@@peers-goal` — whether the goal is met, from the PARTY rows;
//! - `@@scenarios NAME=GOAL_S …` — the benchmark scenarios' wall times against their goals;
//!
//! and inline, anywhere: `{{bench:group/function}}` (a median) and `{{scaling-slope}}` (the
//! log–log slope of time per step against nodes, 2 threads, from 10 000 nodes).

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, Result, bail};
use serde::Deserialize;

use crate::figures::plot;

use peers::{peers_goal, peers_table};

mod peers;

/// The steps of the report.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Step {
    /// `cargo bench --workspace` (criterion benches and the benches' own tables).
    Benches,
    /// The figure sets the report shows (drape time against error, dress and walk, stability).
    Figures,
    /// The peers (`benches/peers/run.sh`: rapier-cloth and pypbd).
    Peers,
    /// The benchmark scenarios (`atelier run` of the dress, the walk, the drape, wet cloth).
    Scenarios,
}

/// The benchmark scenarios timed in the report. `dress_walk_self_collision` is not one since
/// session 15: on the converged step it did not finish in 45 minutes (docs/validation.md), more
/// than the whole report; `garment/step_walking_self_collision` times its step.
const SCENARIOS: [&str; 5] = [
    "default",
    "dress_sewn",
    "dress_walk",
    "drape_jis_cotton_broad",
    "wet_pinch1_air400",
];

/// The figure sets the report shows.
const FIGURE_SETS: [&str; 3] = ["solver", "stability", "tradeoff"];

/// Run the steps not skipped and render the report.
pub fn run(root: &Path, out: &Path, skip: &[Step]) -> Result<()> {
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("target"));
    std::fs::create_dir_all(out)?;
    let clock = std::time::Instant::now();
    if !skip.contains(&Step::Benches) {
        for dir in ["criterion", "atelier-bench"] {
            remove_dir(&target.join(dir))?;
        }
        eprintln!("bench-report: cargo bench --workspace (criterion, about 70 minutes)");
        let status = Command::new(env_or("CARGO", "cargo"))
            // No criterion plots: its plotting backend needs a system font this machine may
            // lack (it panics without one), and the report reads the numbers, not the plots.
            .args(["bench", "--workspace", "--bench", "*", "--", "--noplot"])
            .current_dir(root)
            .status()
            .context("starting cargo bench")?;
        if !status.success() {
            bail!("cargo bench --workspace failed ({status})");
        }
    }
    if !skip.contains(&Step::Figures) {
        plot::register_font()?;
        for set in FIGURE_SETS {
            let dir = out.join("figures").join(set);
            remove_dir(&dir)?;
            std::fs::create_dir_all(&dir)?;
            eprintln!("bench-report: figures {set}");
            let draw: crate::DrawAll = match set {
                "solver" => crate::figures::solver::draw_all,
                "stability" => crate::figures::stability::draw_all,
                _ => crate::figures::tradeoff::draw_all,
            };
            draw(root, &dir)?;
        }
    }
    if !skip.contains(&Step::Peers) {
        let dir = out.join("peers");
        remove_dir(&dir)?;
        std::fs::create_dir_all(&dir)?;
        eprintln!("bench-report: the peers (benches/peers/run.sh)");
        let status = Command::new("sh")
            .arg(root.join("benches/peers/run.sh"))
            .arg(&dir)
            .current_dir(root)
            .status()
            .context("starting benches/peers/run.sh")?;
        if !status.success() {
            bail!("benches/peers/run.sh failed ({status})");
        }
    }
    if !skip.contains(&Step::Scenarios) {
        let dir = out.join("scenarios");
        remove_dir(&dir)?;
        eprintln!("bench-report: the benchmark scenarios");
        let only: Vec<String> = SCENARIOS.iter().map(|s| s.to_string()).collect();
        // A missed expectation does not make a wall time wrong (the table shows the goals and
        // the metrics); a run that did not reach its end does.
        let summary = crate::run_scenarios::run_all(root, &only, &[], &dir, None)?;
        let failed = summary.failed();
        if !failed.is_empty() {
            bail!(
                "benchmark scenarios did not run to their end: {}",
                failed.join(", ")
            );
        }
    }
    let sources = Sources {
        root: root.to_path_buf(),
        bench: target.join("atelier-bench"),
        criterion: criterion_index(&target.join("criterion")),
        out: out.to_path_buf(),
    };
    let template = root.join("xtask/performance.md.in");
    let text = std::fs::read_to_string(&template)
        .with_context(|| format!("reading {}", template.display()))?;
    let (rendered, figures) = render(&text, &sources)?;
    publish(&figures)?;
    atelier_files::files::write_atomic(&root.join("docs/performance.md"), rendered.as_bytes())?;
    eprintln!(
        "bench-report: wrote docs/performance.md ({:.0} s)",
        clock.elapsed().as_secs_f64()
    );
    Ok(())
}

fn env_or(var: &str, default: &str) -> std::ffi::OsString {
    std::env::var_os(var).unwrap_or_else(|| default.into())
}

fn remove_dir(dir: &Path) -> Result<()> {
    match std::fs::remove_dir_all(dir) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(e).with_context(|| format!("removing {}", dir.display())),
    }
}

/// Where the run's outputs are.
struct Sources {
    root: PathBuf,
    bench: PathBuf,
    /// Criterion's results by full id (`group/function[/value]`): the folder holding
    /// `estimates.json` and `benchmark.json` (criterion rewrites `/` in group names).
    criterion: BTreeMap<String, PathBuf>,
    out: PathBuf,
}

/// Every `new/benchmark.json` under criterion's folder, by its `full_id`.
fn criterion_index(dir: &Path) -> BTreeMap<String, PathBuf> {
    #[derive(Deserialize)]
    struct Id {
        full_id: String,
    }
    let mut index = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for entry in entries.flatten() {
            let path = entry.path();
            if path.is_dir() {
                if path.file_name().is_some_and(|n| n == "new") {
                    let id = std::fs::read_to_string(path.join("benchmark.json"))
                        .ok()
                        .and_then(|t| serde_json::from_str::<Id>(&t).ok());
                    if let Some(id) = id {
                        index.insert(id.full_id, path);
                    }
                } else {
                    stack.push(path);
                }
            }
        }
    }
    index
}

impl Sources {
    fn path(&self, rel: &str) -> PathBuf {
        match rel.strip_prefix("bench/") {
            Some(rest) => self.bench.join(rest),
            None => self.out.join(rel),
        }
    }
}

/// Render the template; every missing input is collected and reported together.
fn render(template: &str, src: &Sources) -> Result<(String, Vec<(PathBuf, PathBuf)>)> {
    let mut out = String::new();
    let mut figures = Vec::new();
    let mut missing = Vec::new();
    let mut lines = template.lines().enumerate();
    while let Some((n, line)) = lines.next() {
        let at = |what: String| format!("xtask/performance.md.in:{}: {what}", n + 1);
        let Some(directive) = line.strip_prefix("@@") else {
            match inline(line, src) {
                Ok(l) => out.push_str(&l),
                Err(e) => {
                    missing.push(at(e.to_string()));
                    out.push_str(line);
                }
            }
            out.push('\n');
            continue;
        };
        let (name, arg) = directive
            .split_once(' ')
            .map_or((directive, ""), |(a, b)| (a, b.trim()));
        let result = match name {
            "machine" => Ok(machine(&src.root)),
            "benches" => {
                let mut rows = Vec::new();
                for (_, l) in lines.by_ref() {
                    if l.trim() == "@@end" {
                        break;
                    }
                    rows.push(l.to_string());
                }
                bench_table(&rows, &src.criterion)
            }
            "include" => std::fs::read_to_string(src.path(arg))
                .map(|t| t.trim_end().to_string())
                .map_err(|e| anyhow::anyhow!("{arg}: {e}")),
            "figure" => figure(arg, src, &mut figures),
            "peers" => peers_table(arg, src, &mut figures),
            "peers-goal" => peers_goal(src),
            "scenarios" => scenarios_table(arg, src),
            other => Err(anyhow::anyhow!("unknown directive @@{other}")),
        };
        match result {
            Ok(text) => {
                out.push_str(&text);
                out.push('\n');
            }
            Err(e) => missing.push(at(format!("{e:#}"))),
        }
    }
    if !missing.is_empty() {
        bail!(
            "the report was not written; missing or unreadable:\n  {}",
            missing.join("\n  ")
        );
    }
    Ok((out, figures))
}

/// Replace `{{…}}` placeholders in a line.
fn inline(line: &str, src: &Sources) -> Result<String> {
    let mut out = String::new();
    let mut rest = line;
    while let Some(start) = rest.find("{{") {
        out.push_str(&rest[..start]);
        let end = rest[start..]
            .find("}}")
            .map(|e| start + e)
            .context("unclosed {{")?;
        let key = &rest[start + 2..end];
        let value = if let Some(id) = key.strip_prefix("bench:") {
            let e = estimate(&src.criterion, id)?;
            duration(e.median)
        } else if key == "scaling-slope" {
            format!("{:.2}", scaling_slope(&src.bench.join("scaling.md"))?)
        } else {
            bail!("unknown placeholder {{{{{key}}}}}");
        };
        out.push_str(&value);
        rest = &rest[end + 2..];
    }
    out.push_str(rest);
    Ok(out)
}

/// The machine the report was measured on.
fn machine(root: &Path) -> String {
    let read = |p: &str| std::fs::read_to_string(p).unwrap_or_default();
    let cpuinfo = read("/proc/cpuinfo");
    let field = |name: &str| {
        cpuinfo
            .lines()
            .find(|l| l.starts_with(name))
            .and_then(|l| l.split_once(':'))
            .map(|(_, v)| v.trim().to_string())
            .unwrap_or_else(|| "unknown".into())
    };
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    let memory = read("/proc/meminfo")
        .lines()
        .find(|l| l.starts_with("MemTotal:"))
        .and_then(|l| l.split_whitespace().nth(1)?.parse::<f64>().ok())
        .map_or("unknown".into(), |kb| {
            format!("{:.1} GiB", kb / 1024.0 / 1024.0)
        });
    let mut caches = Vec::new();
    for k in 0..8 {
        let base = format!("/sys/devices/system/cpu/cpu0/cache/index{k}");
        let (level, kind, size) = (
            read(&format!("{base}/level")),
            read(&format!("{base}/type")),
            read(&format!("{base}/size")),
        );
        if level.is_empty() {
            break;
        }
        if kind.trim() != "Instruction" {
            caches.push(format!("L{} {}", level.trim(), size.trim()));
        }
    }
    let command = |program: &str, args: &[&str]| {
        Command::new(program)
            .args(args)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
            .unwrap_or_else(|| "unknown".into())
    };
    format!(
        "| | |\n|---|---|\n| CPU | {} ({} logical cores available to this process; {} per package) |\n| caches (per core unless shared) | {} |\n| memory | {} |\n| system | {} |\n| compiler | {} (bench profile: opt-level 3) |\n| commit | {} |\n| date | {} |",
        field("model name"),
        cores,
        field("siblings"),
        if caches.is_empty() {
            "unknown".into()
        } else {
            caches.join(", ")
        },
        memory,
        command("uname", &["-sr"]),
        command("rustc", &["-V"]),
        crate::run_scenarios::commit(root),
        command("date", &["-u", "+%Y-%m-%d %H:%M UTC"]),
    )
}

#[derive(Deserialize)]
struct Interval {
    lower_bound: f64,
    upper_bound: f64,
}

#[derive(Deserialize)]
struct Statistic {
    point_estimate: f64,
    confidence_interval: Interval,
}

#[derive(Deserialize)]
struct Estimates {
    median: Statistic,
}

#[derive(Deserialize)]
struct Benchmark {
    throughput: Option<BTreeMap<String, u64>>,
}

/// A criterion result: the median of one iteration and its 95 % interval, in seconds, and the
/// elements an iteration processes where the bench declares a throughput.
struct Estimate {
    median: f64,
    low: f64,
    high: f64,
    per: Option<u64>,
}

fn estimate(criterion: &BTreeMap<String, PathBuf>, id: &str) -> Result<Estimate> {
    let dir = criterion
        .get(id)
        .with_context(|| format!("no criterion result {id}"))?;
    let read = |name: &str| {
        std::fs::read_to_string(dir.join(name))
            .with_context(|| format!("criterion result {id} ({})", dir.join(name).display()))
    };
    let e: Estimates = serde_json::from_str(&read("estimates.json")?)?;
    let b: Benchmark = serde_json::from_str(&read("benchmark.json")?)?;
    let per = b.throughput.and_then(|t| t.values().next().copied());
    Ok(Estimate {
        median: e.median.point_estimate * 1e-9,
        low: e.median.confidence_interval.lower_bound * 1e-9,
        high: e.median.confidence_interval.upper_bound * 1e-9,
        per,
    })
}

/// A duration in seconds with three significant digits and a fitting unit.
fn duration(s: f64) -> String {
    let (v, unit) = if s >= 1.0 {
        (s, "s")
    } else if s >= 1e-3 {
        (s * 1e3, "ms")
    } else if s >= 1e-6 {
        (s * 1e6, "µs")
    } else {
        (s * 1e9, "ns")
    };
    let digits = if v >= 100.0 {
        0
    } else if v >= 10.0 {
        1
    } else {
        2
    };
    format!("{v:.digits$} {unit}")
}

fn bench_table(rows: &[String], criterion: &BTreeMap<String, PathBuf>) -> Result<String> {
    let mut t = String::from(
        "| bench | what | median | 95 % interval of the median |\n|---|---|---|---|\n",
    );
    let mut errors = Vec::new();
    for row in rows.iter().filter(|r| !r.trim().is_empty()) {
        let (id, what) = row.split_once('|').unwrap_or((row, ""));
        let id = id.trim();
        match estimate(criterion, id) {
            Ok(e) => {
                let per = e.per.map_or(String::new(), |n| {
                    format!(
                        " — {} per element, {n} per iteration",
                        duration(e.median / n as f64)
                    )
                });
                let _ = writeln!(
                    t,
                    "| `{id}` | {}{per} | {} | {} – {} |",
                    what.trim(),
                    duration(e.median),
                    duration(e.low),
                    duration(e.high)
                );
            }
            Err(_) => errors.push(id.to_string()),
        }
    }
    if !errors.is_empty() {
        bail!("no criterion result for {}", errors.join(", "));
    }
    Ok(t.trim_end().to_string())
}

/// A figure of the run to show: checked now, copied into `docs/img/SET/` by [`publish`] once
/// the whole report rendered; returns its markdown.
fn figure(arg: &str, src: &Sources, figures: &mut Vec<(PathBuf, PathBuf)>) -> Result<String> {
    let (rel, caption) = arg.split_once('|').unwrap_or((arg, ""));
    let rel = rel.trim();
    let from = src.out.join("figures").join(rel);
    if !from.is_file() {
        bail!("figure {} missing", from.display());
    }
    figures.push((from, src.root.join("docs/img").join(rel)));
    Ok(format!("![{}](img/{rel})", caption.trim()))
}

/// Copy the report's figures into `docs/img/` (each atomically).
fn publish(figures: &[(PathBuf, PathBuf)]) -> Result<()> {
    for (from, to) in figures {
        let bytes = std::fs::read(from).with_context(|| format!("figure {}", from.display()))?;
        if let Some(dir) = to.parent() {
            std::fs::create_dir_all(dir)?;
        }
        atelier_files::files::write_atomic(to, &bytes)?;
    }
    Ok(())
}

/// The log–log slope of the 2-thread time per step against nodes, from 10 000 nodes, read
/// from the scaling table (columns: nodes, edges, 1 thread, 2 threads, …).
fn scaling_slope(path: &Path) -> Result<f64> {
    let text = std::fs::read_to_string(path).with_context(|| path.display().to_string())?;
    let number = |s: &str| s.trim().replace([' ', ' '], "").parse::<f64>().ok();
    let points: Vec<(f64, f64)> = text
        .lines()
        .filter_map(|l| {
            let cells: Vec<&str> = l.trim_matches('|').split('|').collect();
            Some((number(cells.first()?)?, number(cells.get(3)?)?))
        })
        .filter(|&(n, _)| n >= 10_000.0)
        .map(|(n, t)| (n.ln(), t.ln()))
        .collect();
    if points.len() < 2 {
        bail!("{}: fewer than two sizes from 10 000 nodes", path.display());
    }
    let m = points.len() as f64;
    let (sx, sy) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x, b + y));
    let (mx, my) = (sx / m, sy / m);
    let (sxy, sxx) = points.iter().fold((0.0, 0.0), |(a, b), (x, y)| {
        (a + (x - mx) * (y - my), b + (x - mx) * (x - mx))
    });
    Ok(sxy / sxx)
}

#[derive(Deserialize)]
struct Summary {
    rows: Vec<ScenarioRow>,
}

#[derive(Deserialize)]
struct ScenarioRow {
    name: String,
    wall_s: f64,
    steps: usize,
    simulated_s: f64,
    key_metrics: String,
    expectations_met: bool,
}

/// The benchmark scenarios against their goals (`NAME=GOAL_S`, or `NAME` for none).
fn scenarios_table(arg: &str, src: &Sources) -> Result<String> {
    let path = src.out.join("scenarios/summary.json");
    let text = std::fs::read_to_string(&path).with_context(|| path.display().to_string())?;
    let summary: Summary = serde_json::from_str(&text)?;
    let mut t = String::from(
        "| scenario | simulated | steps | wall (setup, steps, outputs) | goal | key numbers |\n|---|---|---|---|---|---|\n",
    );
    for item in arg.split_whitespace() {
        let (name, goal) = item
            .split_once('=')
            .map_or((item, None), |(n, g)| (n, Some(g)));
        let row = summary
            .rows
            .iter()
            .find(|r| r.name == name)
            .with_context(|| format!("scenario {name} not in {}", path.display()))?;
        let goal = match goal {
            Some(g) => {
                let g: f64 = g.parse().with_context(|| format!("goal of {name}"))?;
                format!(
                    "≤ {g} s: {}",
                    if row.wall_s <= g {
                        "met"
                    } else {
                        "**not met**"
                    }
                )
            }
            None => "—".into(),
        };
        let _ = writeln!(
            t,
            "| `{}` | {:.2} s | {} | {:.2} s | {goal} | {}{} |",
            row.name,
            row.simulated_s,
            row.steps,
            row.wall_s,
            row.key_metrics,
            if row.expectations_met {
                ""
            } else {
                " (expectations missed)"
            }
        );
    }
    Ok(t.trim_end().to_string())
}

#[cfg(test)]
mod tests;
