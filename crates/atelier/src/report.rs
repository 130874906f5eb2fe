//! The report of a run (`report.json`): what was run, its size, its cost, its metrics, whether
//! its expectations were met, and what went wrong. The schema, every field with its unit, is
//! `docs/report.md`; [`Report::FORMAT`] names its version.
//!
//! The `metrics` object depends only on the scenario and the arithmetic of the run (no wall
//! times), so two runs of the same scenario with one thread write identical `metrics` bytes.

use std::collections::BTreeMap;
use std::path::Path;

use atelier_body::build::Sizes;
use serde::{Deserialize, Serialize};

use crate::camera::Camera;
use crate::convergence::{Convergence, UNCONVERGED_FRACTION};
pub use crate::outcome::Comparison;
use crate::outcome::{RunError, Simulated};
use crate::scenario::Scenario;

/// The scenario a report is about.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScenarioInfo {
    /// Its name.
    pub name: String,
    /// The file it was read from (as given), or `null` for the built-in default.
    pub file: Option<String>,
    /// Kind: `Garment`, `Drape`, `Cantilever` or `Catenary`.
    pub kind: String,
    /// What it reproduces.
    pub reproduces: String,
}

/// Wall time per stage of the step, summed over the run, s.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StageSeconds {
    /// Posing the body and its parts' motion (garment scenes with a motion).
    #[serde(default)]
    pub body: f64,
    /// Normals, curvature, bending force.
    pub bending: f64,
    /// Internal forces.
    pub internal: f64,
    /// Unconstrained velocity.
    pub velocity: f64,
    /// Geometric transfer of body motion.
    pub transfer: f64,
    /// Shape constraint iterations.
    pub shape: f64,
    /// Collision passes (body, self, sewing pull).
    pub collision: f64,
    /// Position update, hysteresis, the solver's diagnostics.
    pub update: f64,
    /// The run's own diagnostics after each step (garment scenes: every node against the body).
    #[serde(default)]
    pub diagnostics: f64,
    /// The air pressure of a wet cloth (wet scenes).
    #[serde(default)]
    pub pressure: f64,
    /// Sum of the stages.
    pub total: f64,
}

/// One expectation and its outcome.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExpectationResult {
    /// Metric name.
    pub metric: String,
    /// Lower bound, if any.
    pub min: Option<f64>,
    /// Upper bound, if any.
    pub max: Option<f64>,
    /// The metric's value (`null`: not measured).
    pub value: Option<f64>,
    /// Whether the bound was met.
    pub met: bool,
}

/// The whole report.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Report {
    /// Schema name and version: [`Report::FORMAT`].
    pub format: String,
    /// Version of atelier that wrote it.
    pub atelier_version: String,
    /// The scenario.
    pub scenario: ScenarioInfo,
    /// The fabric's name.
    pub fabric: String,
    /// Cloth nodes.
    pub nodes: usize,
    /// Cloth triangles.
    pub triangles: usize,
    /// Body (or tester) triangles; 0 when there is none.
    pub body_triangles: usize,
    /// Steps taken.
    pub steps: usize,
    /// Time step Δt, s.
    pub dt_s: f64,
    /// Simulated time reached, s.
    pub simulated_s: f64,
    /// Wall time of the steps, s.
    pub wall_s: f64,
    /// Wall time of everything else before writing (loading, gridding, placing, measuring), s.
    pub setup_s: f64,
    /// Wall time per stage, s.
    pub stage_s: StageSeconds,
    /// Worker threads of the parallel stages.
    pub threads: usize,
    /// Metrics by name (units in the names); `null` when not measured.
    pub metrics: BTreeMap<String, Option<f64>>,
    /// Each expectation with its outcome.
    pub expectations: Vec<ExpectationResult>,
    /// Every expectation met (true when there are none).
    pub expectations_met: bool,
    /// Things the user should know.
    pub warnings: Vec<String>,
    /// The failure that ended the run early (`null`: none).
    pub failure: Option<String>,
    /// Whether the run's steps converged (`null`: no solver stepped, the string
    /// identification; its counts `null` when the solver does not report convergence).
    #[serde(default)]
    pub convergence: Option<Convergence>,
    /// The files written beside the report.
    pub outputs: Vec<String>,
    /// The compared run of a wet scene (absent otherwise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub comparison: Option<Comparison>,
    /// A drape test's final outline and nodes seen from above (drape runs only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drape: Option<crate::outcome::DrapeTop>,
    /// The try-on's fit and composite (`atelier tryon` only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tryon: Option<TryonInfo>,
}

