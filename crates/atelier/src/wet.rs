//! Wet-cloth scenarios (`ScenarioKind::Wet`; `docs/wet.md`): Yamada's experiment — a square of
//! wet cloth on a plane, pinched and lifted, with or without air trapped under it
//! ([`atelier_solver::wet::scene`]) — run on one solver, optionally compared with a run of the
//! same scene on another, and measured: the bubble's volume and pressure over time, the lifted
//! area, the tent's height, the folds around the first pinch, and between the two runs the RMS
//! distance of their final nodes and their cost.

use std::collections::BTreeMap;

use atelier_fabric::Fabric;
use atelier_solver::wet::ATMOSPHERE;
use atelier_solver::wet::scene::{WetRun, WetScene, run};

use crate::chart::{Chart, Series};
use crate::convergence::Convergence;
use crate::export::Animation;
pub use crate::outcome::WetOutputs;
use crate::outcome::{Comparison, KindOutputs, RunError, Simulated};
pub use crate::scenario::wet::{METRICS, WetSpec};
use crate::simulation::Timings;

/// Whether a run's steps converged: the PARTY step's reports as the run counted them
/// (`WetRun::stats`); Yamada's model has no tolerance (a baseline): not reported (`null`).
fn convergence(r: &WetRun) -> Convergence {
    match &r.stats {
        Some(stats) => Convergence::from_stats(r.solver, stats),
        None => Convergence::not_reported(r.solver, r.steps),
    }
}

/// The metrics of one run (without the `compare_` ones).
fn run_metrics(r: &WetRun, spec: &WetSpec) -> BTreeMap<String, Option<f64>> {
    let last = r.last();
    let rest = spec.scene.rest;
    let pressures: Vec<f64> = r.samples[1..]
        .iter()
        .filter_map(|s| s.pressure.map(|p| p - ATMOSPHERE))
        .collect();
    let pinch = r
        .picked
        .iter()
        .map(|&k| r.positions[k as usize].z - rest)
        .fold(None, |m: Option<f64>, h| Some(m.map_or(h, |m| m.max(h))));
    let folds = r
        .picked
        .first()
        .map(|&k| r.folds(k, spec.fold_radius, spec.fold_prominence));
    let mut m = BTreeMap::new();
    let mut put = |k: &str, v: Option<f64>| {
        m.insert(k.to_string(), v);
    };
    put("steps", Some(r.steps as f64));
    put("bubble_volume_cm3", Some(last.volume * 1e6));
    put("air_cm3", last.air.map(|a| a * 1e6));
    put("bubbles", Some(last.bubbles as f64));
    put(
        "pressure_difference_pa",
        last.pressure.map(|p| p - ATMOSPHERE),
    );
    put(
        "min_pressure_difference_pa",
        pressures.iter().copied().reduce(f64::min),
    );
    put(
        "max_pressure_difference_pa",
        pressures.iter().copied().reduce(f64::max),
    );
    put("lifted_area_cm2", Some(last.lifted_area * 1e4));
    put("tent_height_mm", Some(last.tent_height * 1e3));
    put("pinch_height_mm", pinch.map(|h| h * 1e3));
    put("max_strain", Some(last.max_strain));
    put("max_speed_m_s", Some(last.max_speed));
    put("folds", folds.as_ref().map(|f| f.count as f64));
    put(
        "fold_spacing_deviation_deg",
        folds.as_ref().map(|f| f.spacing_deviation_deg),
    );
    put(
        "fold_prominence_ratio",
        folds.as_ref().map(|f| f.prominence_ratio),
    );
    put(
        "fold_ring_height_mm",
        folds.as_ref().map(|f| (f.mean_height - rest) * 1e3),
    );
    m
}

/// The rows of `series.csv` for one run.
fn series_rows(out: &mut String, r: &WetRun) {
    use std::fmt::Write;
    for s in &r.samples {
        let opt = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.9e}"));
        let _ = writeln!(
            out,
            "{},{:.6},{:.9e},{},{},{},{:.9e},{:.9e},{:.9e},{:.9e}",
            r.solver,
            s.time,
            s.volume * 1e6,
            opt(s.pressure.map(|p| p - ATMOSPHERE)),
            opt(s.air.map(|a| a * 1e6)),
            s.bubbles,
            s.lifted_area * 1e4,
            s.tent_height * 1e3,
            s.max_strain,
            s.max_speed,
        );
    }
}

/// The z-up positions of a run's final state.
fn z_up(r: &WetRun) -> Vec<[f64; 3]> {
    r.positions.iter().map(|p| [p.x, p.y, p.z]).collect()
}

