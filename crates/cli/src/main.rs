//! The `atelier` command-line program.
//!
//! - `atelier` (no arguments): run the built-in default scenario — the dress sewn on
//!   the 9AR mannequin, then a short walk — into `./atelier-out`.
//! - `atelier run SCENARIO.ron --out DIR [--threads N] [--frames K]`: run a scenario file.
//! - `atelier validate FILE…`: check data files.
//! - `atelier pattern FILE.dxf|FILE.svg --out DIR [--cell CM]`: pattern pieces from pattern software or
//!   apparel CAD as atelier patterns, grids and a picture.
//! - `atelier view DIR [--serve [PORT]]`: a finished run folder as a web page (3-D, time slider,
//!   the report), opened from the files or served on 127.0.0.1.
//! - `atelier tryon --photo P.png [--mask M.png] --garment G.ron [--pose S.ron] --out DIR`:
//!   virtual try-on from one photograph.
//!
//! Exit status: 0 success; 1 the run could not start or its outputs could not be written (bad
//! command line, bad file, missing file, unwritable folder); 2 the run ended early (diverged)
//! or an expectation was not met — its report and outputs are written all the same. Errors are
//! one line on stderr, never a backtrace.

mod validate;
mod view;

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use atelier::export::FrameSelection;
use atelier::run::{RunOptions, base_of, run};
use atelier::scenario::Scenario;
use clap::{Parser, Subcommand};

/// The built-in default scenario (`fixtures/scenarios/default.ron`), embedded at build time.
const DEFAULT_SCENARIO: &str = include_str!("../../../fixtures/scenarios/default.ron");

/// The folder the default scenario's relative paths are resolved against: the repository's
/// `fixtures/scenarios`, found through the crate's source location at build time (the garment,
/// fabric and motion files it names are read from the repository at run time).
const DEFAULT_BASE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/scenarios");

#[derive(Parser)]
#[command(
    name = "atelier",
    version,
    about = "Garments from measured fabric mechanics",
    long_about = "Garments from measured fabric mechanics.\n\nWith no command, runs the built-in default scenario (the dress sewn on the 9AR mannequin, then a short walk) into ./atelier-out."
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scenario file: report.json, final.obj, final.ply, run.glb and final.png in DIR.
    Run {
        /// Scenario file (RON).
        scenario: PathBuf,
        /// Output folder (created if missing).
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
        #[command(flatten)]
        options: Options,
    },
    /// Fit a fabric's bending rigidity per direction to observed cantilever profiles
    /// (`ClothObservations` RON, docs/fit.md): writes fabric.ron and fit_report.json in DIR.
    Fit {
        /// Observation file (RON).
        observations: PathBuf,
        /// Output folder (created if missing).
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
    },
    /// Virtual try-on: pose the mannequin to a photograph's silhouette, dress it with a garment
    /// scenario, move it to the pose and draw the garment over the photograph (docs/tryon.md):
    /// composite.png, overlay.png, fitted_pose.ron and the run's outputs and report.json in DIR.
    Tryon {
        /// The photograph (PNG, 8 bits per sample).
        #[arg(long, value_name = "PHOTO.png")]
        photo: PathBuf,
        /// The person's mask (PNG, white on black, the photograph's size); without it the
        /// photograph's plain background is segmented.
        #[arg(long, value_name = "MASK.png")]
        mask: Option<PathBuf>,
        /// The garment: a scenario file of kind Garment.
        #[arg(long, value_name = "GARMENT.ron")]
        garment: PathBuf,
        /// A start pose (RON: joints, optionally camera and sizes); default the standard pose.
        #[arg(long, value_name = "START.ron")]
        pose: Option<PathBuf>,
        /// The camera's direction round the vertical, degrees (0 from the front, 90 from the
        /// body's left), or `search` when it is not known (the fit is run over directions from
        /// −90° to 90° and the best overlap kept; about 13 fits).
        #[arg(
            long,
            value_name = "DEG|search",
            default_value = "0",
            value_parser = parse_yaw,
            allow_negative_numbers = true
        )]
        yaw: Yaw,
        /// The person's height, cm (default: the body description's).
        #[arg(long, value_name = "CM")]
        height: Option<f64>,
        /// Direction towards the light in the body frame, `x,y,z` (x the body's left, y up, z
        /// forward).
        #[arg(long, value_name = "X,Y,Z", value_parser = parse_light, allow_hyphen_values = true)]
        light: Option<[f64; 3]>,
        /// Output folder (created if missing).
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
        #[command(flatten)]
        options: Options,
    },
    /// Read a pattern file from pattern software or apparel CAD (DXF-AAMA / ASTM D6673, FreeSewing
    /// SVG): print
    /// one line per piece (size, area, grain angle, notches, darts, teams, grid) and write each
    /// piece as an atelier pattern (NAME.ron) and its grid (NAME.obj), and pieces.png, in DIR.
    Pattern {
        /// The pattern file: DXF-AAMA (.dxf) or FreeSewing SVG (.svg).
        file: PathBuf,
        /// Output folder (created if missing).
        #[arg(long)]
        out: PathBuf,
        /// Target grid cell size, cm.
        #[arg(long, default_value_t = 2.0)]
        cell: f64,
    },
    /// Write DIR/index.html (and its assets, and viewer-data.js with the run) for a finished run
    /// folder: the run in 3-D with a time slider, and its report (docs/viewer.md). Open the page
    /// from the disk, or give --serve to serve the folder on 127.0.0.1.
    View {
        /// The run folder (what `atelier run --out DIR` wrote).
        dir: PathBuf,
        /// Serve the folder on 127.0.0.1 at PORT (default 8000; 0 picks a free port) and print
        /// the address; runs until stopped (Ctrl-C).
        #[arg(long, value_name = "PORT", num_args = 0..=1, default_missing_value = "8000")]
        serve: Option<u16>,
    },
    /// Check fabric, pattern, garment, body, motion, range side, scenario and try-on pose files (RON) and
    /// body meshes (OBJ, PLY); print each problem with file:line:column and field.
    Validate {
        /// Files to check.
        #[arg(required = true)]
        files: Vec<PathBuf>,
    },
}