impl Report {
    /// The schema's name and version.
    pub const FORMAT: &'static str = "atelier-report/1";

    /// The report of a simulation (outputs and setup time filled in by the runner).
    pub fn new(scenario: &Scenario, file: Option<&Path>, sim: &Simulated) -> Self {
        let expectations = check_expectations(scenario, &sim.metrics);
        let t = &sim.timings.solver;
        let stage_s = StageSeconds {
            body: sim.timings.body.as_secs_f64(),
            bending: t.bending.as_secs_f64(),
            internal: t.internal.as_secs_f64(),
            velocity: t.velocity.as_secs_f64(),
            transfer: t.transfer.as_secs_f64(),
            shape: t.shape.as_secs_f64(),
            collision: t.collision.as_secs_f64(),
            update: t.update.as_secs_f64(),
            diagnostics: sim.timings.diagnostics.as_secs_f64(),
            pressure: t.pressure.as_secs_f64(),
            total: sim.timings.total().as_secs_f64(),
        };
        Self {
            format: Self::FORMAT.into(),
            atelier_version: env!("CARGO_PKG_VERSION").into(),
            scenario: ScenarioInfo {
                name: scenario.name.clone(),
                file: file.map(|f| f.display().to_string()),
                kind: scenario.kind.name().into(),
                reproduces: scenario.reproduces.clone(),
            },
            fabric: sim.fabric.clone(),
            nodes: sim.cloth.frames.first().map_or(0, Vec::len),
            triangles: sim.cloth_triangles.len(),
            body_triangles: sim.solid.as_ref().map_or(0, |s| s.triangles.len()),
            steps: sim.steps,
            dt_s: sim.dt,
            simulated_s: sim.simulated,
            wall_s: sim.wall_seconds,
            setup_s: 0.0,
            stage_s,
            threads: rayon::current_num_threads(),
            metrics: sim.metrics.clone(),
            expectations_met: expectations.iter().all(|e| e.met),
            expectations,
            warnings: sim.warnings.clone(),
            failure: sim.failure.clone(),
            convergence: sim.convergence.clone(),
            outputs: Vec::new(),
            comparison: sim.comparison().cloned(),
            drape: sim.drape_top().cloned(),
            tryon: None,
        }
    }

    /// Pretty JSON, ending with a newline.
    pub fn to_json(&self) -> String {
        let mut s = serde_json::to_string_pretty(self).expect("a report serialises");
        s.push('\n');
        s
    }

    /// Read a report back (numbers exactly as written: serde_json's `float_roundtrip`).
    pub fn from_json(text: &str) -> Result<Self, serde_json::Error> {
        serde_json::from_str(text)
    }

    /// Write the report atomically.
    pub fn write(&self, path: &Path) -> Result<(), RunError> {
        atelier_files::files::write_atomic(path, self.to_json().as_bytes()).map_err(|source| {
            RunError::Output {
                path: path.to_path_buf(),
                source,
            }
        })
    }

    /// Whether the run succeeded: no failure, every expectation met, every step converged
    /// (unless the scenario bounds `unconverged_fraction` itself: then that expectation
    /// decides) and, for a try-on, a fit that matched the silhouette.
    pub fn passed(&self) -> bool {
        self.failure.is_none()
            && self.expectations_met
            && !self.unconverged()
            && self.tryon.as_ref().is_none_or(|t| t.iou_after >= LOW_IOU)
    }

    /// Whether some step did not converge — the run's, or a wet scene's compared run's (its
    /// `compare_*` metrics) — and the scenario does not bound `unconverged_fraction` itself:
    /// the run's numbers are not all converged results, and the run does not pass.
    pub fn unconverged(&self) -> bool {
        let compared = self
            .comparison
            .as_ref()
            .and_then(|c| c.convergence.as_ref());
        self.convergence
            .iter()
            .chain(compared)
            .any(Convergence::any_unconverged)
            && !self
                .expectations
                .iter()
                .any(|e| e.metric == UNCONVERGED_FRACTION)
    }

