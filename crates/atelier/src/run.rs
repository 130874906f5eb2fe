//! Run a scenario ([`crate::scenario`]) into an output folder: simulate it ([`simulate`]), then
//! write the report (`report.json`, [`crate::report`]), the final state as OBJ and PLY, the whole
//! run as an animated glTF binary and pictures of the final state ([`run`]).
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
use std::time::{Duration, Instant};

use atelier_fabric::{AnisotropyForm, Fabric};
use atelier_grid::{ClothTopology, StructuredGrid};
use atelier_solver::scenes::DrapeScene;
use atelier_solver::{Cloth, ClothState, PinMotion, Solver, StepParams};
use nalgebra::Vector3;

use crate::convergence::{Convergence, Tally, UNCONVERGED_FRACTION, solvers};
use crate::export::{
    Animation, ExportError, FrameSelection, GlbOptions, MeshPart, write_glb, write_obj, write_ply,
};
pub use crate::outcome::{RunError, Simulated, Solid};
use crate::pipeline::run_garment;
use crate::report::Report;
pub use crate::report::check_expectations;
use crate::scenario::{
    CantileverSpec, CatenarySpec, DrapeSpec, KesBendingSpec, KesTensileSpec, Scenario,
    ScenarioKind, StripDirection, Tester,
};
use crate::simulation::Timings;

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

/// Colour of the cloth in exports and pictures.
const CLOTH_COLOUR: [f32; 3] = [0.85, 0.35, 0.25];
/// Colour of the body or tester.
const SOLID_COLOUR: [f32; 3] = [0.75, 0.75, 0.78];

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

