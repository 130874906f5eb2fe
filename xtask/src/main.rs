//! Project automation for atelier: `cargo xtask <command>`.
//!
//! - `cargo xtask figures fabric [--out DIR]` — the fabric-model figures (tensile minor loops,
//!   bending loop, polar plots of the orthotropic interpolation), PNG, written atomically.
//! - `cargo xtask figures solver [--out DIR]` — time against error of the PARTY step and the
//!   baselines on the thesis's drape (PNG and a markdown table, also printed to stdout).
//! - `cargo xtask figures grid [--out DIR]` — the gridding figures: pattern grids before and after
//!   improvement, energy, quality histograms, the dress panels with seams, the body from range
//!   images coloured by part and its error image.
//! - `cargo xtask figures body [--out DIR]` — the mannequin at rest and walking (front and side),
//!   the arm raise, and its range images with landmarks.
//! - `cargo xtask figures wet [--out DIR]` — Yamada's wet-cloth model against the PARTY step:
//!   the thesis's timing table re-measured, the largest stable Δt, the shape difference.
//! - `cargo xtask figures stability [--out DIR]` — the stability map: per solver, Δt × fabric ×
//!   speed of the held edge → stable / error / non-finite (`stability.md`, `stability.png`).
//! - `cargo xtask figures tradeoff [--out DIR]` — time against error for the sewn dress and the
//!   walk: PARTY's accuracy knobs swept, XPBD and mass-spring, against a tight PARTY reference
//!   (`tradeoff_dress.{md,png}`, `tradeoff_walk.{md,png}`, about 8 minutes).
//! - `cargo xtask figures tryon [--out DIR]` — the virtual try-on on the synthetic photographs
//!   (photograph, fitted silhouette, composite; `tryon.md` with overlaps, errors and times).
//! - `cargo xtask figures dress [--out DIR]` — the sewn dress in silk, cotton broad and denim at
//!   rest, with and without bending hysteresis, side by side, and its hems' extents.
//! - `cargo xtask figures fit [--out DIR]` — the string-identification experiments on the
//!   synthetic objects: Table 1, Fig. 11, Table 3 and the reproduced shapes.
//! - `cargo xtask bench-report [--out DIR] [--skip STEP…]` — every criterion bench, the
//!   time-against-error studies, the stability map, the peers and the benchmark scenarios, then
//!   `docs/performance.md` regenerated from `xtask/performance.md.in`. On the converged step this
//!   takes well over two hours on 2 cores (session 15: the criterion benches 70 min, the
//!   stability map 9 min, the time-against-error study of the dress over 30 min unfinished — its
//!   two references alone 8 and 11 min).
//! - `cargo xtask knob-table [--check]` — the table of `StepParams`' knobs in `docs/solver.md`
//!   regenerated from `StepParams::default()` and the doc comments of `params.rs`; `--check`
//!   fails if the file is out of date (so does `cargo test --workspace`).
//! - `cargo xtask check-layout` — no import cycle between the top-level modules of any crate,
//!   no source file over 800 lines without a `//! Length:` line saying why (the same check is a
//!   test, so `cargo test --workspace` runs it).
//! - `cargo xtask run-scenarios [--only NAME…] [--skip NAME…] [--out DIR] [--shard I/N]` —
//!   every scenario of `fixtures/scenarios/` (or some), `summary.json` and `summary.md`, and on
//!   a full run (or one with only `--skip`) `docs/results.md` with its gallery; fails if a
//!   scenario fails or misses an expectation.
//! - `cargo xtask long-tests [--list]` — the tests marked `#[ignore = "long: …"]`, kept out of
//!   `cargo test` for CI's 30-minute budget, found in the sources and run (`long_tests`).

mod bench_report;
mod figures;
mod knob_table;
mod layout;
mod long_tests;
mod run_scenarios;

use std::path::{Path, PathBuf};

use anyhow::Result;
use clap::{Parser, Subcommand, ValueEnum};

