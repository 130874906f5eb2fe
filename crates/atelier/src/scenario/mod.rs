//! Scenario files: one RON file per run, naming what it reproduces, the kind of scene (a garment
//! sewn on a body and worn, a drape test, a cantilever, a catenary) and, optionally, the bounds
//! its metrics must meet. `atelier run SCENARIO.ron` runs one ([`crate::run`]); the format is
//! documented in `docs/report.md` beside the report it produces.
//!
//! ```ron
//! (
//!     name: "drape_jis_cotton_broad",
//!     reproduces: "JIS L 1096 drape test of cotton broad (Matsudaira et al. 2015: DC 82.9 %)",
//!     kind: Drape(fabric: "../fabrics/cotton_broad.ron", tester: Jis),
//!     expectations: [(metric: "drape_coefficient_percent", min: 74.9, max: 90.9)],
//! )
//! ```
//!
//! Relative paths inside a scenario are resolved against the scenario file's folder. Unknown
//! fields are rejected; every error names the file, line:column and field.

use std::path::{Path, PathBuf};

use atelier_fabric::{AnisotropyForm, ErrorKind, FileError, InvalidValue};
use serde::{Deserialize, Serialize};

use crate::scene::GarmentSpec;

pub mod bounds;
mod drape;
pub mod string_fit;
pub mod wet;

pub use drape::{DrapeSpec, Tester};

/// One scenario file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Short name (letters, digits, `_` and `-`): the output folder of `cargo xtask
    /// run-scenarios` and the row of its summary.
    pub name: String,
    /// What the scenario reproduces: the test, figure or claim, with its source (required).
    pub reproduces: String,
    /// The scene.
    pub kind: ScenarioKind,
    /// Bounds on metrics the runner checks (none by default).
    #[serde(default)]
    pub expectations: Vec<Expectation>,
}

/// The scene a scenario runs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum ScenarioKind {
    /// A garment placed around a body, sewn with gravity off, settled, then worn while the body
    /// moves ([`crate::pipeline`]).
    Garment(GarmentSpec),
    /// The drape test: a circular specimen falling onto a circular support
    /// ([`atelier_solver::scenes::DrapeScene`]).
    Drape(DrapeSpec),
    /// The Peirce cantilever (ASTM D1388, JIS L 1096): a strip overhanging a platform droops to a
    /// chord angle of 41.5° at the overhang 2.0003·c, c = (B/w)^(1/3).
    Cantilever(CantileverSpec),
    /// A strip hung from both ends, bending off, against the inextensible catenary.
    Catenary(CatenarySpec),
    /// The KES-FB1 tensile test on a simulated specimen: its loop's EMT, LT, WT, RT against
    /// the fabric's.
    KesTensile(KesTensileSpec),
    /// The KES-FB2 bending test on a simulated specimen: its loop's B and 2HB against the
    /// fabric's.
    KesBending(KesBendingSpec),
    /// Yamada's wet cloth: a square on a plane, pinched and lifted over trapped air
    /// ([`crate::wet`]), on one solver and optionally compared with another.
    Wet(wet::WetSpec),
    /// Sudoh et al.'s string identification ([`crate::fit`]): J observed shapes fitted,
    /// reproduced, and the later shapes predicted.
    StringFit(string_fit::StringFitSpec),
}

