//! Run a scenario ([`crate::scenario`]) into an output folder: simulate it ([`simulate`]), then
//! write the report (`report.json`, [`crate::report`]), the final state as OBJ and PLY, the whole
//! run as an animated glTF binary and pictures of the final state ([`run`]).
//!
//! This file dispatches a scenario to its kind and writes the report; the validation scenes
//! are in `validation`, the exports and pictures in `write`.
//!
//! Every file is written under a temporary name beside its target and renamed when complete;
//! the report is written last, so a folder whose `report.json` is new holds a complete set. A
//! run that fails part-way (a step diverges) still writes everything, up to its last good frame,
//! with the failure in the report.
//!
//! Frames: garment scenes are in the body frame (x the body's left, y up, z forward). The
//! validation scenes (drape, cantilever, catenary) are simulated with z up, as in the solver's
//! scenes; their outputs are turned into the same y-up frame, (x, y, z) → (x, z, −y), so that
//! every output has y up as glTF expects.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use atelier_fabric::Fabric;
use nalgebra::Vector3;

use crate::convergence::UNCONVERGED_FRACTION;
use crate::export::{Animation, FrameSelection};
pub use crate::outcome::{KindOutputs, RunError, Simulated, Solid};
use crate::pipeline::run_garment;
use crate::report::Report;
pub use crate::report::check_expectations;
use crate::scenario::{Scenario, ScenarioKind};
use validation::{cantilever, catenary, drape, kes_bending, kes_tensile};
use write::write_outputs;

mod validation;
mod write;

/// Options of [`run`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RunOptions {
    /// Frames kept in the glTF animation (default: all).
    pub frames: FrameSelection,
    /// Width and height of each view of the picture, pixels (default 400 × 600).
    pub picture: (usize, usize),
}

impl Default for RunOptions {
    fn default() -> Self {
        Self {
            frames: FrameSelection::All,
            picture: (400, 600),
        }
    }
}

/// The file names a run writes into its folder.
pub mod outputs {
    /// The report.
    pub const REPORT: &str = "report.json";
    /// The final state, Wavefront OBJ.
    pub const OBJ: &str = "final.obj";
    /// The final state, binary PLY.
    pub const PLY: &str = "final.ply";
    /// The whole run, glTF binary.
    pub const GLB: &str = "run.glb";
    /// Front and side views of the final state.
    pub const PICTURE: &str = "final.png";
    /// View from above (drape tests).
    pub const TOP: &str = "top.png";
    /// The compared run's final state (wet scenes).
    pub const COMPARE: &str = "compare.png";
    /// The series of a wet scene, one row per sample of each run.
    pub const SERIES: &str = "series.csv";
    /// Tent height over time (wet scenes).
    pub const TENT: &str = "tent.png";
    /// Trapped air's pressure over time (wet scenes).
    pub const PRESSURE: &str = "pressure.png";
    /// String identification: the fitted model (RON).
    pub const PARAMETERS: &str = "parameters.ron";
    /// Try-on: the garment over the photograph.
    pub const COMPOSITE: &str = "composite.png";
    /// Try-on: the fitted silhouette over the mask.
    pub const OVERLAY: &str = "overlay.png";
    /// Try-on: the fitted pose, camera and sizes (RON).
    pub const FITTED_POSE: &str = "fitted_pose.ron";
    /// Try-on: the pixels the garment covers, white on black.
    pub const FOOTPRINT: &str = "footprint.png";
    /// Every name above.
    pub const ALL: [&str; 15] = [
        REPORT,
        OBJ,
        PLY,
        GLB,
        PICTURE,
        TOP,
        COMPARE,
        SERIES,
        TENT,
        PRESSURE,
        PARAMETERS,
        COMPOSITE,
        OVERLAY,
        FITTED_POSE,
        FOOTPRINT,
    ];
}

/// Run `scenario` (read from `file`, whose folder `base` resolves its relative paths) into the
/// folder `out` (created if missing): simulate, check the expectations, write the outputs and
/// the report. `progress` receives the fraction of simulated time done. Returns the report; a
/// run that diverged returns `Ok` with the failure in the report.
pub fn run(
    scenario: &Scenario,
    file: Option<&Path>,
    base: &Path,
    out: &Path,
    options: &RunOptions,
    progress: &mut dyn FnMut(f64),
) -> Result<Report, RunError> {
    prepare_folder(out)?;
    let clock = Instant::now();
    let sim = simulate(scenario, base, progress)?;
    let setup_seconds = (clock.elapsed().as_secs_f64() - sim.wall_seconds).max(0.0);
    write_run(scenario, file, &sim, setup_seconds, out, options, |_| {})
}