#[derive(clap::Args, Clone, Copy)]
struct Options {
    /// Worker threads of the parallel stages (default: one per core).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..))]
    threads: Option<u16>,
    /// Keep at most K frames in run.glb (K ≥ 2; default: every recorded frame).
    #[arg(long, value_name = "K", value_parser = clap::value_parser!(u32).range(2..))]
    frames: Option<u32>,
}

fn main() -> ExitCode {
    // A command line clap refuses exits with 1, as every run that cannot start does (clap's own
    // code, 2, is atelier's "ran but failed"); help and version print and exit with 0.
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            let _ = e.print();
            return if e.use_stderr() {
                ExitCode::FAILURE
            } else {
                ExitCode::SUCCESS
            };
        }
    };
    match cli.command {
        None => {
            let base = PathBuf::from(DEFAULT_BASE);
            if !base.is_dir() {
                eprintln!(
                    "atelier: the default scenario's fixtures are not at {} (the program was moved away from its source tree); run `atelier run SCENARIO.ron --out DIR` instead",
                    base.display()
                );
                return ExitCode::FAILURE;
            }
            let scenario =
                match Scenario::parse(DEFAULT_SCENARIO, Path::new("<built-in default.ron>")) {
                    Ok(s) => s,
                    Err(e) => {
                        eprintln!("atelier: {e}");
                        return ExitCode::FAILURE;
                    }
                };
            let options = Options {
                threads: None,
                frames: None,
            };
            run_scenario(&scenario, None, &base, Path::new("atelier-out"), options)
        }
        Some(Command::Run {
            scenario,
            out,
            options,
        }) => match Scenario::load(&scenario) {
            Ok(s) => run_scenario(&s, Some(&scenario), &base_of(&scenario), &out, options),
            Err(e) => {
                eprintln!("atelier: {e}");
                ExitCode::FAILURE
            }
        },
        Some(Command::Validate { files }) => validate(&files),
        Some(Command::View { dir, serve }) => view(&dir, serve),
        Some(Command::Pattern { file, out, cell }) => pattern(&file, &out, cell),
        Some(Command::Tryon {
            photo,
            mask,
            garment,
            pose,
            yaw,
            height,
            light,
            out,
            options,
        }) => {
            let mut inputs = atelier_tryon::TryonInputs::new(photo, mask, garment);
            inputs.pose = pose;
            inputs.yaw_deg = yaw.0;
            inputs.height_cm = height;
            if let Some(l) = light {
                inputs.light = l;
            }
            tryon(&inputs, &out, options)
        }
        Some(Command::Fit { observations, out }) => {
            match atelier::fit::fit_cloth(&observations, &out) {
                Ok(report) => {
                    // The fitted values are the program's output.
                    #[allow(clippy::print_stdout)]
                    {
                        for f in &report.fits {
                            let hysteresis = match (f.two_hb_gf_cm_cm, f.base_two_hb_gf_cm_cm) {
                                (Some(h), Some(base)) => {
                                    format!(", 2HB = {h:.4} gf·cm/cm (base {base:.4})")
                                }
                                _ => String::new(),
                            };
                            println!(
                                "{}: B = {:.4} gf·cm²/cm ({:.4e} N·m; base {:.4}){hysteresis}, c = {:.2} cm, RMS {:.3} mm over {} points ({}, {})",
                                f.direction,
                                f.b_gf_cm2_cm,
                                f.b_n_m,
                                f.base_b_gf_cm2_cm,
                                f.bending_length_m * 100.0,
                                f.rms_m * 1e3,
                                f.points,
                                f.observation,
                                f.forward_model
                            );
                        }
                        println!("wrote {}", out.join("fabric.ron").display());
                    }
                    ExitCode::SUCCESS
                }
                Err(e) => {
                    eprintln!("atelier: {e}");
                    ExitCode::FAILURE
                }
            }
        }
    }
}