impl ScenarioKind {
    /// Name of the kind (`Garment`, `Drape`, …), as written in the file.
    pub fn name(&self) -> &'static str {
        match self {
            ScenarioKind::Garment(_) => "Garment",
            ScenarioKind::Drape(_) => "Drape",
            ScenarioKind::Cantilever(_) => "Cantilever",
            ScenarioKind::Catenary(_) => "Catenary",
            ScenarioKind::KesTensile(_) => "KesTensile",
            ScenarioKind::KesBending(_) => "KesBending",
            ScenarioKind::Wet(_) => "Wet",
            ScenarioKind::StringFit(_) => "StringFit",
        }
    }

    /// The fabric file the scene uses.
    pub fn fabric(&self) -> Option<&Path> {
        Some(match self {
            ScenarioKind::Garment(s) => &s.fabric,
            ScenarioKind::Drape(s) => &s.fabric,
            ScenarioKind::Cantilever(s) => &s.fabric,
            ScenarioKind::Catenary(s) => &s.fabric,
            ScenarioKind::KesTensile(s) => &s.fabric,
            ScenarioKind::KesBending(s) => &s.fabric,
            ScenarioKind::Wet(s) => &s.fabric,
            ScenarioKind::StringFit(_) => return None,
        })
    }

    /// The metrics a run of this kind reports (the names expectations may use). Units are in the
    /// names; `docs/report.md` defines each. Every kind that steps a cloth reports
    /// `unconverged_fraction` (`null` when its solver does not report convergence).
    pub fn metric_names(&self) -> &'static [&'static str] {
        match self {
            ScenarioKind::Wet(_) => wet::METRICS,
            ScenarioKind::StringFit(_) => string_fit::METRICS,
            ScenarioKind::Garment(_) => &[
                "nodes",
                "cloth_triangles",
                "body_triangles",
                "pairs",
                "pairs_sewn",
                "unsewn_pairs",
                "sewn_at_s",
                "simulated_s",
                "max_penetration_m",
                "steps_with_penetration",
                "nodes_inside_at_end",
                "max_strain_error",
                "final_strain_error",
                "kinetic_energy_j",
                "max_motion_kinetic_energy_j",
                "lowest_node_m",
                "nodes_below_body",
                "hem_width_m",
                "hem_depth_m",
                "body_vertices_showing",
                "body_showing_depth_m",
                "final_rms_speed_m_s",
                "frames",
                crate::convergence::UNCONVERGED_FRACTION,
            ],
            ScenarioKind::Drape(_) => &[
                "nodes",
                "cloth_triangles",
                "simulated_s",
                "drape_coefficient_percent",
                "node_count",
                "shadow_area_m2",
                "settled",
                "rms_speed_m_s",
                "min_edge_radius_m",
                "max_edge_radius_m",
                "max_strain_error",
                "kinetic_energy_j",
                "frames",
                crate::convergence::UNCONVERGED_FRACTION,
            ],
            ScenarioKind::Cantilever(_) => &[
                "nodes",
                "cloth_triangles",
                "simulated_s",
                "bending_length_m",
                "overhang_m",
                "chord_angle_deg",
                "chord_angle_error_deg",
                "tip_droop_m",
                "max_speed_m_s",
                "max_strain_error",
                "kinetic_energy_j",
                "frames",
                crate::convergence::UNCONVERGED_FRACTION,
            ],
            ScenarioKind::Catenary(_) => &[
                "nodes",
                "cloth_triangles",
                "simulated_s",
                "catenary_parameter_m",
                "max_deviation_m",
                "max_deviation_percent_span",
                "sag_m",
                "max_speed_m_s",
                "max_strain_error",
                "kinetic_energy_j",
                "frames",
                crate::convergence::UNCONVERGED_FRACTION,
            ],
            ScenarioKind::KesTensile(_) => &[
                "nodes",
                "cloth_triangles",
                "simulated_s",
                "emt_percent",
                "input_emt_percent",
                "lt",
                "input_lt",
                "wt_gf_cm_cm2",
                "input_wt_gf_cm_cm2",
                "rt_percent",
                "input_rt_percent",
                "largest_relative_error",
                "kinetic_energy_j",
                "frames",
                crate::convergence::UNCONVERGED_FRACTION,
            ],
            ScenarioKind::KesBending(_) => &[
                "nodes",
                "cloth_triangles",
                "simulated_s",
                "b_gf_cm2_cm",
                "input_b_gf_cm2_cm",
                "two_hb_gf_cm_cm",
                "input_two_hb_gf_cm_cm",
                "largest_relative_error",
                "kinetic_energy_j",
                "frames",
                crate::convergence::UNCONVERGED_FRACTION,
            ],
        }
    }
}

/// A bound on one metric: `min ≤ value ≤ max` (either may be left out, not both).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Expectation {
    /// Metric name (see [`ScenarioKind::metric_names`]).
    pub metric: String,
    /// Smallest value accepted.
    #[serde(default)]
    pub min: Option<f64>,
    /// Largest value accepted.
    #[serde(default)]
    pub max: Option<f64>,
}

impl Expectation {
    /// Whether `value` meets the bound (a missing or NaN value never does).
    pub fn met_by(&self, value: Option<f64>) -> bool {
        value.is_some_and(|v| {
            !v.is_nan() && self.min.is_none_or(|m| v >= m) && self.max.is_none_or(|m| v <= m)
        })
    }
}