/// Write a simulated run's outputs and its report into `out` (which [`prepare_folder`] made):
/// what [`run`] does after simulating. `extend` adds to the report before it is written.
pub fn write_run(
    scenario: &Scenario,
    file: Option<&Path>,
    sim: &Simulated,
    setup_seconds: f64,
    out: &Path,
    options: &RunOptions,
    extend: impl FnOnce(&mut Report),
) -> Result<Report, RunError> {
    let mut report = Report::new(scenario, file, sim);
    report.setup_s = setup_seconds;
    let mut options = *options;
    if !matches!(scenario.kind, ScenarioKind::Garment(_)) {
        // The validation scenes are wider than tall: square views.
        options.picture.1 = options.picture.0;
    }
    let style = match scenario.kind {
        ScenarioKind::Garment(_) => PictureStyle::Plain,
        ScenarioKind::Drape(_) => PictureStyle::WithTop,
        ScenarioKind::Cantilever(_)
        | ScenarioKind::Catenary(_)
        | ScenarioKind::KesTensile(_)
        | ScenarioKind::KesBending(_) => PictureStyle::Tilted,
        ScenarioKind::Wet(_) => PictureStyle::Wet,
        ScenarioKind::StringFit(_) => PictureStyle::Tilted,
    };
    let (written, warnings) = write_outputs(sim, out, &options, style)?;
    report.outputs = written;
    report.warnings.extend(warnings);
    extend(&mut report);
    report.write(&out.join(outputs::REPORT))?;
    Ok(report)
}

/// How the final state is pictured.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum PictureStyle {
    /// Front and side.
    Plain,
    /// Front and side, and a view from above (`top.png`).
    WithTop,
    /// Front and side of the scene tilted 35° about x (strips).
    Tilted,
    /// A wet cloth: seen from above at an angle, and its height map (the compared run's in
    /// `compare.png`).
    Wet,
}

/// Create the output folder and remove temporary files a killed run may have left beside the
/// outputs.
pub fn prepare_folder(out: &Path) -> Result<(), RunError> {
    std::fs::create_dir_all(out).map_err(|source| RunError::Output {
        path: out.to_path_buf(),
        source,
    })?;
    let entries = std::fs::read_dir(out).map_err(|source| RunError::Output {
        path: out.to_path_buf(),
        source,
    })?;
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        let stale = outputs::ALL.iter().any(|target| {
            let stem = target.split('.').next().unwrap_or(target);
            name.starts_with(&format!(".{stem}.tmp-"))
        });
        if stale {
            let _ = std::fs::remove_file(entry.path());
        }
    }
    Ok(())
}

/// Simulate a scenario (nothing is written). `base` resolves its relative paths.
pub fn simulate(
    scenario: &Scenario,
    base: &Path,
    progress: &mut dyn FnMut(f64),
) -> Result<Simulated, RunError> {
    let Some(fabric_file) = scenario.kind.fabric() else {
        // No cloth: the string identification.
        let ScenarioKind::StringFit(spec) = &scenario.kind else {
            unreachable!("every other kind names a fabric")
        };
        let sim = crate::fit::simulate(spec, base)?;
        progress(1.0);
        return Ok(sim);
    };
    let fabric = Fabric::load(&base.join(fabric_file))?;
    simulate_with_fabric(scenario, &fabric, base, progress)
}

