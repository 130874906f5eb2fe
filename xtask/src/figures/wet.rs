//! The wet-cloth measurements (issue 8, "Figures and speed"; `docs/wet.md`): Yamada's
//! mass-spring model against the PARTY step with the same pressure force, on the thesis's scene
//! (a 30 cm square of wet satin over 400 cm³ of air, pinched at its centre and lifted 2 cm at
//! 2 cm/s, `fixtures/scenarios/wet_pinch1_air400.ron`).
//!
//! 1. The thesis's timing table (Table 4.2, particles → frames per second) re-measured at 100,
//!    400, 900, 1 600 and 2 500 particles over 0.5 s of the scene: steps per second and wall time
//!    per simulated second of Yamada's model (Δt 1/12 000 s, one thread, as the thesis) and of the
//!    PARTY step (Δt 5 ms, on one thread and on the machine's two).
//! 2. The largest stable Δt of each solver on the scene and on its dry control (bisection on a
//!    log scale; stable: the 0.5 s run ends without a failed step and no node faster than 2 m/s),
//!    and of Yamada's model with springs as stiff as the satin.
//! 3. The shape difference: the RMS distance of the final nodes (t = 1.5 s) of each run from
//!    Yamada's at Δt 1/12 000 s, with Yamada's own at Δt/2 as the reference's uncertainty, for the
//!    PARTY step at Δt 2, 5, 10 and 15 ms (and with fewer iterations: cheaper steps) and for
//!    Yamada's model with the satin's springs.
//!
//! Output: `wet_speed.png` (wall time per simulated second against particles, log–log) and
//! `wet.md` (the three tables, also printed to stderr).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use atelier_fabric::Fabric;
use atelier_solver::StepParams;
use atelier_solver::wet::scene::{
    Springs, WetPartyParams, WetRun, WetScene, WetSolver, YamadaParams, largest_dt_where,
    largest_stable_dt, run,
};
use plotters::prelude::*;

use crate::figures::plot::{PALETTE, png};

/// The thesis's Table 4.2: particles, frames per second (Core i7-3930K, one thread).
const THESIS_FPS: [(usize, f64); 5] = [
    (100, 1720.0),
    (400, 500.0),
    (900, 210.0),
    (1600, 115.0),
    (2500, 64.0),
];

/// The scene of `wet_pinch1_air400` with `side` particles per side, `air` cm³ (none: dry) and
/// `duration` s.
fn scene(side: usize, air: Option<f64>, duration: f64) -> WetScene {
    WetScene {
        particles: side,
        duration,
        ..WetScene::thesis_pinch(1, air.map(|a| a * 1e-6))
    }
}

fn yamada(dt: f64) -> WetSolver {
    WetSolver::Yamada(YamadaParams {
        dt,
        ..YamadaParams::default()
    })
}

fn party(dt: f64) -> WetSolver {
    WetSolver::Party(WetPartyParams {
        dt,
        ..WetPartyParams::default()
    })
}

/// One run on `threads` worker threads.
fn run_on(threads: usize, scene: &WetScene, fabric: &Fabric, solver: &WetSolver) -> Result<WetRun> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .context("thread pool")?;
    pool.install(|| run(scene, fabric, solver))
        .context("wet scene")
}