    /// The warning about the run's unconverged steps, if some step did not converge; else the
    /// compared run's (wet scenes), if some of its steps did not.
    pub fn convergence_warning(&self) -> Option<String> {
        self.convergence
            .as_ref()
            .and_then(Convergence::warning)
            .or_else(|| {
                self.comparison
                    .as_ref()
                    .and_then(Comparison::convergence_warning)
            })
    }

    /// One line: name, outcome, steps and wall time, and the failure, the unmet expectations
    /// or the steps that did not converge (`ok`, `FAILED`, `EXPECTATION NOT MET`, `NOT
    /// CONVERGED`).
    pub fn summary_line(&self) -> String {
        let head = format!(
            "{}: {} steps, {:.2} s simulated in {:.2} s wall",
            self.scenario.name, self.steps, self.simulated_s, self.wall_s
        );
        if let Some(f) = &self.failure {
            return format!("FAILED {head}: {f}");
        }
        let unmet: Vec<String> = self
            .expectations
            .iter()
            .filter(|e| !e.met)
            .map(|e| {
                let value = e.value.map_or("not measured".into(), |v| {
                    if v.fract() == 0.0 && v.abs() < 1e15 {
                        format!("{v:.0}")
                    } else {
                        format!("{v:.4}")
                    }
                });
                let bound = match (e.min, e.max) {
                    (Some(a), Some(b)) => format!("[{a}, {b}]"),
                    (Some(a), None) => format!("≥ {a}"),
                    (None, Some(b)) => format!("≤ {b}"),
                    (None, None) => String::new(),
                };
                format!("{} = {value} not {bound}", e.metric)
            })
            .collect();
        let unconverged = self
            .unconverged()
            .then(|| self.convergence_warning())
            .flatten();
        match (unmet.is_empty(), unconverged) {
            (true, None) => format!("ok {head}"),
            (true, Some(w)) => format!("NOT CONVERGED {head}: {w}"),
            (false, None) => format!("EXPECTATION NOT MET {head}: {}", unmet.join("; ")),
            (false, Some(w)) => {
                format!("EXPECTATION NOT MET {head}: {}; {w}", unmet.join("; "))
            }
        }
    }
}

/// The try-on (`atelier-tryon`): below this silhouette overlap the fit is reported as failed (a warning and exit status 2).
pub const LOW_IOU: f64 = 0.8;

/// The try-on's part of `report.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TryonInfo {
    /// The photograph, as given.
    pub photo: String,
    /// The mask, as given; `null` when the background was segmented.
    pub mask: Option<String>,
    /// Pixels of the person in the mask.
    pub mask_pixels: usize,
    /// Silhouette overlap (intersection over union) at the start: the standard (or given)
    /// pose, the camera put on the mask's box.
    pub iou_before: f64,
    /// Silhouette overlap fitted.
    pub iou_after: f64,
    /// Wall time of the fit, s.
    pub fit_s: f64,
    /// Silhouettes rendered by the fit.
    pub evaluations: usize,
    /// How the fit's last minimisation ended.
    pub termination: String,
    /// The fitted camera.
    pub camera: Camera,
    /// With the camera's direction searched (`--yaw search`): every direction tried, degrees,
    /// and its fit's silhouette overlap, in the order tried; empty when the direction was given.
    pub yaw_tried: Vec<(f64, f64)>,
    /// The fitted sizes.
    pub sizes: Sizes,
    /// Fitted joint angles (α, β, γ), degrees, by part.
    pub joints: BTreeMap<String, (f64, f64, f64)>,
    /// Length of the motion from the standard pose to the fitted one, s.
    pub motion_s: f64,
    /// Pixels of the person the fitted mannequin does not cover (red in `overlay.png`): where
    /// the person is wider than the mannequin, the person can show beside the garment (the
    /// composite does not paint the photograph's background over them).
    pub person_outside_mannequin_px: usize,
    /// Pixels of the photograph the garment covers.
    pub garment_pixels: usize,
    /// The light's direction (body frame).
    pub light: [f64; 3],
}

/// Check each expectation against the metrics.
pub fn check_expectations(
    scenario: &Scenario,
    metrics: &BTreeMap<String, Option<f64>>,
) -> Vec<ExpectationResult> {
    scenario
        .expectations
        .iter()
        .map(|e| {
            let value = metrics.get(&e.metric).copied().flatten();
            ExpectationResult {
                metric: e.metric.clone(),
                min: e.min,
                max: e.max,
                value,
                met: e.met_by(value),
            }
        })
        .collect()
}