/// Simulate a scenario with `fabric` in place of the fabric file it names (nothing is written;
/// a garment scene still reads its own fabric file, which its panels name): what the Python
/// bindings run for a fabric built in memory. `base` resolves the other relative paths.
pub fn simulate_with_fabric(
    scenario: &Scenario,
    fabric: &Fabric,
    base: &Path,
    progress: &mut dyn FnMut(f64),
) -> Result<Simulated, RunError> {
    let mut sim = match &scenario.kind {
        ScenarioKind::Garment(spec) => garment(spec, base, progress)?,
        ScenarioKind::Drape(spec) => drape(spec, fabric, progress)?,
        ScenarioKind::Cantilever(spec) => cantilever(spec, fabric, progress)?,
        ScenarioKind::Catenary(spec) => catenary(spec, fabric, progress)?,
        ScenarioKind::KesTensile(spec) => kes_tensile(spec, fabric)?,
        ScenarioKind::KesBending(spec) => kes_bending(spec, fabric)?,
        ScenarioKind::Wet(spec) => crate::wet::simulate(spec, fabric)?,
        ScenarioKind::StringFit(spec) => crate::fit::simulate(spec, base)?,
    };
    sim.fabric = fabric.name.clone();
    finish_simulated(&mut sim);
    progress(1.0);
    Ok(sim)
}

/// Simulate a garment scene already set up (nothing is written): the garment kind of
/// [`simulate`] with the scene's own body and motion.
pub fn simulate_scene(
    scene: crate::scene::Scene,
    progress: &mut dyn FnMut(f64),
) -> Result<Simulated, RunError> {
    let dt = scene.settings.dt;
    let fabric = scene.garment.fabric.name.clone();
    let run = crate::pipeline::run_scene(scene, progress)?;
    let mut sim = garment_simulated(run, dt);
    sim.fabric = fabric;
    finish_simulated(&mut sim);
    progress(1.0);
    Ok(sim)
}

/// The measurements every run reports, and the frames cut at the first non-finite one.
fn finish_simulated(sim: &mut Simulated) {
    trim_non_finite(sim);
    sim.metrics
        .insert("nodes".into(), Some(node_count(sim) as f64));
    sim.metrics.insert(
        "cloth_triangles".into(),
        Some(sim.cloth_triangles.len() as f64),
    );
    sim.simulated = round_time(sim.simulated);
    sim.metrics
        .insert("simulated_s".into(), Some(sim.simulated));
    sim.metrics
        .insert("frames".into(), Some(sim.cloth.frames.len() as f64));
    if let Some(c) = &sim.convergence {
        sim.metrics
            .insert(UNCONVERGED_FRACTION.into(), c.unconverged_fraction());
        sim.warnings.extend(c.warning());
    }
}

fn node_count(sim: &Simulated) -> usize {
    sim.cloth.frames.first().map_or(0, Vec::len)
}

/// Simulated time rounded to a nanosecond (summed steps carry rounding noise).
fn round_time(t: f64) -> f64 {
    (t * 1e9).round() / 1e9
}

/// Drop frames holding a non-finite coordinate (and every frame after one): the outputs stop
/// at the last good frame.
fn trim_non_finite(sim: &mut Simulated) {
    let bad = sim
        .cloth
        .frames
        .iter()
        .position(|f| f.iter().flatten().any(|v| !v.is_finite()));
    if let Some(k) = bad {
        let k = k.max(1);
        sim.cloth.frames.truncate(k);
        sim.cloth.times.truncate(k);
        sim.warnings.push(format!(
            "frames from t = {:.3} s on hold non-finite positions and were dropped",
            sim.cloth.times.last().copied().unwrap_or(0.0)
        ));
        if sim.failure.is_none() {
            sim.failure = Some("non-finite positions".into());
        }
    }
}

fn to_y_up(p: &Vector3<f64>) -> [f64; 3] {
    [p.x, p.z, -p.y]
}

fn garment(
    spec: &crate::scene::GarmentSpec,
    base: &Path,
    progress: &mut dyn FnMut(f64),
) -> Result<Simulated, RunError> {
    let run = run_garment(spec, base, progress)?;
    Ok(garment_simulated(run, spec.settings.dt))
}