/// Write the exports and pictures; returns the names written and warnings for exports that
/// could not be made (other than for I/O, which is an error).
fn write_outputs(
    sim: &Simulated,
    out: &Path,
    options: &RunOptions,
    style: PictureStyle,
) -> Result<(Vec<String>, Vec<String>), RunError> {
    let mut written = Vec::new();
    let mut warnings = Vec::new();
    if let Some(fit) = &sim.fit {
        // A string identification: its parameters and the shapes' chart, no cloth.
        let (w, h) = options.picture;
        let io = |path: PathBuf| move |source| RunError::Output { path, source };
        let path = out.join(outputs::PARAMETERS);
        atelier_fabric::files::write_atomic(&path, fit.parameters_ron.as_bytes())
            .map_err(io(path))?;
        written.push(outputs::PARAMETERS.into());
        if let Some(chart) = &sim.chart {
            let size = (2 * w as u32, h as u32);
            write_chart(
                out,
                outputs::PICTURE,
                chart,
                size,
                &mut written,
                &mut warnings,
            )?;
        }
        return Ok((written, warnings));
    }
    let Some(final_cloth) = sim.cloth.last() else {
        warnings.push("no frame to write".into());
        return Ok((written, warnings));
    };
    let cloth_part = MeshPart::cloth("cloth", &sim.cloth_triangles, CLOTH_COLOUR);
    let solid_part = sim
        .solid
        .as_ref()
        .map(|s| (MeshPart::body(s.name, &s.triangles, SOLID_COLOUR), s));
    let mut still: Vec<(MeshPart<'_>, &[[f64; 3]])> = vec![(cloth_part, final_cloth)];
    if let Some((part, s)) = &solid_part
        && let Some(last) = s.motion.last()
    {
        still.push((*part, last));
    }
    let mut export = |name: &str, result: Result<(), ExportError>| -> Result<(), RunError> {
        match result {
            Ok(()) => {
                written.push(name.to_string());
                Ok(())
            }
            Err(ExportError::Io { path, source }) => Err(RunError::Output { path, source }),
            Err(e) => {
                warnings.push(format!("{name} not written: {e}"));
                Ok(())
            }
        }
    };
    export(outputs::OBJ, write_obj(&out.join(outputs::OBJ), &still))?;
    export(outputs::PLY, write_ply(&out.join(outputs::PLY), &still))?;
    let mut animated: Vec<(MeshPart<'_>, &Animation)> = vec![(cloth_part, &sim.cloth)];
    if let Some((part, s)) = &solid_part {
        animated.push((*part, &s.motion));
    }
    let glb = GlbOptions {
        frames: options.frames,
        ..GlbOptions::default()
    };
    export(
        outputs::GLB,
        write_glb(&out.join(outputs::GLB), &animated, &glb),
    )?;

    let (w, h) = options.picture;
    if let Some(wet) = &sim.wet {
        write_wet_outputs(
            wet,
            &sim.cloth_triangles,
            out,
            (w, h),
            &mut written,
            &mut warnings,
        )?;
        return Ok((written, warnings));
    }
    let solid_final = solid_part
        .as_ref()
        .and_then(|(_, s)| s.motion.last().map(|p| (p, s.triangles.as_slice())));
    let draw = |map: &dyn Fn(&[f64; 3]) -> [f64; 3], w: usize, h: usize| {
        let cloth: Vec<[f64; 3]> = final_cloth.iter().map(map).collect();
        let solid_points: Option<Vec<[f64; 3]>> =
            solid_final.map(|(p, _)| p.iter().map(map).collect());
        let solid = solid_points.as_deref().zip(solid_final.map(|(_, t)| t));
        crate::picture::garment_views((&cloth, &sim.cloth_triangles), solid, w, h)
    };
    let pixels = match style {
        // A strip is seen edge-on from the front: tilt it 35° about x (its top towards the
        // camera) so that its droop and its surface both show.
        PictureStyle::Tilted => {
            let (s, c) = 35f64.to_radians().sin_cos();
            draw(&|p| [p[0], p[1] * c - p[2] * s, p[1] * s + p[2] * c], w, h)
        }
        _ => draw(&|p| *p, w, h),
    };
    match &sim.chart {
        Some(chart) if crate::chart::DRAWN => {
            let size = (2 * w as u32, h as u32);
            write_chart(
                out,
                outputs::PICTURE,
                chart,
                size,
                &mut written,
                &mut warnings,
            )?;
        }
        _ => {
            // Without the `charts` feature a virtual test's chart gives way to the cloth's picture.
            let path = out.join(outputs::PICTURE);
            crate::picture::write_png(&path, &pixels, 2 * w, h, [1.0; 3])
                .map_err(|source| RunError::Output { path, source })?;
            written.push(outputs::PICTURE.into());
        }
    }
    if style == PictureStyle::WithTop {
        // Seen from above: screen x = x, screen y = −z (forward is down), depth y.
        let pixels = draw(&|p| [p[0], -p[2], p[1]], h, h);
        // Keep the left (front) half: the view from above.
        let mut top = Vec::with_capacity(h * h);
        for row in pixels.chunks(2 * h) {
            top.extend_from_slice(&row[..h]);
        }
        let path = out.join(outputs::TOP);
        crate::picture::write_png(&path, &top, h, h, [1.0; 3])
            .map_err(|source| RunError::Output { path, source })?;
        written.push(outputs::TOP.into());
    }
    Ok((written, warnings))
}

/// The pictures, series and charts of a wet scene.
fn write_wet_outputs(
    wet: &crate::wet::WetOutputs,
    triangles: &[[u32; 3]],
    out: &Path,
    (w, h): (usize, usize),
    written: &mut Vec<String>,
    warnings: &mut Vec<String>,
) -> Result<(), RunError> {
    let io = |path: PathBuf| move |source| RunError::Output { path, source };
    // One height scale for both runs' pictures.
    let top = std::iter::once(&wet.final_z_up)
        .chain(wet.compare_z_up.as_ref())
        .flatten()
        .map(|p| p[2])
        .fold(0.01, f64::max);
    for (name, positions) in std::iter::once((outputs::PICTURE, &wet.final_z_up))
        .chain(wet.compare_z_up.as_ref().map(|c| (outputs::COMPARE, c)))
    {
        let pixels = crate::picture::wet_views((positions, triangles), wet.size, top, w, h);
        let path = out.join(name);
        crate::picture::write_png(&path, &pixels, 2 * w, h, [1.0; 3]).map_err(io(path))?;
        written.push(name.into());
    }
    let path = out.join(outputs::SERIES);
    atelier_fabric::files::write_atomic(&path, wet.series_csv.as_bytes()).map_err(io(path))?;
    written.push(outputs::SERIES.into());
    for (name, chart) in &wet.charts {
        write_chart(
            out,
            name,
            chart,
            (2 * w as u32, h as u32),
            written,
            warnings,
        )?;
    }
    Ok(())
}

/// Draw `chart` into `out/name` and list it as written; without the `charts` feature, a warning
/// that it was left out instead.
fn write_chart(
    out: &Path,
    name: &str,
    chart: &crate::chart::Chart,
    size: (u32, u32),
    written: &mut Vec<String>,
    warnings: &mut Vec<String>,
) -> Result<(), RunError> {
    #[cfg(feature = "charts")]
    {
        let _ = warnings;
        let path = out.join(name);
        crate::chart::write_chart(&path, chart, size)
            .map_err(|source| RunError::Output { path, source })?;
        written.push(name.into());
    }
    #[cfg(not(feature = "charts"))]
    {
        let _ = (out, chart, size, written);
        warnings.push(format!(
            "{name} ({}) not drawn: atelier was built without its `charts` feature",
            chart.title
        ));
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
    let fabric_path = base.join(fabric_file);
    let fabric = Fabric::load(&fabric_path).map_err(|e| RunError::Setup(e.to_string()))?;
    let mut sim = match &scenario.kind {
        ScenarioKind::Garment(spec) => garment(spec, base, progress)?,
        ScenarioKind::Drape(spec) => drape(spec, &fabric, progress)?,
        ScenarioKind::Cantilever(spec) => cantilever(spec, &fabric, progress)?,
        ScenarioKind::Catenary(spec) => catenary(spec, &fabric, progress)?,
        ScenarioKind::KesTensile(spec) => kes_tensile(spec, &fabric)?,
        ScenarioKind::KesBending(spec) => kes_bending(spec, &fabric)?,
        ScenarioKind::Wet(spec) => crate::wet::simulate(spec, &fabric)?,
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
    let run =
        crate::pipeline::run_scene(scene, progress).map_err(|e| RunError::Setup(e.to_string()))?;
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
    let run = run_garment(spec, base, progress).map_err(|e| RunError::Setup(e.to_string()))?;
    Ok(garment_simulated(run, spec.settings.dt))
}

/// A garment run as a [`Simulated`]: frames, body, metrics and warnings.
fn garment_simulated(run: crate::pipeline::GarmentRun, dt: f64) -> Simulated {
    let speed = run.final_rms_speed();
    let mut cloth = Animation::default();
    let mut body = Animation::default();
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
        chart: None,
        wet: None,
        fit: None,
        comparison: None,
        convergence: Some(run.convergence),
    }
}

/// How far below the body's lowest point a garment's node counts as fallen off it, m.
const FALLEN_BELOW_FEET: f64 = 0.05;

/// A stepping loop shared by the validation scenes: steps `state` until `done` says so (or a
/// step fails), records a frame every `interval` and keeps the last good positions.
struct Stepper {
    frames: Animation,
    interval: f64,
    next_frame: f64,
    steps: usize,
    wall: Duration,
    timings: Timings,
    max_strain_error: f64,
    max_speed: f64,
    failure: Option<String>,
    last_good: Vec<Vector3<f64>>,
    tally: Tally,
    /// The shape tolerance of the steps.
    tolerance: f64,
}

impl Stepper {
    fn new(state: &ClothState, interval: f64) -> Self {
        let mut frames = Animation::default();
        frames.push(state.time, state.positions.iter().map(to_y_up).collect());
        Self {
            frames,
            interval,
            next_frame: state.time + interval,
            steps: 0,
            wall: Duration::ZERO,
            timings: Timings::default(),
            max_strain_error: 0.0,
            max_speed: 0.0,
            failure: None,
            last_good: state.positions.clone(),
            tally: Tally::default(),
            tolerance: StepParams::default().shape_tolerance,
        }
    }

    /// One step; false when it failed (the state is then restored to the last good positions).
    fn step(
        &mut self,
        solver: &mut Solver,
        cloth: &Cloth,
        state: &mut ClothState,
        params: &StepParams,
    ) -> bool {
        self.last_good.copy_from_slice(&state.positions);
        let t = state.time;
        let clock = Instant::now();
        let result = solver.step(cloth, state, params);
        self.wall += clock.elapsed();
        match result {
            Ok(r) => {
                self.steps += 1;
                self.tally.add(&r, t, None);
                self.tolerance = params.shape_tolerance;
                self.timings.add(&Timings {
                    solver: r.timings,
                    ..Timings::default()
                });
                self.max_strain_error = self.max_strain_error.max(r.max_strain_error);
                self.max_speed = r.max_speed;
                if state.time + 1e-9 * params.dt >= self.next_frame {
                    self.frames
                        .push(state.time, state.positions.iter().map(to_y_up).collect());
                    self.next_frame += self.interval;
                }
                true
            }
            Err(e) => {
                self.failure = Some(format!("step at time {t:.4} s: {e}"));
                state.positions.copy_from_slice(&self.last_good);
                state.time = t;
                false
            }
        }
    }

    /// Record the final state unless it is the last frame already.
    fn finish(&mut self, state: &ClothState) {
        if self
            .frames
            .times
            .last()
            .is_none_or(|&t| state.time > t + 1e-12)
        {
            self.frames
                .push(state.time, state.positions.iter().map(to_y_up).collect());
        }
    }

    fn into_simulated(
        self,
        cloth: &Cloth,
        state: &ClothState,
        dt: f64,
        solid: Option<Solid>,
        mut metrics: BTreeMap<String, Option<f64>>,
    ) -> Simulated {
        metrics.insert("max_strain_error".into(), Some(self.max_strain_error));
        let ke = if self.failure.is_some() {
            None
        } else {
            Some(state.kinetic_energy(cloth))
        };
        metrics.insert("kinetic_energy_j".into(), ke);
        Simulated {
            fabric: String::new(),
            cloth_triangles: cloth.topology().triangles().to_vec(),
            cloth: self.frames,
            solid,
            steps: self.steps,
            dt,
            simulated: state.time,
            wall_seconds: self.wall.as_secs_f64(),
            timings: self.timings,
            metrics,
            warnings: Vec::new(),
            failure: self.failure,
            chart: None,
            wet: None,
            fit: None,
            comparison: None,
            convergence: Some(self.tally.convergence(self.tolerance)),
        }
    }
}

/// RMS speed of the free nodes, mass-weighted, m/s (the drape's rest test).
fn rms_speed(cloth: &Cloth, state: &ClothState) -> f64 {
    let (mut e, mut m) = (0.0, 0.0);
    for (i, (v, mass)) in state.velocities.iter().zip(cloth.masses()).enumerate() {
        if !cloth.is_pinned(i) {
            e += mass * v.norm_squared();
            m += mass;
        }
    }
    if m > 0.0 { (e / m).sqrt() } else { 0.0 }
}

fn drape(
    spec: &DrapeSpec,
    fabric: &Fabric,
    progress: &mut dyn FnMut(f64),
) -> Result<Simulated, RunError> {
    let (preset, dt) = match spec.tester {
        Tester::Jis => (DrapeScene::jis(72, 8), 1e-3),
        Tester::Thesis => (DrapeScene::thesis(), 2.5e-3),
    };
    let mut scene = DrapeScene {
        n_around: spec.n_around.unwrap_or(preset.n_around),
        n_rings: spec.n_rings.unwrap_or(preset.n_rings),
        perturbation: spec.perturbation,
        seed: spec.seed,
        ..preset
    };
    scene.cloth_options.form = spec.form;
    let (cloth, mut state) = scene
        .build(fabric)
        .map_err(|e| RunError::Setup(format!("drape scene: {e}")))?;
    let params = StepParams {
        dt: spec.dt.unwrap_or(dt),
        ..spec.step.clone()
    };
    params
        .validate()
        .map_err(|e| RunError::Setup(format!("drape scene: {e}")))?;
    // The rest criterion of `run_drape` (RestCriterion::default()).
    let stop = atelier_solver::scenes::RestCriterion::default();
    let eps = 1e-9 * params.dt;
    let mut stepper = Stepper::new(&state, spec.frame_interval);
    let mut solver = Solver::new();
    let mut below_since: Option<f64> = None;
    let mut settled = false;
    while state.time < spec.max_time - eps {
        if !stepper.step(&mut solver, &cloth, &mut state, &params) {
            break;
        }
        progress(state.time / spec.max_time);
        if spec.until_rest {
            if rms_speed(&cloth, &state) < stop.rest_speed {
                let since = *below_since.get_or_insert(state.time);
                if state.time >= stop.min_time - eps && state.time - since >= stop.hold_time - eps {
                    settled = true;
                    break;
                }
            } else {
                below_since = None;
            }
        }
    }
    stepper.finish(&state);
    let mut metrics = BTreeMap::new();
    let ok = stepper.failure.is_none();
    let m = scene.measure(&cloth, &state);
    let mut put = |k: &str, v: f64| {
        metrics.insert(k.to_string(), ok.then_some(v));
    };
    put("drape_coefficient_percent", m.drape_coefficient);
    put("node_count", m.nodes as f64);
    put("shadow_area_m2", m.shadow_area);
    put("settled", if settled { 1.0 } else { 0.0 });
    put("rms_speed_m_s", rms_speed(&cloth, &state));
    put("min_edge_radius_m", m.min_edge_radius);
    put("max_edge_radius_m", m.max_edge_radius);
    let mut warnings = Vec::new();
    if spec.until_rest && !settled && ok {
        warnings.push(format!(
            "not at rest after {:.2} s: measured at the time cap",
            spec.max_time
        ));
    }
    let support = support_stand(
        scene.support_radius(),
        1.2 * (scene.specimen_radius() - scene.support_radius()),
    );
    let mut sim = stepper.into_simulated(&cloth, &state, params.dt, Some(support), metrics);
    sim.warnings.extend(warnings);
    Ok(sim)
}

/// The drape tester's support: a closed cylinder of the support's radius and height `depth`
/// under the specimen, top at z = 0 (y-up frame in the outputs).
fn support_stand(radius: f64, depth: f64) -> Solid {
    let n = 48;
    let mut v: Vec<[f64; 3]> = Vec::new();
    for k in 0..n {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        let (x, y) = (radius * a.cos(), radius * a.sin());
        v.push(to_y_up(&Vector3::new(x, y, 0.0)));
        v.push(to_y_up(&Vector3::new(x, y, -depth)));
    }
    let top = v.len() as u32;
    v.push(to_y_up(&Vector3::new(0.0, 0.0, 0.0)));
    let bottom = top + 1;
    v.push(to_y_up(&Vector3::new(0.0, 0.0, -depth)));
    let mut t = Vec::new();
    for k in 0..n as u32 {
        let j = (k + 1) % n as u32;
        let (a0, a1, b0, b1) = (2 * k, 2 * k + 1, 2 * j, 2 * j + 1);
        // In the z-up frame counter-clockwise about +z; the map to y up is a rotation.
        t.push([a0, a1, b1]);
        t.push([a0, b1, b0]);
        t.push([top, a0, b0]);
        t.push([bottom, b1, a1]);
    }
    Solid {
        name: "support",
        triangles: t,
        motion: Animation::still(v),
    }
}

/// An axis-aligned box (z-up frame), outward triangles.
fn block(lo: [f64; 3], hi: [f64; 3], name: &'static str) -> Solid {
    let mut v = Vec::new();
    for k in 0..8 {
        let p = Vector3::new(
            if k & 1 == 0 { lo[0] } else { hi[0] },
            if k & 2 == 0 { lo[1] } else { hi[1] },
            if k & 4 == 0 { lo[2] } else { hi[2] },
        );
        v.push(to_y_up(&p));
    }
    // Faces as quads (outward, counter-clockwise seen from outside).
    let quads = [
        [0, 2, 3, 1], // z lo
        [4, 5, 7, 6], // z hi
        [0, 1, 5, 4], // y lo
        [2, 6, 7, 3], // y hi
        [0, 4, 6, 2], // x lo
        [1, 3, 7, 5], // x hi
    ];
    let mut t = Vec::new();
    for q in quads {
        t.push([q[0], q[1], q[2]]);
        t.push([q[0], q[2], q[3]]);
    }
    Solid {
        name,
        triangles: t,
        motion: Animation::still(v),
    }
}

/// The Peirce cantilever: the strip of `segments` cells along its direction, two nodes (1 cm)
/// wide, clamped by two rows of pinned nodes at ±h/2 about the platform edge x = 0, its tip at
/// x = overhang; run until every node is slower than 5 mm/s after 1.5 s (or the time cap).
/// The chord angle from the edge to the tip is compared with the elastica's 41.5° (exact at the
/// default overhang 2.0003·c).
fn cantilever(
    spec: &CantileverSpec,
    fabric: &Fabric,
    progress: &mut dyn FnMut(f64),
) -> Result<Simulated, RunError> {
    let rigidity = match spec.direction {
        StripDirection::Warp => fabric.bending.warp.rigidity(),
        StripDirection::Weft => fabric.bending.weft.rigidity(),
    };
    let c = (rigidity / fabric.weight_per_area()).cbrt();
    let length = spec.overhang.unwrap_or(2.0003 * c);
    let segments = spec.segments;
    let h = length / (segments as f64 + 0.5);
    let width = 0.01;
    let nv = segments + 2;
    let mut grid = StructuredGrid::sheet(2, nv, width, (nv - 1) as f64 * h);
    if spec.direction == StripDirection::Weft {
        // Warp across the strip (along pattern x): the strip runs along the weft.
        grid.grain_angle = 0.0;
    }
    let setup = |e: String| RunError::Setup(format!("cantilever: {e}"));
    let topo = ClothTopology::from_structured(&grid).map_err(|e| setup(e.to_string()))?;
    let mut cloth =
        Cloth::new(topo, fabric, AnisotropyForm::Thesis).map_err(|e| setup(e.to_string()))?;
    let place = |[x, y]: [f64; 2]| Vector3::new(y - 0.5 * h, x, 0.0);
    for node in 0..4 {
        let p = place(cloth.topology().rest_positions()[node]);
        cloth
            .pin(node as u32, p, PinMotion::Fixed)
            .map_err(|e| setup(e.to_string()))?;
    }
    let mut state = ClothState::placed(&cloth, place);
    // Implicit bending keeps this stable up to about 0.4·h s/m; 0.25·h leaves a margin.
    let params = StepParams {
        dt: 0.25 * h,
        damping: spec.damping,
        hysteresis: spec.hysteresis,
        ..StepParams::default()
    };
    params.validate().map_err(|e| setup(e.to_string()))?;
    let mut stepper = Stepper::new(&state, spec.frame_interval);
    let mut solver = Solver::new();
    let mut at_rest = false;
    while state.time < spec.max_time {
        if !stepper.step(&mut solver, &cloth, &mut state, &params) {
            break;
        }
        progress(state.time / spec.max_time);
        if state.time > 1.5 && stepper.max_speed < 5e-3 {
            at_rest = true;
            break;
        }
    }
    stepper.finish(&state);
    let tip = (state.positions[2 * (nv - 1)] + state.positions[2 * (nv - 1) + 1]) * 0.5;
    let angle = (-tip.z).atan2(tip.x).to_degrees();
    let ok = stepper.failure.is_none();
    let mut metrics = BTreeMap::new();
    metrics.insert("bending_length_m".into(), Some(c));
    metrics.insert("overhang_m".into(), Some(length));
    metrics.insert("chord_angle_deg".into(), ok.then_some(angle));
    let reference = (spec.overhang.is_none()).then_some(41.5);
    metrics.insert(
        "chord_angle_error_deg".into(),
        reference.filter(|_| ok).map(|r| angle - r),
    );
    metrics.insert("tip_droop_m".into(), ok.then_some(-tip.z));
    metrics.insert("max_speed_m_s".into(), ok.then_some(stepper.max_speed));
    let platform = block(
        [-length, -0.01, -0.02],
        [0.0, width + 0.01, 0.0],
        "platform",
    );
    let mut sim = stepper.into_simulated(&cloth, &state, params.dt, Some(platform), metrics);
    if !at_rest && ok {
        sim.warnings.push(format!(
            "not at rest after {:.2} s (fastest node {:.2e} m/s)",
            spec.max_time,
            sim.metrics
                .get("max_speed_m_s")
                .copied()
                .flatten()
                .unwrap_or(f64::NAN)
        ));
    }
    Ok(sim)
}

/// The inextensible catenary with span `d` and length `l`: the parameter a of
/// l = 2a·sinh(d/2a), by bisection.
fn catenary_parameter(d: f64, l: f64) -> f64 {
    let (mut lo, mut hi): (f64, f64) = (1e-4, 1e4);
    for _ in 0..200 {
        let a = (lo * hi).sqrt();
        if 2.0 * a * (d / (2.0 * a)).sinh() > l {
            lo = a
        } else {
            hi = a
        }
    }
    (lo * hi).sqrt()
}

/// A strip two nodes (1 cm) wide hung from both ends, bending off, started on a circular arc of
/// its own length through both supports; compared at the end with the inextensible catenary
/// z = a(cosh(x/a) − cosh(d/2a)).
fn catenary(
    spec: &CatenarySpec,
    fabric: &Fabric,
    progress: &mut dyn FnMut(f64),
) -> Result<Simulated, RunError> {
    let (length, span, segments) = (spec.length, spec.span, spec.segments);
    let setup = |e: String| RunError::Setup(format!("catenary: {e}"));
    let topo =
        ClothTopology::from_structured(&StructuredGrid::sheet(segments + 1, 2, length, 0.01))
            .map_err(|e| setup(e.to_string()))?;
    let mut cloth =
        Cloth::new(topo, fabric, AnisotropyForm::Thesis).map_err(|e| setup(e.to_string()))?;
    let a = catenary_parameter(span, length);
    let (mut lo, mut hi) = (1e-6_f64, std::f64::consts::PI - 1e-9);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if span / (2.0 * mid.sin()) * 2.0 * mid > length {
            hi = mid
        } else {
            lo = mid
        }
    }
    let half = 0.5 * (lo + hi);
    let radius = span / (2.0 * half.sin());
    let place = |[x, y]: [f64; 2]| {
        let phi = -half + 2.0 * half * x / length;
        Vector3::new(radius * phi.sin(), y, -radius * (phi.cos() - half.cos()))
    };
    let n_u = segments + 1;
    for j in 0..2 {
        for i in [0, segments] {
            let node = j * n_u + i;
            let p = place(cloth.topology().rest_positions()[node]);
            cloth
                .pin(node as u32, p, PinMotion::Fixed)
                .map_err(|e| setup(e.to_string()))?;
        }
    }
    let mut state = ClothState::placed(&cloth, place);
    let params = StepParams {
        dt: spec.dt,
        damping: spec.damping,
        bending_off: true,
        ..StepParams::default()
    };
    params.validate().map_err(|e| setup(e.to_string()))?;
    let mut stepper = Stepper::new(&state, spec.frame_interval);
    let mut solver = Solver::new();
    let steps = (spec.duration / spec.dt).round() as usize;
    for _ in 0..steps {
        if !stepper.step(&mut solver, &cloth, &mut state, &params) {
            break;
        }
        progress(state.time / spec.duration);
    }
    stepper.finish(&state);
    let ok = stepper.failure.is_none();
    let mut worst: f64 = 0.0;
    for p in &state.positions {
        let exact = a * ((p.x / a).cosh() - (span / (2.0 * a)).cosh());
        worst = worst.max((p.z - exact).abs());
    }
    let sag = -state
        .positions
        .iter()
        .map(|p| p.z)
        .fold(f64::INFINITY, f64::min);
    let mut metrics = BTreeMap::new();
    metrics.insert("catenary_parameter_m".into(), Some(a));
    metrics.insert("max_deviation_m".into(), ok.then_some(worst));
    metrics.insert(
        "max_deviation_percent_span".into(),
        ok.then_some(100.0 * worst / span),
    );
    metrics.insert("sag_m".into(), ok.then_some(sag));
    metrics.insert("max_speed_m_s".into(), ok.then_some(stepper.max_speed));
    Ok(stepper.into_simulated(&cloth, &state, params.dt, None, metrics))
}

/// The folder relative paths of a scenario file are resolved against: the file's own folder.
pub fn base_of(file: &Path) -> PathBuf {
    file.parent()
        .map(Path::to_path_buf)
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or_else(|| PathBuf::from("."))
}

/// The two recorded frames of a virtual KES test: the specimen at rest and at the end.
fn kes_frames(start: Vec<[f64; 3]>, end: &ClothState, time: f64) -> Animation {
    let mut a = Animation::default();
    a.push(0.0, start);
    a.push(time, end.positions.iter().map(to_y_up).collect());
    a
}

/// The virtual KES-FB1 tensile test: the specimen's loop 0 → F_m → 0 against the fabric's
/// own loop along the same path (its tensile model, state by state).
fn kes_tensile(spec: &KesTensileSpec, fabric: &Fabric) -> Result<Simulated, RunError> {
    use atelier_fabric::{TensileState, units};
    use atelier_solver::kes;
    let setup = |e: String| RunError::Setup(format!("KES tensile test: {e}"));
    let path = kes::cycle(units::force_from_kes(spec.max_force_gf_cm), spec.levels);
    let form = AnisotropyForm::Thesis;
    let clock = Instant::now();
    let curve = kes::tensile_test(fabric, form, spec.direction, &path, 3)
        .map_err(|e| setup(e.to_string()))?;
    let wall = clock.elapsed().as_secs_f64();
    let input_loop = match spec.direction {
        StripDirection::Warp => &fabric.tensile.warp,
        StripDirection::Weft => &fabric.tensile.weft,
    };
    let mut st = TensileState::VIRGIN;
    let model: Vec<(f64, f64)> = path
        .iter()
        .map(|&f| (f, st.update(input_loop, f)))
        .collect();
    let (sim, input) = (curve.kes_values(), kes::values_of(&model));
    let mut metrics = BTreeMap::new();
    let errors = [
        (sim.emt, input.emt),
        (sim.lt, input.lt),
        (sim.wt, input.wt),
        (sim.rt, input.rt),
    ]
    .map(|(a, b)| (a / b - 1.0).abs());
    for (k, v) in [
        ("emt_percent", 100.0 * sim.emt),
        ("input_emt_percent", 100.0 * input.emt),
        ("lt", sim.lt),
        ("input_lt", input.lt),
        ("wt_gf_cm_cm2", units::energy_to_kes(sim.wt)),
        ("input_wt_gf_cm_cm2", units::energy_to_kes(input.wt)),
        ("rt_percent", 100.0 * sim.rt),
        ("input_rt_percent", 100.0 * input.rt),
        (
            "largest_relative_error",
            errors.iter().copied().fold(0.0, f64::max),
        ),
    ] {
        metrics.insert(k.to_string(), Some(v));
    }
    let kes = |pts: &[(f64, f64)]| -> Vec<(f64, f64)> {
        pts.iter()
            .map(|&(f, e)| (100.0 * e, units::force_to_kes(f)))
            .collect()
    };
    let chart = crate::chart::Chart {
        title: format!("KES-FB1 tensile, {} {:?}", fabric.name, spec.direction),
        x_label: "strain (%)".into(),
        y_label: "force per width (gf/cm)".into(),
        series: vec![
            crate::chart::Series {
                name: "the fabric's loop".into(),
                points: std::iter::once((0.0, 0.0)).chain(kes(&model)).collect(),
            },
            crate::chart::Series {
                name: "simulated specimen".into(),
                points: std::iter::once((0.0, 0.0))
                    .chain(kes(&curve.points))
                    .collect(),
            },
        ],
        markers: None,
        equal_aspect: false,
    };
    kes_simulated(
        curve.cloth,
        &curve.state,
        &curve.stats,
        kes::TensileProtocol::default().dt,
        wall,
        metrics,
        chart,
    )
}

/// The virtual KES-FB2 bending test: B and 2HB of the specimen's loop against the fabric's.
fn kes_bending(spec: &KesBendingSpec, fabric: &Fabric) -> Result<Simulated, RunError> {
    use atelier_fabric::units;
    use atelier_solver::kes;
    let setup = |e: String| RunError::Setup(format!("KES bending test: {e}"));
    let clock = Instant::now();
    let curve = kes::bending_test(
        fabric,
        AnisotropyForm::Thesis,
        spec.direction,
        spec.steps_per_leg,
    )
    .map_err(|e| setup(e.to_string()))?;
    let wall = clock.elapsed().as_secs_f64();
    let spindle = match spec.direction {
        StripDirection::Warp => &fabric.bending.warp,
        StripDirection::Weft => &fabric.bending.weft,
    };
    let (b_in, hb_in) = (spindle.rigidity(), 2.0 * spindle.residual_moment());
    let mut metrics = BTreeMap::new();
    for (k, v) in [
        ("b_gf_cm2_cm", units::rigidity_to_kes(curve.rigidity)),
        ("input_b_gf_cm2_cm", units::rigidity_to_kes(b_in)),
        ("two_hb_gf_cm_cm", units::moment_to_kes(curve.two_hb)),
        ("input_two_hb_gf_cm_cm", units::moment_to_kes(hb_in)),
        (
            "largest_relative_error",
            ((curve.rigidity / b_in - 1.0).abs()).max((curve.two_hb / hb_in - 1.0).abs()),
        ),
    ] {
        metrics.insert(k.to_string(), Some(v));
    }
    // The fabric's own loop along the same curvature path, through its hysteresis state.
    let mut st = atelier_fabric::BendingState::VIRGIN;
    let model: Vec<(f64, f64)> = curve
        .passes
        .iter()
        .flatten()
        .map(|&(eta, _)| (eta, st.update(spindle, eta)))
        .collect();
    let kes_pts = |pts: &mut dyn Iterator<Item = (f64, f64)>| -> Vec<(f64, f64)> {
        pts.map(|(eta, m)| (units::curvature_to_kes(eta), units::moment_to_kes(m)))
            .collect()
    };
    let chart = crate::chart::Chart {
        title: format!("KES-FB2 bending, {} {:?}", fabric.name, spec.direction),
        x_label: "curvature (1/cm)".into(),
        y_label: "moment per width (gf·cm/cm)".into(),
        series: vec![
            crate::chart::Series {
                name: "the fabric's spindle".into(),
                points: kes_pts(&mut model.iter().copied()),
            },
            crate::chart::Series {
                name: "simulated specimen".into(),
                points: kes_pts(&mut curve.passes.iter().flatten().copied()),
            },
        ],
        markers: None,
        equal_aspect: false,
    };
    kes_simulated(
        curve.cloth,
        &curve.state,
        &curve.stats,
        curve.dt,
        wall,
        metrics,
        chart,
    )
}

/// A virtual KES test's outputs: its specimen at the end, its steps (`stats`, counted by the
/// instrument) of `dt`, and its loop as the chart.
fn kes_simulated(
    cloth: Cloth,
    state: &ClothState,
    stats: &atelier_solver::SolveStats,
    dt: f64,
    wall: f64,
    mut metrics: BTreeMap<String, Option<f64>>,
    chart: crate::chart::Chart,
) -> Result<Simulated, RunError> {
    let rest: Vec<[f64; 3]> = cloth
        .topology()
        .rest_positions()
        .iter()
        .map(|&[x, y]| to_y_up(&Vector3::new(x, y, 0.0)))
        .collect();
    metrics.insert(
        "kinetic_energy_j".into(),
        Some(state.kinetic_energy(&cloth)),
    );
    Ok(Simulated {
        fabric: String::new(),
        cloth_triangles: cloth.topology().triangles().to_vec(),
        cloth: kes_frames(rest, state, state.time),
        solid: None,
        steps: stats.steps,
        dt,
        simulated: state.time,
        wall_seconds: wall,
        timings: Timings::default(),
        metrics,
        warnings: Vec::new(),
        failure: None,
        chart: Some(chart),
        wet: None,
        fit: None,
        comparison: None,
        convergence: Some(Convergence::from_stats(solvers::PARTY, stats)),
    })
}
