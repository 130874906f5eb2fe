//! The drape-test scenario ([`crate::run`] runs it with `atelier_solver::scenes::DrapeScene`):
//! the tester and the file format.

use std::path::PathBuf;

use atelier_fabric::AnisotropyForm;
use atelier_solver::StepParams;
use serde::{Deserialize, Serialize};

/// The drape tester's geometry.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Tester {
    /// JIS L 1096: Ø 25.4 cm specimen on a Ø 12.7 cm support; default grid 72 × 8 nodes, Δt 1 ms.
    Jis,
    /// The thesis §3.9.3: Ø 63.5 cm with a Ø 12.7 cm hole; default grid 60 × 6 nodes, Δt 2.5 ms.
    Thesis,
}

impl Tester {
    /// The fewest rings of nodes its scene can have: the JIS specimen is clamped (a second held
    /// ring one spacing inside the rim, which must not reach the centre), the thesis's hole is
    /// hinged.
    pub fn min_rings(self) -> usize {
        match self {
            Tester::Jis => 3,
            Tester::Thesis => 2,
        }
    }
}

/// A drape test.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DrapeSpec {
    /// Fabric file (RON).
    pub fabric: PathBuf,
    /// Tester geometry.
    pub tester: Tester,
    /// Nodes around each ring (default: 72 JIS, 60 thesis).
    #[serde(default)]
    pub n_around: Option<usize>,
    /// Rings of nodes from the support's rim to the edge (default: 8 JIS, 6 thesis).
    #[serde(default)]
    pub n_rings: Option<usize>,
    /// Time step, s (default: 0.001 JIS, 0.0025 thesis: the largest at which the rim ring does
    /// not chatter, `docs/validation.md`).
    #[serde(default)]
    pub dt: Option<f64>,
    /// Longest simulated time, s. Default 5.
    #[serde(default = "super::default_drape_time")]
    pub max_time: f64,
    /// Stop once at rest (RMS speed of the free nodes below 5 mm/s for 0.2 s, after 0.5 s), as
    /// `run_drape`'s default rest criterion; false: run `max_time`. Default true.
    #[serde(default = "super::yes")]
    pub until_rest: bool,
    /// Seeded vertical perturbation of the free nodes at the start, m. Default 1e-4.
    #[serde(default = "super::default_perturbation")]
    pub perturbation: f64,
    /// Seed of the perturbation. Default 1.
    #[serde(default = "super::default_seed")]
    pub seed: u64,
    /// Anisotropy form. Default `Compliance` (the drape tests' choice, `docs/validation.md`).
    #[serde(default = "super::default_drape_form")]
    pub form: AnisotropyForm,
    /// Interval between recorded frames, s. Default 0.04.
    #[serde(default = "super::default_frame_interval")]
    pub frame_interval: f64,
    /// Overrides of the solver's step parameters (Δt is set by `dt`; gravity −z).
    #[serde(default)]
    pub step: StepParams,
}
