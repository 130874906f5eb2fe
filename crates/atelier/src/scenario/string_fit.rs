//! The string-identification scenario ([`crate::fit`] runs it): its file format and its metrics.

use std::path::PathBuf;

use atelier_fit::FitOptions;
use atelier_fit::synthetic::Object;
use serde::{Deserialize, Serialize};

/// Where the observations come from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Source {
    /// One of the synthetic objects (`atelier_fit::synthetic`), observed with the default
    /// settings (20 shapes, 9 markers, σ = 0.5 px, seed 1).
    Synthetic(Object),
    /// An observation file (RON, `docs/fit.md`), relative to the scenario's folder.
    File(PathBuf),
}

/// The initial s and b (l and φ come from the first shape).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Initial {
    /// Every s, N.
    pub stretch: f64,
    /// Every b, N·m.
    pub bending: f64,
}

/// A string-identification scenario.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StringFitSpec {
    /// The observations.
    pub observations: Source,
    /// J: the first J shapes are fitted (≥ 1).
    pub observed: usize,
    /// The shapes from this index on are predicted (unobserved). Default 10 (the paper's split
    /// of 20 shapes).
    #[serde(default = "default_unobserved_from")]
    pub unobserved_from: usize,
    /// Initial s and b; none: the paper's Table 2 for a synthetic object (required for a file).
    #[serde(default)]
    pub initial: Option<Initial>,
    /// Fit settings (defaults: `docs/fit.md`).
    #[serde(default)]
    pub options: FitOptions,
}

fn default_unobserved_from() -> usize {
    10
}

/// The metrics of a string-fit scenario (units in the names; `docs/report.md`).
pub const METRICS: &[&str] = &[
    "shapes",
    "observed_shapes",
    "unobserved_shapes",
    "iterations",
    "converged",
    "initial_cost",
    "cost",
    "max_observed_error_px",
    "mean_observed_error_px",
    "mean_unobserved_error_px",
    "initial_unobserved_error_px",
    "fit_wall_s",
];