#[derive(Parser)]
#[command(name = "xtask", about = "atelier project automation")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Draw the figures of a model.
    Figures {
        /// Which set of figures.
        which: FigureSet,
        /// Output folder (created if missing); default `figures/<set>` in the repository.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Run the scenarios of fixtures/scenarios/: summary.json and summary.md in the output
    /// folder; a full run regenerates docs/results.md. Fails if a scenario fails or misses an
    /// expectation.
    RunScenarios {
        /// Run only these scenarios (file names without `.ron`).
        #[arg(long, num_args = 1..)]
        only: Vec<String>,
        /// Leave these scenarios out (file names without `.ron`); a run of every other one still
        /// regenerates docs/results.md, listing these as not run.
        #[arg(long, num_args = 1..)]
        skip: Vec<String>,
        /// Output folder (created if missing); default `target/scenarios` in the repository.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Run shard I of N (1-based): every N-th scenario by name from the I-th.
        #[arg(long, value_name = "I/N")]
        shard: Option<String>,
    },
    /// Run the benches, figures, peers and benchmark scenarios and regenerate
    /// docs/performance.md from xtask/performance.md.in (over two hours on 2 cores).
    BenchReport {
        /// Output folder for the run's figures, peers and scenarios (created if missing);
        /// default `target/bench-report` in the repository.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Reuse an earlier run's output of these steps instead of running them.
        #[arg(long, num_args = 1..)]
        skip: Vec<bench_report::Step>,
    },
    /// Regenerate the table of the step's knobs in docs/solver.md from `StepParams::default()`
    /// and the doc comments of crates/solver/src/params.rs.
    KnobTable {
        /// Write nothing; fail if docs/solver.md differs from what would be written.
        #[arg(long)]
        check: bool,
    },
    /// Check the layout rules: no import cycle between a crate's modules, no source file over
    /// 800 lines without a `//! Length:` line saying why (also run by `cargo test`).
    CheckLayout,
    /// Run the tests marked `#[ignore = "long: …"]`, which `cargo test` skips for CI's time
    /// budget (found in the sources; about half an hour on 2 cores).
    LongTests {
        /// Only list them, with their files and reasons.
        #[arg(long)]
        list: bool,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum FigureSet {
    /// Tensile and bending hysteresis, orthotropic interpolation.
    Fabric,
    /// Time against error of the PARTY step and the baselines (takes a few minutes).
    Solver,
    /// Pattern grids before and after improvement, quality histograms, the dress panels, the
    /// body from range images.
    Grid,
    /// The mannequin at rest, walking and raising its arms; its range images.
    Body,
    /// Wet cloth: Yamada's model against the PARTY step — timing table, largest stable Δt,
    /// shape difference (takes a few minutes).
    Wet,
    /// String identification (Sudoh et al.) on the synthetic objects: Table 1, Fig. 11,
    /// Table 3 (about a minute).
    Fit,
    /// The stability map: Δt × fabric × body speed per solver (a few minutes).
    Stability,
    /// Time against error for the sewn dress and the walk: PARTY's knobs swept, XPBD and
    /// mass-spring, against a tight PARTY reference (about 8 minutes).
    Tradeoff,
    /// The sewn dress in silk, cotton broad and denim at rest, with and without bending
    /// hysteresis: pictures side by side and the hems' extents (about 10 minutes).
    Dress,
    /// Virtual try-on on the synthetic photographs: photograph, fit, composite; the frontal
    /// ambiguity; a segmented photograph (about a minute).
    Tryon,
}

/// A figure set's entry point: draw everything from the repository root into a folder, return
/// the files written.
type DrawAll = fn(&Path, &Path) -> Result<Vec<PathBuf>>;

fn repository_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn main() -> Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Command::Figures { which, out } => {
            let (name, draw_all): (&str, DrawAll) = match which {
                FigureSet::Fabric => ("fabric", figures::fabric::draw_all),
                FigureSet::Solver => ("solver", figures::solver::draw_all),
                FigureSet::Grid => ("grid", figures::grid::draw_all),
                FigureSet::Body => ("body", figures::body::draw_all),
                FigureSet::Wet => ("wet", figures::wet::draw_all),
                FigureSet::Fit => ("fit", figures::fit::draw_all),
                FigureSet::Stability => ("stability", figures::stability::draw_all),
                FigureSet::Tradeoff => ("tradeoff", figures::tradeoff::draw_all),
                FigureSet::Tryon => ("tryon", figures::tryon::draw_all),
                FigureSet::Dress => ("dress", figures::dress::draw_all),
            };
            let out = out.unwrap_or_else(|| repository_root().join("figures").join(name));
            std::fs::create_dir_all(&out)?;
            figures::plot::register_font()?;
            for written in draw_all(&repository_root(), &out)? {
                eprintln!("wrote {}", written.display());
            }
        }
        Command::RunScenarios {
            only,
            skip,
            out,
            shard,
        } => {
            let shard = shard
                .as_deref()
                .map(run_scenarios::parse_shard)
                .transpose()?;
            let root = repository_root();
            let out = out.unwrap_or_else(|| root.join("target/scenarios"));
            if !run_scenarios::run_all(&root, &only, &skip, &out, shard)?.all_passed() {
                eprintln!("some scenarios failed or missed an expectation (see above)");
                std::process::exit(1);
            }
        }
        Command::BenchReport { out, skip } => {
            let root = repository_root();
            let out = out.unwrap_or_else(|| root.join("target/bench-report"));
            bench_report::run(&root, &out, &skip)?;
        }
        Command::KnobTable { check } => {
            if !knob_table::run(&repository_root(), check)? {
                eprintln!(
                    "docs/solver.md's knob table is out of date: run `cargo xtask knob-table`"
                );
                std::process::exit(1);
            }
        }
        Command::CheckLayout => layout::main(&repository_root())?,
        Command::LongTests { list } => {
            if !long_tests::run(&repository_root(), list)? {
                eprintln!("a long test failed (see above)");
                std::process::exit(1);
            }
        }
    }
    Ok(())
}