fn run_scenario(
    scenario: &Scenario,
    file: Option<&Path>,
    base: &Path,
    out: &Path,
    options: Options,
) -> ExitCode {
    let run_options = match start(options) {
        Ok(o) => o,
        Err(code) => return code,
    };
    let bar = progress_bar(&scenario.name);
    let mut progress = |f: f64| {
        if let Some(b) = &bar {
            b.set_position((f.clamp(0.0, 1.0) * 1000.0) as u64);
        }
    };
    let result = run(scenario, file, base, out, &run_options, &mut progress);
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    match result {
        Ok(report) => {
            let line = format!("{} (outputs in {})", report.summary_line(), out.display());
            finish(&report, &line)
        }
        Err(e) => {
            eprintln!("atelier: {}: {e}", scenario.name);
            ExitCode::FAILURE
        }
    }
}

/// `atelier view`: the page, each problem on stderr first; then, with `--serve`, the server.
/// Exit status 1 when the page could not be written or the port not opened, 2 when the page
/// was written but the folder lacks or breaks a file the page shows.
fn view(dir: &Path, serve: Option<u16>) -> ExitCode {
    let page = match view::write_page(dir) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("atelier: {e}");
            return ExitCode::FAILURE;
        }
    };
    for p in &page.problems {
        eprintln!("atelier: {}: {p}", dir.display());
    }
    // The page's address is the program's output.
    #[allow(clippy::print_stdout)]
    {
        println!("wrote {}", page.index.display());
    }
    if let Some(port) = serve {
        let served = view::serve(dir, port, |address| {
            #[allow(clippy::print_stdout)]
            {
                println!("serving {} at {address} (Ctrl-C stops)", dir.display());
            }
        });
        if let Err(e) = served {
            eprintln!("atelier: cannot serve on 127.0.0.1:{port}: {e}");
            return ExitCode::FAILURE;
        }
    }
    if page.problems.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(2)
    }
}

/// `x,y,z`: three finite numbers, not all zero.
/// `--yaw`: degrees, or `None` for `search`.
#[derive(Clone, Copy, Debug)]
struct Yaw(Option<f64>);

fn parse_yaw(text: &str) -> Result<Yaw, String> {
    if text.trim() == "search" {
        return Ok(Yaw(None));
    }
    match text.trim().parse::<f64>() {
        Ok(d) if d.is_finite() && (-180.0..=180.0).contains(&d) => Ok(Yaw(Some(d))),
        Ok(_) => Err(format!(
            "`{text}`: a direction from -180 to 180 degrees, or `search`"
        )),
        Err(e) => Err(format!("`{text}`: {e} (give degrees, or `search`)")),
    }
}

fn parse_light(text: &str) -> Result<[f64; 3], String> {
    let v: Vec<f64> = text
        .split(',')
        .map(|s| s.trim().parse::<f64>().map_err(|e| format!("`{s}`: {e}")))
        .collect::<Result<_, _>>()?;
    match v[..] {
        [x, y, z] if v.iter().all(|c| c.is_finite()) && v.iter().any(|&c| c != 0.0) => {
            Ok([x, y, z])
        }
        _ => Err(format!(
            "`{text}`: give three finite numbers x,y,z, not all zero"
        )),
    }
}

