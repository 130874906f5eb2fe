//! Time against error for the garment pipeline (issue 10): the sewn dress and the walk, with
//! every accuracy knob of PARTY swept (Δt, shape and internal iteration caps, tolerances, the
//! tolerance policy), XPBD over substeps × sweeps (and Δt) and the mass-spring model over its
//! substeps, each run's error measured against a tight PARTY reference at equal simulated time.
//!
//! Scenes (`fixtures/scenarios/dress_sewn.ron`, `dress_walk.ron`, cotton broad, 2 558 nodes):
//!
//! - `dress`: sewn with gravity off, then settling, stopped at t = `DRESS_T` s;
//! - `walk`: sewn, settled 0.5 s, then the normal-gait walk, stopped at t = `WALK_T` s (about
//!   1 s of walking; the walk starts 0.5 s after the last pair is sewn, which differs between
//!   runs by a step or two).
//!
//! Per run: wall time of the steps, RMS node distance to the reference at the stop time, the
//! deepest any node went inside the body after any step (the simulation's own check), the
//! largest seam-pair gap at the end, and whether the run finished. The reference is PARTY at
//! Δt 2.5 ms with tight tolerances and high caps; its own uncertainty is its distance to a
//! tighter run (Δt 1.25 ms, caps doubled), reported in the table and drawn on the figure.
//!
//! Writes `tradeoff_<scene>.md` and `tradeoff_<scene>.png` into the output folder, each
//! atomically (a temporary name, then a rename). The full set takes about 8 minutes on two
//! cores; `quick` runs a smoke subset (shorter, coarser reference, three runs).

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use atelier::scenario::{Scenario, ScenarioKind};
use atelier::{ClothSolver, GarmentSpec, Scene, Simulation};
type V3 = nalgebra::Vector3<f64>;
use atelier_solver::baselines::{MassSpringParams, XpbdParams};
use atelier_solver::{StepParams, TolerancePolicy};
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::figures::plot::{PALETTE, png};

/// Simulated time of the dress scene, s.
const DRESS_T: f64 = 0.8;
/// Simulated time of the walk scene, s.
const WALK_T: f64 = 1.8;

/// One configuration.
#[derive(Clone)]
struct Config {
    family: &'static str,
    sweep: &'static str,
    label: String,
    dt: f64,
    solver: ClothSolver,
    step: StepParams,
    is_default: bool,
}

/// What a run measured.
struct Outcome {
    wall: Duration,
    positions: Vec<V3>,
    time: f64,
    depth: f64,
    gap: f64,
    status: String,
    steps: usize,
}

struct Row {
    config: Config,
    outcome: Outcome,
    error: Option<f64>,
    pareto: bool,
}

fn party(sweep: &'static str, label: String, dt: f64, step: StepParams, default: bool) -> Config {
    Config {
        family: "PARTY",
        sweep,
        label,
        dt,
        solver: ClothSolver::Party,
        step,
        is_default: default,
    }
}

/// The PARTY reference: Δt `dt`, tolerances 1e-9, caps `cap` (shape, per pass) and `cap / 2`
/// (internal, per phase).
fn reference(dt: f64, cap: usize) -> Config {
    party(
        "reference",
        format!("reference Δt {dt}, caps {cap}/{}", cap / 2),
        dt,
        StepParams {
            shape: atelier_solver::ShapeParams {
                tolerance: 1e-9,
                max_iterations: cap,
                ..atelier_solver::ShapeParams::default()
            },
            internal: atelier_solver::InternalParams {
                tolerance: 1e-9,
                max_iterations: cap / 2,
                ..atelier_solver::InternalParams::default()
            },
            ..StepParams::default()
        },
        false,
    )
}