/// The grain direction along a strip: `Warp` (default) or `Weft`.
pub use atelier_solver::kes::Direction as StripDirection;

/// The virtual KES-FB1 tensile test (`atelier_solver::kes::tensile_test`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KesTensileSpec {
    /// Fabric file (RON).
    pub fabric: PathBuf,
    /// Direction of the specimen. Default `Warp`.
    #[serde(default)]
    pub direction: StripDirection,
    /// Largest force, gf/cm. Default 500 (the KES-FB1 standard F_m).
    #[serde(default = "default_kes_force")]
    pub max_force_gf_cm: f64,
    /// Force levels each way (0 → F_m and back). Default 100.
    #[serde(default = "default_kes_levels")]
    pub levels: usize,
}

/// The virtual KES-FB2 bending test (`atelier_solver::kes::bending_test`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KesBendingSpec {
    /// Fabric file (RON).
    pub fabric: PathBuf,
    /// Direction of the specimen. Default `Warp`.
    #[serde(default)]
    pub direction: StripDirection,
    /// Steps per 2.5 cm⁻¹ leg of the cycle 0 → +2.5 → −2.5 → 0 cm⁻¹ (at the KES rate
    /// 0.5 cm⁻¹/s, Δt = 5 s / `steps_per_leg`; at least 50). Default 500.
    #[serde(default = "default_kes_steps")]
    pub steps_per_leg: usize,
}

/// The Peirce cantilever.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CantileverSpec {
    /// Fabric file (RON).
    pub fabric: PathBuf,
    /// Direction of the strip. Default `Warp`.
    #[serde(default)]
    pub direction: StripDirection,
    /// Cells along the overhang (≥ 4). Default 40.
    #[serde(default = "default_segments")]
    pub segments: usize,
    /// Overhang, m; default 2.0003·c with c = (B/w)^(1/3) of the strip's direction, the length
    /// at which the exact heavy elastica's chord makes 41.5°.
    #[serde(default)]
    pub overhang: Option<f64>,
    /// Damping c/S, kg/(m²·s). Default 1.
    #[serde(default = "one")]
    pub damping: f64,
    /// Bending hysteresis on. Default false (the elastica is elastic).
    #[serde(default)]
    pub hysteresis: bool,
    /// Longest simulated time, s; the run stops earlier once every node is slower than 5 mm/s
    /// after 1.5 s. Default 6.
    #[serde(default = "default_cantilever_time")]
    pub max_time: f64,
    /// Interval between recorded frames, s. Default 0.04.
    #[serde(default = "default_frame_interval")]
    pub frame_interval: f64,
}

/// A strip hung from both ends.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CatenarySpec {
    /// Fabric file (RON).
    pub fabric: PathBuf,
    /// Strip length, m. Default 1.
    #[serde(default = "one")]
    pub length: f64,
    /// Distance between the supports, m (less than the length). Default 0.8.
    #[serde(default = "default_span")]
    pub span: f64,
    /// Cells along the strip. Default 50.
    #[serde(default = "default_catenary_segments")]
    pub segments: usize,
    /// Time step, s. Default 0.005.
    #[serde(default = "default_catenary_dt")]
    pub dt: f64,
    /// Simulated time, s. Default 10.
    #[serde(default = "default_catenary_time")]
    pub duration: f64,
    /// Damping c/S, kg/(m²·s). Default 2.
    #[serde(default = "two")]
    pub damping: f64,
    /// Interval between recorded frames, s. Default 0.04.
    #[serde(default = "default_frame_interval")]
    pub frame_interval: f64,
}

fn yes() -> bool {
    true
}
fn one() -> f64 {
    1.0
}
fn two() -> f64 {
    2.0
}
fn default_drape_time() -> f64 {
    5.0
}
fn default_perturbation() -> f64 {
    1e-4
}
fn default_seed() -> u64 {
    1
}
fn default_drape_form() -> AnisotropyForm {
    AnisotropyForm::Compliance
}
fn default_frame_interval() -> f64 {
    0.04
}
fn default_kes_force() -> f64 {
    500.0
}
fn default_kes_levels() -> usize {
    100
}
fn default_kes_steps() -> usize {
    500
}
fn default_segments() -> usize {
    40
}
fn default_cantilever_time() -> f64 {
    6.0
}
fn default_span() -> f64 {
    0.8
}
fn default_catenary_segments() -> usize {
    50
}
fn default_catenary_dt() -> f64 {
    0.005
}
fn default_catenary_time() -> f64 {
    10.0
}

