//! The wet-cloth scenario ([`crate::wet`] runs it): its file format and its metrics.

use std::path::PathBuf;

use atelier_solver::wet::scene::{WetScene, WetSolver};
use serde::{Deserialize, Serialize};

use crate::convergence::UNCONVERGED_FRACTION;

/// A wet-cloth scenario.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WetSpec {
    /// Fabric file (RON).
    pub fabric: PathBuf,
    /// The scene (size, particles, air, picks, duration; defaults: the thesis's 30 cm square of
    /// 50 × 50 particles with no air).
    #[serde(default)]
    pub scene: WetScene,
    /// The solver of the run whose outputs are written: `Yamada((...))` (the thesis's
    /// mass-spring model, Δt 1/12 000 s by default) or `Party((dt: ...))` (the PARTY step).
    pub solver: WetSolver,
    /// A second run of the same scene to compare with (its metrics are prefixed `compare_`, its
    /// cost is in the report's `comparison`). Default none.
    #[serde(default)]
    pub compare: Option<WetSolver>,
    /// Interval between recorded frames, s. Default 0.04.
    #[serde(default = "default_frame_interval")]
    pub frame_interval: f64,
    /// Radius of the circle (on the cloth, around the first pick) on which folds are counted, m.
    /// Default 0.04.
    #[serde(default = "default_fold_radius")]
    pub fold_radius: f64,
    /// Smallest prominence of a fold, m. Default 0.5 mm.
    #[serde(default = "default_fold_prominence")]
    pub fold_prominence: f64,
}

fn default_frame_interval() -> f64 {
    0.04
}
fn default_fold_radius() -> f64 {
    0.04
}
fn default_fold_prominence() -> f64 {
    0.5e-3
}

/// The metrics of a wet scenario (units in the names; `docs/report.md`).
pub const METRICS: &[&str] = &[
    "nodes",
    "cloth_triangles",
    "simulated_s",
    "frames",
    "steps",
    "bubble_volume_cm3",
    "air_cm3",
    "bubbles",
    "pressure_difference_pa",
    "min_pressure_difference_pa",
    "max_pressure_difference_pa",
    "lifted_area_cm2",
    "tent_height_mm",
    "pinch_height_mm",
    "max_strain",
    "max_speed_m_s",
    "folds",
    "fold_spacing_deviation_deg",
    "fold_prominence_ratio",
    "fold_ring_height_mm",
    "compare_simulated_s",
    "compare_failed",
    "compare_tent_height_mm",
    "compare_lifted_area_cm2",
    "compare_folds",
    "rms_difference_mm",
    UNCONVERGED_FRACTION,
];