/// The sweeps: PARTY over each knob from its default, XPBD, mass-spring.
fn configs(quick: bool) -> Vec<Config> {
    let d = StepParams::default;
    let mut c = vec![party("Δt", "defaults (Δt 0.01)".into(), 0.01, d(), true)];
    if quick {
        c.push(Config {
            family: "XPBD",
            sweep: "substeps × sweeps",
            label: "10 × 4".into(),
            dt: 0.01,
            solver: ClothSolver::Xpbd(XpbdParams::default()),
            step: d(),
            is_default: false,
        });
        return c;
    }
    for dt in [0.02, 0.005] {
        c.push(party("Δt", format!("Δt {dt}"), dt, d(), false));
    }
    for cap in [10, 100] {
        c.push(party(
            "shape cap",
            format!("shape cap {cap}"),
            0.01,
            StepParams {
                shape: atelier_solver::ShapeParams {
                    max_iterations: cap,
                    ..d().shape
                },
                ..d()
            },
            false,
        ));
    }
    for cap in [3, 30] {
        c.push(party(
            "internal cap",
            format!("internal cap {cap}"),
            0.01,
            StepParams {
                internal: atelier_solver::InternalParams {
                    max_iterations: cap,
                    ..d().internal
                },
                ..d()
            },
            false,
        ));
    }
    for tol in [1e-4, 1e-8] {
        c.push(party(
            "tolerances",
            format!("shape tol. {tol:e} m, internal {:e}", tol * 100.0),
            0.01,
            StepParams {
                shape: atelier_solver::ShapeParams {
                    tolerance: tol,
                    max_iterations: if tol < 1e-6 { 100 } else { 30 },
                    ..d().shape
                },
                internal: atelier_solver::InternalParams {
                    tolerance: (tol * 100.0).min(0.5),
                    ..d().internal
                },
                ..d()
            },
            false,
        ));
    }
    c.push(party(
        "tolerances",
        "adaptive policy (×10 above 0.5 m/s)".into(),
        0.01,
        StepParams {
            tolerance_policy: TolerancePolicy::Adaptive {
                loose_factor: 10.0,
                fast_speed: 0.5,
                slow_speed: 0.05,
            },
            ..d()
        },
        false,
    ));
    for (dt, substeps, iterations) in [
        (0.01, 2, 2),
        (0.01, 5, 2),
        (0.01, 10, 4),
        (0.01, 20, 8),
        (0.005, 10, 4),
    ] {
        c.push(Config {
            family: "XPBD",
            sweep: "substeps × sweeps",
            label: format!("Δt {dt}, {substeps} × {iterations}"),
            dt,
            solver: ClothSolver::Xpbd(XpbdParams {
                substeps,
                iterations,
                ..XpbdParams::default()
            }),
            step: d(),
            is_default: false,
        });
    }
    for substeps in [250, 500] {
        c.push(Config {
            family: "mass-spring",
            sweep: "substeps",
            label: format!("Δt 0.01 in {substeps} (h {:.0} µs)", 1e4 / substeps as f64),
            dt: 0.01,
            solver: ClothSolver::MassSpring(MassSpringParams {
                substeps,
                ..MassSpringParams::default()
            }),
            step: d(),
            is_default: false,
        });
    }
    c
}

/// A scene of the study: its spec and stop time.
struct SceneDef {
    name: &'static str,
    title: &'static str,
    spec: GarmentSpec,
    stop: f64,
}

fn scenes(root: &Path, quick: bool) -> Result<Vec<SceneDef>> {
    let load = |name: &str| -> Result<GarmentSpec> {
        let path = root.join("fixtures/scenarios").join(format!("{name}.ron"));
        let s = Scenario::load(&path).with_context(|| format!("loading {}", path.display()))?;
        match s.kind {
            ScenarioKind::Garment(g) => Ok(g),
            _ => anyhow::bail!("{name} is not a garment scenario"),
        }
    };
    let mut dress = load("dress_sewn")?;
    dress.settings.settle = 10.0;
    let mut walk = load("dress_walk")?;
    walk.settings.settle = 0.5;
    walk.settings.motion_time = 10.0;
    let (dress_t, walk_t) = if quick { (0.3, 0.8) } else { (DRESS_T, WALK_T) };
    Ok(vec![
        SceneDef {
            name: "dress",
            title: "the sewn dress",
            spec: dress,
            stop: dress_t,
        },
        SceneDef {
            name: "walk",
            title: "the walk",
            spec: walk,
            stop: walk_t,
        },
    ])
}