/// The most frames a scenario may record.
pub const MAX_FRAMES: usize = 100_000;

impl Scenario {
    /// Read and check a scenario file.
    pub fn load(path: &Path) -> Result<Self, FileError> {
        let text = std::fs::read_to_string(path).unwrap_or_default();
        let s: Scenario = atelier_files::files::load_ron(path)?;
        s.check()
            .map_err(|e| atelier_files::files::located(path, &text, e))?;
        Ok(s)
    }

    /// Parse and check scenario text; `file` names it in errors.
    pub fn parse(text: &str, file: &Path) -> Result<Self, FileError> {
        let s: Scenario = atelier_files::files::parse_ron(text, file)?;
        s.check()
            .map_err(|e| atelier_files::files::located(file, text, e))?;
        Ok(s)
    }

    /// The files the scenario names (resolved against `base`) exist and are files.
    pub fn check_files(&self, base: &Path) -> Result<(), InvalidValue> {
        let mut files: Vec<(&str, &Path)> = self
            .kind
            .fabric()
            .map(|f| ("kind.fabric", f))
            .into_iter()
            .collect();
        if let ScenarioKind::StringFit(string_fit::StringFitSpec {
            observations: string_fit::Source::File(f),
            ..
        }) = &self.kind
        {
            files.push(("kind.observations", f));
        }
        if let ScenarioKind::Garment(g) = &self.kind {
            files.push(("kind.garment", &g.garment));
            if let Some(b) = &g.body {
                files.push(("kind.body", b));
            }
            if let Some(s) = &g.body_scan {
                files.push(("kind.body_scan.mesh", &s.mesh));
                if let Some(l) = &s.landmarks {
                    files.push(("kind.body_scan.landmarks", l));
                }
            }
            if let Some(m) = &g.motion {
                files.push(("kind.motion", m));
            }
        }
        for (field, f) in files {
            let path = base.join(f);
            if !path.is_file() {
                return Err(InvalidValue::new(
                    ErrorKind::Io,
                    field,
                    format!("{} is not a readable file", path.display()),
                ));
            }
        }
        Ok(())
    }