fn tryon(inputs: &atelier_tryon::TryonInputs, out: &Path, options: Options) -> ExitCode {
    let run_options = match start(options) {
        Ok(o) => o,
        Err(code) => return code,
    };
    let bar = progress_bar("tryon");
    let mut progress = |f: f64| {
        if let Some(b) = &bar {
            b.set_position((f.clamp(0.0, 1.0) * 1000.0) as u64);
        }
    };
    let result = atelier_tryon::tryon(inputs, out, &run_options, &mut progress);
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    match result {
        Ok(report) => {
            let fit = report.tryon.as_ref().map_or(String::new(), |t| {
                format!(
                    "; silhouette overlap {:.3} → {:.3} (fit {:.1} s)",
                    t.iou_before, t.iou_after, t.fit_s
                )
            });
            let line = format!(
                "{}{fit} (outputs in {})",
                report.summary_line(),
                out.display()
            );
            if !report.passed() {
                // The convergence warning is printed by `finish` (or is in the summary line).
                let convergence = report.convergence_warning();
                for w in report
                    .warnings
                    .iter()
                    .filter(|w| Some(*w) != convergence.as_ref())
                {
                    eprintln!("atelier: warning: {w}");
                }
            }
            finish(&report, &line)
        }
        Err(e) => {
            eprintln!("atelier: tryon: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Start the thread pool (`--threads`) and the run's options (`--frames`); the exit code when
/// the threads cannot start.
fn start(options: Options) -> Result<RunOptions, ExitCode> {
    if let Some(n) = options.threads
        && let Err(e) = rayon::ThreadPoolBuilder::new()
            .num_threads(usize::from(n))
            .build_global()
    {
        eprintln!("atelier: cannot start {n} threads: {e}");
        return Err(ExitCode::FAILURE);
    }
    Ok(RunOptions {
        frames: options
            .frames
            .map_or(FrameSelection::All, |k| FrameSelection::AtMost(k as usize)),
        ..RunOptions::default()
    })
}

/// The summary `line` on stdout and exit status 0 when the run passed; on stderr and 2 when not.
/// Steps that did not converge are always said on stderr: in the summary line when they make
/// the run fail, as a warning line before it when the scenario accepts them (it bounds
/// `unconverged_fraction` itself) or when the run failed for another reason.
fn finish(report: &atelier::report::Report, line: &str) -> ExitCode {
    if let Some(w) = report.convergence_warning()
        && !line.contains(&w)
    {
        eprintln!("atelier: warning: {w}");
    }
    if report.passed() {
        // The summary is the program's output.
        #[allow(clippy::print_stdout)]
        {
            println!("{line}");
        }
        ExitCode::SUCCESS
    } else {
        eprintln!("atelier: {line}");
        ExitCode::from(2)
    }
}

/// A progress bar on a terminal (none otherwise).
fn progress_bar(name: &str) -> Option<indicatif::ProgressBar> {
    std::io::stderr().is_terminal().then(|| {
        let bar = indicatif::ProgressBar::new(1000);
        bar.set_style(
            indicatif::ProgressStyle::with_template(
                "{msg} [{elapsed_precise}] {wide_bar} {percent:>3}% (eta {eta})",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        bar.set_message(name.to_string());
        bar
    })
}

fn validate(files: &[PathBuf]) -> ExitCode {
    let mut failed = 0;
    for f in files {
        let outcome = validate::validate(f);
        failed += usize::from(outcome.is_err());
        // The report is the program's output.
        #[allow(clippy::print_stdout)]
        {
            println!("{}", validate::report_line(f, &outcome));
        }
    }
    if failed > 0 {
        eprintln!("{failed} of {} files have problems", files.len());
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    }
}

fn pattern(file: &Path, out: &Path, cell: f64) -> ExitCode {
    let options = atelier_import::PanelOptions {
        spacing_cm: cell,
        ..atelier_import::PanelOptions::default()
    };
    let imported = match atelier::patterns::import(file, &options) {
        Ok(i) => i,
        Err(e) => {
            eprintln!("atelier: {e}");
            return ExitCode::FAILURE;
        }
    };
    for w in &imported.warnings {
        eprintln!("warning: {w}");
    }
    // The pieces are the program's output.
    #[allow(clippy::print_stdout)]
    for p in &imported.pieces {
        let [w, h] = p.piece.size_cm();
        let q = (&p.panel.quality_before, &p.panel.quality_after);
        println!(
            "{}: {w:.1} × {h:.1} cm, {:.1} cm², grain {:.1}°, {} notches, {} darts, {} teams, quantity {}; grid {} nodes, shear SD {:.1}° → {:.1}° ({})",
            p.piece.name,
            p.piece.area_cm2(),
            p.piece.grain_deg(),
            p.piece.notches.len(),
            p.piece.darts.len(),
            p.plan.breakpoints.len(),
            p.piece.quantity,
            p.panel.topology.node_count(),
            q.0.shear_deg.sd,
            q.1.shear_deg.sd,
            p.piece.outline_source
        );
    }
    let written = match atelier::patterns::write_pieces(&imported, out) {
        Ok(w) => w,
        Err(e) => {
            eprintln!("atelier: {e}");
            return ExitCode::FAILURE;
        }
    };
    let picture = out.join("pieces.png");
    let title = format!(
        "{} — seam lines, grids, grain (green), notches (red), grid corners (blue), darts (purple), team ends numbered (teams k-(k+1))",
        file.file_name()
            .map_or(String::new(), |n| n.to_string_lossy().into_owned())
    );
    if let Err(e) =
        atelier::chart::write_pieces(&picture, &title, &atelier::patterns::drawings(&imported))
    {
        eprintln!("atelier: {}: {e}", picture.display());
        return ExitCode::FAILURE;
    }
    eprintln!(
        "wrote {} files and {} in {}",
        written.len(),
        picture.display(),
        out.display()
    );
    ExitCode::SUCCESS
}