/// Run one configuration on a scene to its stop time.
fn run_one(root: &Path, scene: &SceneDef, c: &Config) -> Result<Outcome> {
    let mut spec = scene.spec.clone();
    spec.settings.dt = c.dt;
    spec.settings.step = c.step.clone();
    spec.settings.solver = c.solver.clone();
    let base = root.join("fixtures/scenarios");
    let s = Scene::load(&spec, &base)?;
    let pairs = s.garment.cloth.pairs.clone();
    let mut sim = Simulation::new(s)?;
    let (mut depth, mut steps, mut status) = (0.0f64, 0usize, "ok".to_owned());
    let clock = Instant::now();
    while sim.time() < scene.stop - 0.5 * c.dt {
        match sim.step() {
            Ok(Some(o)) => {
                depth = depth.max(o.depth);
                steps += 1;
            }
            Ok(None) => {
                status = format!("schedule ended at {:.2} s", sim.time());
                break;
            }
            Err(e) => {
                status = format!("failed: {e}");
                break;
            }
        }
    }
    let wall = clock.elapsed();
    if sim.sewn_at().is_none() && status == "ok" {
        status = "not sewn".into();
    }
    let x = &sim.state().positions;
    let gap = pairs
        .iter()
        .map(|&(a, b)| (x[a as usize] - x[b as usize]).norm())
        .fold(0.0, f64::max);
    Ok(Outcome {
        wall,
        positions: x.clone(),
        time: sim.time(),
        depth,
        gap,
        status,
        steps,
    })
}

fn rms(a: &[V3], b: &[V3]) -> f64 {
    let s: f64 = a.iter().zip(b).map(|(p, q)| (p - q).norm_squared()).sum();
    (s / a.len() as f64).sqrt()
}

/// The figure set's entry point for `cargo xtask figures tradeoff`.
pub fn draw_all(_root: &Path, out: &Path) -> Result<Vec<PathBuf>> {
    run(out, false)?;
    Ok(["dress", "walk"]
        .iter()
        .flat_map(|s| {
            [
                out.join(format!("tradeoff_{s}.md")),
                out.join(format!("tradeoff_{s}.png")),
            ]
        })
        .collect())
}

/// Run the study and write `tradeoff_<scene>.{md,png}` into `out`.
pub fn run(out: &Path, quick: bool) -> Result<()> {
    let root = crate::repository_root();
    std::fs::create_dir_all(out)?;
    for scene in scenes(&root, quick)? {
        let (ref_dt, ref_cap) = if quick { (0.005, 100) } else { (0.0025, 200) };
        eprintln!("{}: reference …", scene.name);
        let reference_cfg = reference(ref_dt, ref_cap);
        let r = run_one(&root, &scene, &reference_cfg)?;
        anyhow::ensure!(
            r.status == "ok",
            "{}: the reference did not finish: {}",
            scene.name,
            r.status
        );
        let tighter_cfg = reference(ref_dt / 2.0, ref_cap * 2);
        eprintln!("{}: tighter reference …", scene.name);
        let t = run_one(&root, &scene, &tighter_cfg)?;
        let uncertainty = rms(&r.positions, &t.positions);
        eprintln!(
            "{}: reference {:.1} s wall, its distance to the tighter one {:.2} mm ({:.1} s wall)",
            scene.name,
            r.wall.as_secs_f64(),
            uncertainty * 1e3,
            t.wall.as_secs_f64()
        );
        let mut rows: Vec<Row> = Vec::new();
        for c in configs(quick) {
            let o = run_one(&root, &scene, &c)?;
            let error = (o.status == "ok" && (o.time - r.time).abs() < 1e-6)
                .then(|| rms(&o.positions, &r.positions))
                .filter(|e| e.is_finite());
            eprintln!(
                "{} {} / {}: {:.2} s wall, error {}, depth {:.2} mm, gap {:.1} mm, {}",
                scene.name,
                c.family,
                c.label,
                o.wall.as_secs_f64(),
                error.map_or("–".into(), |e| format!("{:.2} mm", e * 1e3)),
                o.depth * 1e3,
                o.gap * 1e3,
                o.status
            );
            rows.push(Row {
                config: c,
                outcome: o,
                error,
                pareto: false,
            });
        }
        let front = crate::figures::plot::pareto_front(
            &rows
                .iter()
                .map(|r| (r.outcome.wall.as_secs_f64(), r.error))
                .collect::<Vec<_>>(),
        );
        for (r, on) in rows.iter_mut().zip(front) {
            r.pareto = on;
        }
        let md = out.join(format!("tradeoff_{}.md", scene.name));
        let text = table(
            &scene,
            &rows,
            &r,
            &reference_cfg,
            &t,
            &tighter_cfg,
            uncertainty,
        );
        atelier_files::files::write_atomic(&md, text.as_bytes())?;
        let pic = out.join(format!("tradeoff_{}.png", scene.name));
        png(&pic, (1300, 850), |area| {
            draw(area, &scene, &rows, uncertainty)
        })?;
    }
    Ok(())
}