    /// The checks serde cannot make: a usable name, a stated purpose, ranges, metric names.
    /// (Garment scene ranges are checked by the pipeline when it starts.)
    pub fn check(&self) -> Result<(), InvalidValue> {
        let bad = |field: &str, kind: ErrorKind, message: String| {
            Err(InvalidValue::new(kind, field, message))
        };
        if self.name.is_empty()
            || !self
                .name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
        {
            return bad(
                "name",
                ErrorKind::OutOfRange,
                format!(
                    "`{}`: use letters, digits, `_` and `-` only (it names a folder)",
                    self.name
                ),
            );
        }
        if self.reproduces.trim().is_empty() {
            return bad(
                "reproduces",
                ErrorKind::MissingField,
                "say what the scenario reproduces".into(),
            );
        }
        // A run records a frame per interval: a tiny interval over a long run would exhaust
        // memory before it failed.
        let frames = |field: &str, duration: f64, interval: f64| -> Result<(), InvalidValue> {
            let n = duration / interval;
            if n > MAX_FRAMES as f64 {
                bad(
                    field,
                    ErrorKind::OutOfRange,
                    format!(
                        "{duration} s every {interval} s is {n:.0} frames; record at most {MAX_FRAMES}"
                    ),
                )
            } else {
                Ok(())
            }
        };
        let at_most = |field: &str, n: usize, max: usize, what: &str| -> Result<(), InvalidValue> {
            if n > max {
                bad(
                    field,
                    ErrorKind::OutOfRange,
                    format!("{n} {what}: at most {max}"),
                )
            } else {
                Ok(())
            }
        };
        let positive = |field: &str, v: f64| -> Result<(), InvalidValue> {
            if !v.is_finite() {
                bad(field, ErrorKind::NotFinite, format!("{v}"))
            } else if v <= 0.0 {
                bad(field, ErrorKind::OutOfRange, format!("{v} must be > 0"))
            } else {
                Ok(())
            }
        };
        match &self.kind {
            ScenarioKind::Garment(g) => {
                g.settings.check().map_err(|e| e.within("kind"))?;
                let s = &g.settings;
                frames(
                    "kind.settings.frame_interval",
                    s.sew_limit + s.settle + s.motion_time,
                    s.frame_interval,
                )?;
            }
            ScenarioKind::Drape(d) => {
                if let Some(dt) = d.dt {
                    positive("kind.dt", dt)?;
                }
                positive("kind.max_time", d.max_time)?;
                positive("kind.frame_interval", d.frame_interval)?;
                if !(d.perturbation >= 0.0 && d.perturbation.is_finite()) {
                    return bad(
                        "kind.perturbation",
                        ErrorKind::OutOfRange,
                        format!("{} must be finite and ≥ 0", d.perturbation),
                    );
                }
                if d.n_around.is_some_and(|n| n < 3) {
                    return bad(
                        "kind.n_around",
                        ErrorKind::OutOfRange,
                        "need at least 3 nodes around".into(),
                    );
                }
                let rings = d.tester.min_rings();
                if let Some(n) = d.n_rings.filter(|&n| n < rings) {
                    return bad(
                        "kind.n_rings",
                        ErrorKind::OutOfRange,
                        format!(
                            "{n}: the {:?} tester needs at least {rings} rings",
                            d.tester
                        ),
                    );
                }
                at_most(
                    "kind.n_around",
                    d.n_around.unwrap_or(0),
                    10_000,
                    "nodes around",
                )?;
                at_most("kind.n_rings", d.n_rings.unwrap_or(0), 10_000, "rings")?;
                at_most(
                    "kind.n_around",
                    d.n_around
                        .unwrap_or(0)
                        .saturating_mul(d.n_rings.unwrap_or(0)),
                    1_000_000,
                    "nodes (around × rings)",
                )?;
                frames("kind.frame_interval", d.max_time, d.frame_interval)?;
            }
            ScenarioKind::Cantilever(c) => {
                if c.segments < 4 {
                    return bad(
                        "kind.segments",
                        ErrorKind::OutOfRange,
                        format!("{} cells: use at least 4", c.segments),
                    );
                }
                if let Some(l) = c.overhang {
                    positive("kind.overhang", l)?;
                }
                positive("kind.damping", c.damping)?;
                positive("kind.max_time", c.max_time)?;
                positive("kind.frame_interval", c.frame_interval)?;
                at_most("kind.segments", c.segments, 10_000, "cells")?;
                frames("kind.frame_interval", c.max_time, c.frame_interval)?;
            }
            ScenarioKind::KesTensile(k) => {
                positive("kind.max_force_gf_cm", k.max_force_gf_cm)?;
                if !(2..=10_000).contains(&k.levels) {
                    return bad(
                        "kind.levels",
                        ErrorKind::OutOfRange,
                        format!("{} levels: use 2 to 10000", k.levels),
                    );
                }
            }
            ScenarioKind::Wet(w) => {
                use atelier_solver::wet::scene::{WetError, WetSolver};
                w.scene.validate().map_err(|e| match e {
                    WetError::Range {
                        field,
                        value,
                        range,
                    } => InvalidValue::new(
                        ErrorKind::OutOfRange,
                        format!("kind.scene.{field}"),
                        format!("{value} is outside {range}"),
                    ),
                    other => {
                        InvalidValue::new(ErrorKind::OutOfRange, "kind.scene", other.to_string())
                    }
                })?;
                for (field, solver) in std::iter::once(("kind.solver", &w.solver))
                    .chain(w.compare.as_ref().map(|c| ("kind.compare", c)))
                {
                    let checked = match solver {
                        WetSolver::Party(p) => p.step.validate(),
                        WetSolver::Yamada(y) => atelier_solver::baselines::MassSpringParams {
                            damping: y.damping,
                            ..Default::default()
                        }
                        .validate(),
                    }
                    .and_then(|()| atelier_solver::StepInput::new(solver.dt()).validate());
                    checked.map_err(|e| {
                        InvalidValue::new(ErrorKind::OutOfRange, field, e.to_string())
                    })?;
                }
                positive("kind.frame_interval", w.frame_interval)?;
                positive("kind.fold_radius", w.fold_radius)?;
                positive("kind.fold_prominence", w.fold_prominence)?;
            }
            ScenarioKind::StringFit(f) => {
                if f.observed == 0 {
                    return bad(
                        "kind.observed",
                        ErrorKind::OutOfRange,
                        "0 shapes: fit at least 1".into(),
                    );
                }
                if let Some(i) = &f.initial {
                    positive("kind.initial.stretch", i.stretch)?;
                    positive("kind.initial.bending", i.bending)?;
                }
                positive("kind.options.c_s", f.options.c_s)?;
                positive("kind.options.c_f", f.options.c_f)?;
                positive("kind.options.mass", f.options.mass)?;
                if f.options.max_iterations == Some(0) {
                    return bad(
                        "kind.options.max_iterations",
                        ErrorKind::OutOfRange,
                        "0: use at least 1".into(),
                    );
                }
            }
            ScenarioKind::KesBending(k) => {
                if !(20..=100_000).contains(&k.steps_per_leg) {
                    return bad(
                        "kind.steps_per_leg",
                        ErrorKind::OutOfRange,
                        format!("{} steps: use 20 to 100000", k.steps_per_leg),
                    );
                }
            }
            ScenarioKind::Catenary(c) => {
                positive("kind.length", c.length)?;
                positive("kind.span", c.span)?;
                if c.span >= c.length {
                    return bad(
                        "kind.span",
                        ErrorKind::Inconsistent,
                        format!(
                            "span {} m must be shorter than the strip ({} m)",
                            c.span, c.length
                        ),
                    );
                }
                if c.segments < 4 {
                    return bad(
                        "kind.segments",
                        ErrorKind::OutOfRange,
                        format!("{} cells: use at least 4", c.segments),
                    );
                }
                positive("kind.dt", c.dt)?;
                positive("kind.duration", c.duration)?;
                positive("kind.damping", c.damping)?;
                positive("kind.frame_interval", c.frame_interval)?;
                at_most("kind.segments", c.segments, 100_000, "cells")?;
                frames("kind.frame_interval", c.duration, c.frame_interval)?;
            }
        }
        let names = self.kind.metric_names();
        for (i, e) in self.expectations.iter().enumerate() {
            let field = format!("expectations[{i}]");
            if !names.contains(&e.metric.as_str()) {
                return bad(
                    &format!("{field}.metric"),
                    ErrorKind::UnknownVariant,
                    format!(
                        "`{}` is not a metric of a {} scenario; expected one of {}",
                        e.metric,
                        self.kind.name(),
                        names.join(", ")
                    ),
                );
            }
            if e.min.is_none() && e.max.is_none() {
                return bad(
                    &field,
                    ErrorKind::MissingField,
                    "give `min`, `max` or both".into(),
                );
            }
            for (which, v) in [("min", e.min), ("max", e.max)] {
                if v.is_some_and(f64::is_nan) {
                    return bad(
                        &format!("{field}.{which}"),
                        ErrorKind::NotFinite,
                        "NaN".into(),
                    );
                }
            }
            if let (Some(lo), Some(hi)) = (e.min, e.max)
                && lo > hi
            {
                return bad(
                    &field,
                    ErrorKind::Inconsistent,
                    format!("min {lo} > max {hi}"),
                );
            }
            // `unconverged_fraction` is the exception: without a bound a run fails on any step
            // that missed its tolerance, so a bound of 1 is a deliberate acceptance of
            // unconverged steps (docs/report.md, convergence), not a check that cannot fail.
            if e.metric != crate::convergence::UNCONVERGED_FRACTION
                && bounds::covers_everything(&e.metric, e.min, e.max)
            {
                let (lo, hi) = bounds::physical_range(&e.metric);
                return bad(
                    &field,
                    ErrorKind::Inconsistent,
                    format!(
                        "[{}, {}] covers the whole physical range [{lo}, {hi}] of `{}`: no run \
                         can miss it; bound it by a reference (docs/report.md, expectations)",
                        e.min.map_or("−∞".to_string(), |v| v.to_string()),
                        e.max.map_or("∞".to_string(), |v| v.to_string()),
                        e.metric
                    ),
                );
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests;