/// Draw everything into `out`.
pub fn draw_all(root: &Path, out: &Path) -> Result<Vec<PathBuf>> {
    let fabric = Fabric::load(&root.join("fixtures/fabrics/polyester_satin_wet.ron"))
        .context("the wet satin")?;
    let mut md = String::from("# Wet cloth: Yamada's model against the PARTY step\n\n");
    let machine = format!(
        "{} worker threads available; release build.",
        std::thread::available_parallelism().map_or(1, |n| n.get())
    );
    writeln!(
        md,
        "Scene: `wet_pinch1_air400` (30 cm wet satin over 400 cm³ of air, pinched at the centre, 2 cm at 2 cm/s). {machine}\n"
    )?;

    // 1. Timing table.
    writeln!(
        md,
        "## Timing (thesis Table 4.2 re-measured, 0.5 s of the scene)\n"
    )?;
    writeln!(
        md,
        "| particles | thesis fps | Yamada steps/s (1 thread, Δt 1/12 000 s) | Yamada wall per simulated s | PARTY steps/s (Δt 5 ms, 1 thread) | PARTY wall per simulated s, 1 thread | PARTY, 2 threads | Yamada ÷ PARTY (1 thread) |"
    )?;
    writeln!(md, "|---|---|---|---|---|---|---|---|")?;
    let mut speed: Vec<(usize, f64, f64, f64)> = Vec::new();
    for (side, (n, fps)) in [10, 20, 30, 40, 50].into_iter().zip(THESIS_FPS) {
        let s = scene(side, Some(400.0), 0.5);
        let y = run_on(1, &s, &fabric, &yamada(1.0 / 12000.0))?;
        let p1 = run_on(1, &s, &fabric, &party(0.005))?;
        let p2 = run_on(2, &s, &fabric, &party(0.005))?;
        for r in [&y, &p1, &p2] {
            if let Some(f) = &r.failure {
                writeln!(
                    md,
                    "(the {} run at {n} particles stopped: {})",
                    r.solver, f.error
                )?;
            }
        }
        let (wy, w1, w2) = (
            y.wall_per_second(),
            p1.wall_per_second(),
            p2.wall_per_second(),
        );
        writeln!(
            md,
            "| {n} | {fps:.0} | {:.0} | {wy:.3} s | {:.0} | {w1:.3} s | {w2:.3} s | {:.2} |",
            y.steps as f64 / y.wall.as_secs_f64(),
            p1.steps as f64 / p1.wall.as_secs_f64(),
            wy / w1
        )?;
        speed.push((n, wy, w1, w2));
    }
    writeln!(
        md,
        "\nThe thesis's frames per second cannot be converted without its steps per frame; if each frame advanced one step of 1/12 000 s, its wall time per simulated second was 12 000/fps: {} s at 2 500 particles.\n",
        12000.0 / 64.0
    )?;

    // 2. Largest stable Δt, and largest usable Δt (the final shape within 5 mm RMS of
    // Yamada's at 1/12 000 s).
    let full = scene(50, Some(400.0), 1.5);
    let reference = run_on(1, &full, &fabric, &yamada(1.0 / 12000.0))?;
    writeln!(
        md,
        "## Largest Δt (2 500 particles)
"
    )?;
    writeln!(md, "Stable: 0.5 s of the scene without a failed step and no node above 2 m/s. Usable: the whole 1.5 s with the final nodes within 5 mm RMS of Yamada's at Δt 1/12 000 s. Bisection on a log scale, 7 halvings.
")?;
    writeln!(
        md,
        "| solver | stable, 400 cm³ of air | stable, dry | usable, 400 cm³ |"
    )?;
    writeln!(md, "|---|---|---|---|")?;
    let fabric_springs = WetSolver::Yamada(YamadaParams {
        springs: Springs::FromFabric { fraction: 0.01 },
        ..YamadaParams::default()
    });
    let solvers = [
        (
            "Yamada, the thesis's springs (200 / 50 N/m)",
            yamada(1.0 / 12000.0),
            (4e-5, 4e-4),
        ),
        (
            "Yamada, springs as stiff as the satin",
            fabric_springs.clone(),
            (1e-5, 1e-4),
        ),
        ("PARTY step (2 threads)", party(0.005), (1e-3, 0.1)),
    ];
    let mut stable_fabric = 2e-5;
    let cell = |dt: Option<f64>, range: (f64, f64)| {
        dt.map_or(format!("below {:.3} ms", range.0 * 1e3), |dt| {
            if dt >= range.1 {
                format!("≥ {:.3} ms (the range's top)", dt * 1e3)
            } else {
                format!("{:.3} ms", dt * 1e3)
            }
        })
    };
    for (name, solver, range) in &solvers {
        let mut cells = Vec::new();
        for air in [Some(400.0), None] {
            let dt = largest_stable_dt(&scene(50, air, 0.5), &fabric, solver, *range, 7, 2.0)
                .context("stability")?;
            if air.is_some() && name.contains("satin") {
                stable_fabric = dt.unwrap_or(range.0);
            }
            cells.push(cell(dt, *range));
        }
        let usable = largest_dt_where(&full, &fabric, solver, *range, 7, &|r: &WetRun| {
            r.failure.is_none() && r.rms_distance(&reference) <= 5e-3
        })
        .context("usable Δt")?;
        cells.push(cell(usable, *range));
        writeln!(
            md,
            "| {name} | {} | {} | {} |",
            cells[0], cells[1], cells[2]
        )?;
    }
    writeln!(
        md,
        "\nThe air cushion alone limits an explicit step to 2·√(ρ·h₀/P_a) (ρ the cloth's mass per area, h₀ = v₀/A the air's mean thickness): 0.144 ms for 0.12 kg/m² over 4.4 mm.\n"
    )?;

    // 3. Shape difference.
    writeln!(
        md,
        "## Shape difference at t = 1.5 s (RMS distance of the 2 500 nodes from Yamada's at Δt 1/12 000 s)\n"
    )?;
    writeln!(
        md,
        "| run | Δt | wall for 1.5 s | RMS from Yamada | tent height | ended |"
    )?;
    writeln!(md, "|---|---|---|---|---|---|")?;
    let mut rows: Vec<(String, WetRun)> = vec![(
        "Yamada, Δt/2".into(),
        run_on(1, &full, &fabric, &yamada(1.0 / 24000.0))?,
    )];
    for dt in [0.002, 0.005, 0.01, 0.015] {
        rows.push((
            "PARTY step, 2 threads".into(),
            run_on(2, &full, &fabric, &party(dt))?,
        ));
    }
    // Cheaper PARTY steps: fewer iterations (time against error).
    for (dt, cap) in [(0.005, 10), (0.005, 5), (0.01, 5)] {
        let cheap = WetSolver::Party(WetPartyParams {
            dt,
            step: StepParams {
                shape: atelier_solver::ShapeParams {
                    max_iterations: cap,
                    ..atelier_solver::ShapeParams::default()
                },
                internal: atelier_solver::InternalParams {
                    max_iterations: cap,
                    ..atelier_solver::InternalParams::default()
                },
                ..StepParams::default()
            },
        });
        let name = format!("PARTY step, 2 threads, ≤ {cap} shape and {cap} internal iterations");
        rows.push((name, run_on(2, &full, &fabric, &cheap)?));
    }
    let stiff = WetSolver::Yamada(YamadaParams {
        dt: 0.8 * stable_fabric,
        springs: Springs::FromFabric { fraction: 0.01 },
        ..YamadaParams::default()
    });
    rows.push((
        "Yamada, satin springs".into(),
        run_on(1, &full, &fabric, &stiff)?,
    ));
    let line = |name: &str, r: &WetRun, rms: Option<f64>| {
        format!(
            "| {name} | {:.4} ms | {:.2} s | {} | {:.2} mm | {} |",
            r.dt * 1e3,
            r.wall.as_secs_f64(),
            rms.map_or("–".into(), |v| format!("{:.2} mm", v * 1e3)),
            r.last().tent_height * 1e3,
            r.failure
                .as_ref()
                .map_or("yes".to_string(), |f| format!("no, at {:.3} s", f.time))
        )
    };
    writeln!(md, "{}", line("Yamada (the reference)", &reference, None))?;
    for (name, r) in &rows {
        let rms = r.failure.is_none().then(|| r.rms_distance(&reference));
        writeln!(md, "{}", line(name, r, rms))?;
    }
    let (_, w50, p50, _) = speed.last().copied().unwrap_or_default();
    writeln!(
        md,
        "\nAt 2 500 particles the PARTY step (Δt 5 ms, one thread) takes {:.2} of Yamada's wall time per simulated second ({:.1}× faster); the issue's goal was 10×.\n",
        p50 / w50,
        w50 / p50
    )?;

    eprint!("{md}");
    let md_path = out.join("wet.md");
    atelier_files::files::write_atomic(&md_path, md.as_bytes())
        .with_context(|| format!("writing {}", md_path.display()))?;
    let chart = speed_chart(&out.join("wet_speed.png"), &speed)?;
    Ok(vec![md_path, chart])
}

/// Wall time per simulated second against particles, log–log.
fn speed_chart(path: &Path, speed: &[(usize, f64, f64, f64)]) -> Result<PathBuf> {
    png(path, (900, 600), |root| {
        let mut chart = ChartBuilder::on(root)
            .caption(
                "wet cloth: wall time per simulated second",
                ("sans-serif", 22),
            )
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d((80f64..3000f64).log_scale(), (1e-2f64..1000f64).log_scale())?;
        chart
            .configure_mesh()
            .x_desc("particles")
            .y_desc("wall s per simulated s")
            .x_labels(6)
            .x_label_formatter(&|x| format!("{x:.0}"))
            .y_label_formatter(&|y| format!("{y}"))
            .label_style(("sans-serif", 15))
            .draw()?;
        let series: [(&str, Vec<(f64, f64)>); 4] = [
            (
                "thesis, if one frame was one step (12 000/fps)",
                THESIS_FPS
                    .iter()
                    .map(|&(n, f)| (n as f64, 12000.0 / f))
                    .collect(),
            ),
            (
                "Yamada, Δt 1/12 000 s, 1 thread",
                speed.iter().map(|s| (s.0 as f64, s.1)).collect(),
            ),
            (
                "PARTY, Δt 5 ms, 1 thread",
                speed.iter().map(|s| (s.0 as f64, s.2)).collect(),
            ),
            (
                "PARTY, Δt 5 ms, 2 threads",
                speed.iter().map(|s| (s.0 as f64, s.3)).collect(),
            ),
        ];
        for (k, (name, pts)) in series.into_iter().enumerate() {
            let c = PALETTE[k];
            chart
                .draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))?
                .label(name)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2))
                });
            chart.draw_series(pts.into_iter().map(|p| Circle::new(p, 4, c.filled())))?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK)
            .label_font(("sans-serif", 14))
            .position(SeriesLabelPosition::LowerRight)
            .draw()?;
        Ok(())
    })
}