fn table(
    scene: &SceneDef,
    rows: &[Row],
    r: &Outcome,
    rc: &Config,
    t: &Outcome,
    tc: &Config,
    uncertainty: f64,
) -> String {
    let mut s = format!(
        "# Time against error: {} ({:.2} s simulated)\n\n\
         Written by `cargo xtask figures tradeoff`. Error: RMS node distance to the reference at \
         t = {:.2} s. Reference: {} — {:.1} s wall, {} steps, deepest node inside the body \
         {:.2} mm, largest seam gap {:.2} mm. Its uncertainty, judged by a tighter run ({}; \
         {:.1} s wall): **{:.2} mm**.\n\n\
         | solver | sweep | setting | steps | wall s | RMS error mm | deepest inside mm | largest seam gap mm | Pareto | status |\n\
         |---|---|---|---|---|---|---|---|---|---|\n",
        scene.title,
        scene.stop,
        r.time,
        rc.label,
        r.wall.as_secs_f64(),
        r.steps,
        r.depth * 1e3,
        r.gap * 1e3,
        tc.label,
        t.wall.as_secs_f64(),
        uncertainty * 1e3
    );
    for row in rows {
        let o = &row.outcome;
        s += &format!(
            "| {} | {} | {}{} | {} | {:.2} | {} | {:.2} | {:.2} | {} | {} |\n",
            row.config.family,
            row.config.sweep,
            row.config.label,
            if row.config.is_default {
                " (defaults)"
            } else {
                ""
            },
            o.steps,
            o.wall.as_secs_f64(),
            row.error.map_or("–".into(), |e| format!("{:.2}", e * 1e3)),
            o.depth * 1e3,
            o.gap * 1e3,
            if row.pareto { "yes" } else { "" },
            o.status
        );
    }
    s
}

fn colour(family: &str) -> RGBColor {
    match family {
        "PARTY" => PALETTE[0],
        "XPBD" => PALETTE[1],
        _ => PALETTE[2],
    }
}