/// Run a wet scenario: the main run (its frames recorded), then the compared run if any.
pub fn simulate(spec: &WetSpec, fabric: &Fabric) -> Result<Simulated, RunError> {
    const SCENE: &str = "wet scene";
    if !(spec.frame_interval > 0.0 && spec.frame_interval.is_finite()) {
        return Err(RunError::out_of_range(
            SCENE,
            "frame_interval",
            format!("{} is outside (0, ∞)", spec.frame_interval),
        ));
    }
    if !(spec.fold_radius > 0.0 && spec.fold_radius < spec.scene.size) {
        return Err(RunError::out_of_range(
            SCENE,
            "fold_radius",
            format!("{} is outside (0, size)", spec.fold_radius),
        ));
    }
    let scene = WetScene {
        frame_interval: Some(spec.frame_interval),
        ..spec.scene.clone()
    };
    let main = run(&scene, fabric, &spec.solver).map_err(RunError::setup(SCENE))?;
    let compared = match &spec.compare {
        Some(solver) => Some(run(&spec.scene, fabric, solver).map_err(RunError::setup(SCENE))?),
        None => None,
    };
    let mut metrics = run_metrics(&main, spec);
    let mut series_csv = String::from(
        "solver,time_s,volume_cm3,pressure_difference_pa,air_cm3,bubbles,lifted_area_cm2,tent_height_mm,max_strain,max_speed_m_s\n",
    );
    series_rows(&mut series_csv, &main);
    let mut comparison = None;
    let mut warnings = Vec::new();
    if let Some(c) = &compared {
        series_rows(&mut series_csv, c);
        let cm = run_metrics(c, spec);
        let failed = c.failure.is_some();
        metrics.insert(
            "compare_simulated_s".into(),
            Some((c.time * 1e9).round() / 1e9),
        );
        metrics.insert("compare_failed".into(), Some(f64::from(u8::from(failed))));
        for (k, from) in [
            ("compare_tent_height_mm", "tent_height_mm"),
            ("compare_lifted_area_cm2", "lifted_area_cm2"),
            ("compare_folds", "folds"),
        ] {
            metrics.insert(k.into(), cm.get(from).copied().flatten());
        }
        metrics.insert(
            "rms_difference_mm".into(),
            (!failed && main.failure.is_none()).then(|| main.rms_distance(c) * 1e3),
        );
        let compared = Comparison {
            solver: c.solver.into(),
            dt_s: c.dt,
            steps: c.steps,
            simulated_s: c.time,
            wall_s: c.wall.as_secs_f64(),
            pressure_s: c.pressure_wall.as_secs_f64(),
            failure: c.failure.as_ref().map(|f| f.error.to_string()),
            convergence: Some(convergence(c)),
        };
        warnings.extend(compared.convergence_warning());
        if let Some(f) = &c.failure {
            warnings.push(format!(
                "the compared {} run stopped at t = {:.3} s: {}",
                c.solver, f.time, f.error
            ));
        }
        comparison = Some(compared);
    }
    let charts = charts(&main, compared.as_ref());
    let mut cloth = Animation::default();
    for (t, frame) in &main.frames {
        cloth.push(*t, frame.iter().map(|p| [p.x, p.z, -p.y]).collect());
    }
    let wet = WetOutputs {
        series_csv,
        charts,
        final_z_up: z_up(&main),
        compare_z_up: compared.as_ref().map(z_up),
        size: spec.scene.size,
    };
    let mut timings = Timings::default();
    timings.solver.pressure = main.pressure_wall;
    Ok(Simulated {
        fabric: String::new(),
        cloth_triangles: main.triangles.clone(),
        cloth,
        solid: None,
        steps: main.steps,
        dt: main.dt,
        simulated: main.time,
        wall_seconds: main.wall.as_secs_f64(),
        timings,
        metrics,
        warnings,
        failure: main
            .failure
            .as_ref()
            .map(|f| format!("t = {:.4} s: {}", f.time, f.error)),
        outputs: KindOutputs::Wet(Box::new(wet), comparison),
        convergence: Some(convergence(&main)),
        detail: crate::outcome::ClothDetail::default(),
    })
}

/// Tent height and pressure over time, one curve per run.
fn charts(main: &WetRun, compared: Option<&WetRun>) -> Vec<(&'static str, Chart)> {
    let runs: Vec<&WetRun> = std::iter::once(main).chain(compared).collect();
    let curve =
        |r: &WetRun, f: &dyn Fn(&atelier_solver::wet::scene::WetSample) -> Option<f64>| Series {
            name: format!("{} (Δt {:.3} ms)", r.solver, r.dt * 1e3),
            points: r
                .samples
                .iter()
                .filter_map(|s| f(s).map(|v| (s.time, v)))
                .collect(),
        };
    let mut out = vec![(
        "tent.png",
        Chart {
            title: "tent height (highest free node above the plane)".into(),
            x_label: "time (s)".into(),
            y_label: "height (mm)".into(),
            series: runs
                .iter()
                .map(|r| curve(r, &|s| Some(s.tent_height * 1e3)))
                .collect(),
            markers: None,
            equal_aspect: false,
        },
    )];
    if main.samples.iter().any(|s| s.pressure.is_some()) {
        out.push((
            "pressure.png",
            Chart {
                title: "trapped air: pressure above the atmosphere".into(),
                x_label: "time (s)".into(),
                y_label: "P_b − P_a (Pa)".into(),
                series: runs
                    .iter()
                    .map(|r| curve(r, &|s| s.pressure.map(|p| p - ATMOSPHERE)))
                    .collect(),
                markers: None,
                equal_aspect: false,
            },
        ));
    }
    out
}