/// A garment run as a [`Simulated`]: frames, body, metrics and warnings.
fn garment_simulated(run: crate::pipeline::GarmentRun, dt: f64) -> Simulated {
    let speed = run.final_rms_speed();
    let mut cloth = Animation::default();
    let mut body = Animation::default();
    let strain_error: Vec<Vec<f32>> = run.frames.iter().map(|f| f.strain_error.clone()).collect();
    let n = run.frames.first().map_or(0, |f| f.cloth.len());
    let detail = crate::outcome::ClothDetail {
        strain_error: if strain_error.iter().all(|s| s.len() == n) {
            strain_error
        } else {
            Vec::new()
        },
        panels: run.panels.0.clone(),
        node_panel: run.panels.1.clone(),
    };
    for f in &run.frames {
        cloth.push(f.time, f.cloth.clone());
        body.push(f.time, f.body.clone());
    }
    let body_moves = body.frames.iter().any(|f| *f != body.frames[0]);
    if !body_moves {
        body = Animation::still(body.frames[0].clone());
    }
    let last = run.frames.last().map(|f| f.time).unwrap_or(0.0);
    let lowest = run
        .frames
        .last()
        .map(|f| f.cloth.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min));
    let mut warnings = run.warnings;
    // A garment the body does not hold (too large for it, or a tube with nothing to rest on)
    // slides off and falls without end (there is no floor): say so instead of drawing it.
    let below = run.frames.last().map_or(0, |f| {
        let feet = f.body.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min);
        let fallen = f
            .cloth
            .iter()
            .filter(|p| p[1] < feet - FALLEN_BELOW_FEET)
            .count();
        if fallen > 0 {
            warnings.push(format!(
                "{fallen} of {} cloth nodes ended more than {:.0} cm below the body's lowest point (y = {feet:.3} m; lowest node {:.3} m): the body does not hold the garment (too large for it, or nothing to rest on) and it falls",
                f.cloth.len(),
                FALLEN_BELOW_FEET * 100.0,
                lowest.unwrap_or(feet)
            ));
        }
        fallen
    });
    let mut metrics = BTreeMap::new();
    let mut put = |k: &str, v: Option<f64>| {
        metrics.insert(k.to_string(), v);
    };
    put("body_triangles", Some(run.body_triangles.len() as f64));
    put("pairs", Some(run.pairs.1 as f64));
    put("pairs_sewn", Some(run.pairs.0 as f64));
    put(
        "unsewn_pairs",
        Some(run.pairs.1.saturating_sub(run.pairs.0) as f64),
    );
    put("sewn_at_s", run.sewn_at.map(round_time));
    put("max_penetration_m", Some(run.max_penetration));
    put(
        "steps_with_penetration",
        Some(run.steps_with_penetration as f64),
    );
    put("nodes_inside_at_end", Some(run.inside_at_end as f64));
    put("max_strain_error", Some(run.max_strain_error.0));
    put("final_strain_error", Some(run.max_strain_error.1));
    put("kinetic_energy_j", Some(run.kinetic_energy));
    put("max_motion_kinetic_energy_j", Some(run.max_motion_energy));
    put("lowest_node_m", lowest);
    put("nodes_below_body", Some(below as f64));
    let hem = run.frames.last().and_then(|f| {
        atelier_solver::metrics::hem_extent(&f.cloth, atelier_solver::metrics::HEM_BAND)
    });
    put("hem_width_m", hem.map(|h| h.width));
    put("hem_depth_m", hem.map(|h| h.depth));
    let showing = run.frames.last().map(|f| {
        atelier_solver::show_through::show_through(
            &f.body,
            &run.body_triangles,
            &f.cloth,
            &run.cloth_triangles,
            atelier_solver::show_through::SHOW_THROUGH_REACH,
        )
    });
    put(
        "body_vertices_showing",
        showing.as_ref().map(|s| s.vertices.len() as f64),
    );
    put("body_showing_depth_m", showing.map(|s| s.deepest));
    put("final_rms_speed_m_s", speed);
    Simulated {
        fabric: String::new(),
        cloth_triangles: run.cloth_triangles,
        cloth,
        solid: Some(Solid {
            name: "body",
            triangles: run.body_triangles,
            motion: body,
        }),
        steps: run.steps,
        dt,
        simulated: last,
        wall_seconds: run.wall_seconds,
        timings: run.timings,
        metrics,
        warnings,
        failure: run.failure,
        outputs: KindOutputs::Cloth,
        convergence: Some(run.convergence),
        detail,
    }
}

/// How far below the body's lowest point a garment's node counts as fallen off it, m.
const FALLEN_BELOW_FEET: f64 = 0.05;

/// The folder relative paths of a scenario file are resolved against: the file's own folder.
pub fn base_of(file: &Path) -> PathBuf {
    file.parent()
        .map(Path::to_path_buf)
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or_else(|| PathBuf::from("."))
}