fn draw(
    root: &DrawingArea<BitMapBackend, Shift>,
    scene: &SceneDef,
    rows: &[Row],
    uncertainty: f64,
) -> Result<()> {
    let pts: Vec<(f64, f64)> = rows
        .iter()
        .filter_map(|r| r.error.map(|e| (r.outcome.wall.as_secs_f64(), e * 1e3)))
        .collect();
    anyhow::ensure!(!pts.is_empty(), "{}: no run finished", scene.name);
    let (x_min, x_max) = pts.iter().fold((f64::INFINITY, 0.0f64), |(a, b), p| {
        (a.min(p.0), b.max(p.0))
    });
    let (y_min, y_max) = pts.iter().fold((uncertainty * 1e3, 0.0f64), |(a, b), p| {
        (a.min(p.1), b.max(p.1))
    });
    let x_range = (x_min / 1.5)..(x_max * 1.5);
    let y_range = (y_min.max(1e-3) / 2.0)..(y_max * 2.0);
    let mut chart = ChartBuilder::on(root)
        .caption(
            format!(
                "Time against error: {} (dress_{}, 2 558 nodes, cotton), {:.1} s simulated",
                scene.title,
                if scene.name == "dress" {
                    "sewn"
                } else {
                    "walk"
                },
                scene.stop
            ),
            ("sans-serif", 22),
        )
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d(x_range.clone().log_scale(), y_range.clone().log_scale())?;
    chart
        .configure_mesh()
        .x_desc(format!("wall time for {:.1} s simulated (s)", scene.stop))
        .y_desc("RMS node distance to the reference (mm)")
        .light_line_style(TRANSPARENT)
        .x_label_formatter(&|v| format!("{v:.1}"))
        .y_label_formatter(&|v| {
            if *v >= 1.0 {
                format!("{v:.0}")
            } else {
                format!("{v:.2}")
            }
        })
        .axis_desc_style(("sans-serif", 17))
        .label_style(("sans-serif", 14))
        .draw()?;
    let grey = RGBColor(120, 120, 120);
    chart
        .draw_series(DashedLineSeries::new(
            vec![
                (x_range.start, uncertainty * 1e3),
                (x_range.end, uncertainty * 1e3),
            ],
            3,
            4,
            grey.stroke_width(2),
        ))?
        .label("reference uncertainty (vs. a tighter run)")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], grey.stroke_width(2)));
    let mut sweeps: Vec<(&str, &str)> = Vec::new();
    for r in rows {
        if !sweeps.contains(&(r.config.family, r.config.sweep)) {
            sweeps.push((r.config.family, r.config.sweep));
        }
    }
    let default = rows.iter().find(|r| r.config.is_default);
    for (k, &(family, sweep)) in sweeps.iter().enumerate() {
        // PARTY's sweeps each go through the defaults.
        let mut members: Vec<&Row> = rows
            .iter()
            .filter(|r| r.config.family == family && r.config.sweep == sweep)
            .collect();
        if family == "PARTY"
            && let Some(d) = default
            && !members.iter().any(|m| m.config.is_default)
        {
            members.push(d);
        }
        members.sort_by_key(|r| r.outcome.wall);
        let line: Vec<(f64, f64)> = members
            .iter()
            .filter_map(|r| r.error.map(|e| (r.outcome.wall.as_secs_f64(), e * 1e3)))
            .collect();
        if line.is_empty() {
            continue;
        }
        let c = colour(family);
        let style = c.stroke_width(2);
        if k % 2 == 1 {
            chart.draw_series(DashedLineSeries::new(line.clone(), 7, 4, style))?;
        } else {
            chart.draw_series(LineSeries::new(line.clone(), style))?;
        }
        chart
            .draw_series(
                line.iter()
                    .map(|&p| EmptyElement::at(p) + marker(k, c.stroke_width(2))),
            )?
            .label(format!("{family}: {sweep}"))
            .legend(move |(x, y)| {
                EmptyElement::at((x + 12, y))
                    + PathElement::new(vec![(-12, 0), (12, 0)], style)
                    + marker(k, style)
            });
    }
    if let Some(d) = default
        && let Some(e) = d.error
    {
        chart.draw_series(std::iter::once(
            EmptyElement::at((d.outcome.wall.as_secs_f64(), e * 1e3))
                + Circle::new((0, 0), 11, BLACK.stroke_width(2))
                + Text::new("PARTY defaults", (12, -22), ("sans-serif", 15).into_font()),
        ))?;
    }
    let mut front: Vec<&Row> = rows.iter().filter(|r| r.pareto).collect();
    front.sort_by_key(|r| r.outcome.wall);
    let mut stairs: Vec<(f64, f64)> = Vec::new();
    for r in &front {
        let p = (
            r.outcome.wall.as_secs_f64(),
            r.error.unwrap_or(f64::NAN) * 1e3,
        );
        if let Some(&(_, y)) = stairs.last() {
            stairs.push((p.0, y));
        }
        stairs.push(p);
    }
    if let Some(&(_, y)) = stairs.last() {
        stairs.push((x_range.end, y));
    }
    chart
        .draw_series(LineSeries::new(stairs, BLACK.stroke_width(1)))?
        .label("Pareto front (filled: on it)")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], BLACK.stroke_width(1)));
    chart.draw_series(front.iter().map(|r| {
        EmptyElement::at((
            r.outcome.wall.as_secs_f64(),
            r.error.unwrap_or(f64::NAN) * 1e3,
        )) + Circle::new((0, 0), 5, colour(r.config.family).filled())
    }))?;
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerRight)
        .label_font(("sans-serif", 13))
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .draw()?;
    Ok(())
}

/// A marker shape per sweep.
fn marker<DB: DrawingBackend>(k: usize, style: ShapeStyle) -> DynElement<'static, DB, (i32, i32)> {
    match k % 6 {
        0 => Circle::new((0, 0), 5, style).into_dyn(),
        1 => TriangleMarker::new((0, 0), 6, style).into_dyn(),
        2 => Rectangle::new([(-4, -4), (4, 4)], style).into_dyn(),
        3 => Cross::new((0, 0), 5, style).into_dyn(),
        4 => Polygon::new(vec![(0, -6), (6, 0), (0, 6), (-6, 0)], style).into_dyn(),
        _ => Circle::new((0, 0), 3, style.filled()).into_dyn(),
    }
}
