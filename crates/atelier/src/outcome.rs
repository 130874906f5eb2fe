//! What a simulation produced, before anything is written ([`Simulated`]), and why a run could
//! not start or write ([`RunError`]): the data the runner ([`crate::run`]), the report
//! ([`crate::report`]) and the scene kinds ([`crate::wet`], [`crate::fit`]) share. It holds
//! data only, so every one of them can depend on it without depending on each other.

use std::collections::BTreeMap;
use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use crate::chart::Chart;
use atelier_files::{ErrorKind, FileError, InvalidValue};

use crate::convergence::Convergence;
use crate::export::Animation;
use crate::scene::SceneError;
use crate::simulation::Timings;

/// Why a scenario could not be run or its outputs not written. (A run that diverges is not an
/// error: it is a [`Simulated`] with a failure, and its outputs are written.)
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// A file the scenario names could not be read (the error names the file, the position and
    /// the field).
    #[error(transparent)]
    File(#[from] FileError),
    /// The garment scene could not be set up (its files, its body, its sewing).
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// Another scene kind could not be set up (a parameter out of range, a grid or cloth that
    /// cannot be built): the scene and why.
    #[error("{scene}: {source}")]
    Setup {
        /// The scene (`cantilever`, `wet scene`, `string fit`, …).
        scene: &'static str,
        /// Why (boxed: the crates' errors are large and a run returns this on every path).
        source: Box<SetupError>,
    },
    /// `atelier fit`: the observations could not be fitted.
    #[error(transparent)]
    FabricFit(#[from] atelier_fit::fabric_fit::FabricFitError),
    /// The output folder could not be created or written.
    #[error("cannot write {}: {source}", path.display())]
    Output {
        /// The folder or file.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
}

impl RunError {
    /// A [`RunError::Setup`] of `scene`, as a `map_err` argument.
    pub fn setup<E: Into<SetupError>>(scene: &'static str) -> impl Fn(E) -> Self {
        move |e| Self::Setup {
            scene,
            source: Box::new(e.into()),
        }
    }

    /// A [`RunError::Setup`] of `scene`: `field` out of range, `message` naming the value.
    pub fn out_of_range(
        scene: &'static str,
        field: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        Self::setup(scene)(InvalidValue::new(ErrorKind::OutOfRange, field, message))
    }
}

/// Why a scene kind other than the garment could not be set up: the typed error of the crate
/// that refused it.
#[derive(Debug, thiserror::Error)]
pub enum SetupError {
    /// A setting out of range (the field and the value).
    #[error(transparent)]
    Invalid(#[from] InvalidValue),
    /// The step parameters.
    #[error(transparent)]
    Params(#[from] atelier_solver::ParamError),
    /// The grid.
    #[error(transparent)]
    Topology(#[from] atelier_grid::TopologyError),
    /// The cloth or a pin.
    #[error(transparent)]
    Cloth(#[from] atelier_solver::ClothError),
    /// The drape tester.
    #[error(transparent)]
    Drape(#[from] atelier_solver::scenes::SceneError),
    /// A virtual KES instrument.
    #[error(transparent)]
    Kes(#[from] atelier_solver::kes::KesError),
    /// The wet scene.
    #[error(transparent)]
    Wet(#[from] atelier_solver::wet::scene::WetError),
    /// The string model or its fit.
    #[error(transparent)]
    Fit(#[from] atelier_fit::FitError),
    /// The turned strip.
    #[error(transparent)]
    Strip(#[from] atelier_fit::strip::StripError),
    /// A result could not be serialised.
    #[error("writing the result: {0}")]
    Write(#[from] ron::Error),
}

/// A fixed part drawn and exported with the cloth: the body, or a drape tester's support.
#[derive(Clone, Debug)]
pub struct Solid {
    /// Part name in the exports (`body`, `support`, `platform`).
    pub name: &'static str,
    /// Triangles (vertex indices), outward.
    pub triangles: Vec<[u32; 3]>,
    /// Its positions over the run (one frame when it does not move).
    pub motion: Animation,
}

/// What a simulation produced, before anything is written.
#[derive(Clone, Debug)]
pub struct Simulated {
    /// The fabric's name.
    pub fabric: String,
    /// Cloth triangles (node indices).
    pub cloth_triangles: Vec<[u32; 3]>,
    /// Cloth node positions over the run (y up), the last frame the final or last good state.
    pub cloth: Animation,
    /// The body or the tester, if any.
    pub solid: Option<Solid>,
    /// Steps taken.
    pub steps: usize,
    /// Time step, s.
    pub dt: f64,
    /// Simulated time reached, s.
    pub simulated: f64,
    /// Wall time of the steps, s.
    pub wall_seconds: f64,
    /// Wall time per stage, summed over the steps.
    pub timings: Timings,
    /// Metrics by name (see [`crate::scenario::ScenarioKind::metric_names`]); `None` when not measured (for
    /// example a drape coefficient after a failed step).
    pub metrics: BTreeMap<String, Option<f64>>,
    /// Things the user should know.
    pub warnings: Vec<String>,
    /// The failure that ended the run early.
    pub failure: Option<String>,
    /// What the run adds by scene kind (a chart, a wet scene's series, a fit's parameters).
    pub outputs: KindOutputs,
    /// Whether the steps converged (`None`: no solver stepped, the string identification).
    pub convergence: Option<Convergence>,
    /// Strain errors per frame and panels per node, where the run knows them.
    pub detail: ClothDetail,
}

/// What a run knows of its cloth beyond positions, for the viewer (`run.glb`'s colours).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ClothDetail {
    /// Per recorded frame (as `Simulated::cloth`'s), each node's largest axial strain error
    /// |ε − ε̄| (the solver's `max_strain_error` per node); empty when not recorded.
    pub strain_error: Vec<Vec<f32>>,
    /// Names of the garment's panels; empty for a one-piece cloth.
    pub panels: Vec<String>,
    /// The panel of each node (index into `panels`); empty for a one-piece cloth.
    pub node_panel: Vec<u16>,
}

/// What a run adds to the cloth's frames, by scene kind.
#[derive(Clone, Debug)]
pub enum KindOutputs {
    /// Nothing: the final state's views are the pictures (garments, strips).
    Cloth,
    /// A drape test: its final outline seen from above, with the counted nodes.
    Drape(DrapeTop),
    /// A virtual KES test: its loop, drawn instead of the final state's views.
    Chart(Chart),
    /// A wet scene: its series and charts, and the compared run's cost if there was one.
    Wet(Box<WetOutputs>, Option<Comparison>),
    /// A string identification: its fitted parameters and the shapes' chart (no cloth).
    Fit(Box<FitOutputs>, Chart),
}

impl Simulated {
    /// The compared run of a wet scene.
    pub fn comparison(&self) -> Option<&Comparison> {
        match &self.outputs {
            KindOutputs::Wet(_, c) => c.as_ref(),
            _ => None,
        }
    }

    /// The top view of a drape test.
    pub fn drape_top(&self) -> Option<&DrapeTop> {
        match &self.outputs {
            KindOutputs::Drape(top) => Some(top),
            _ => None,
        }
    }
}

/// A drape test's final state seen from above, in the horizontal plane (x, z) of the outputs'
/// y-up frame, m: what the report's `drape` section and the viewer's top view show.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct DrapeTop {
    /// The specimen's outer edge, one point per node of its outer ring, in ring order.
    pub outline_m: Vec<[f64; 2]>,
    /// The counted nodes (folds): the outer-edge point at the top of each.
    pub node_points_m: Vec<[f64; 2]>,
    /// Radius of the support disk, m.
    pub support_radius_m: f64,
    /// Radius of the flat specimen, m.
    pub specimen_radius_m: f64,
}

/// What a wet run adds to the usual outputs: the series, charts and the compared run's final
/// state.
#[derive(Clone, Debug)]
pub struct WetOutputs {
    /// `series.csv`: one row per sample of each run.
    pub series_csv: String,
    /// Charts by file name (`tent.png`, `pressure.png`).
    pub charts: Vec<(&'static str, Chart)>,
    /// Final positions of the main run, z up (for its picture).
    pub final_z_up: Vec<[f64; 3]>,
    /// Final positions of the compared run, z up.
    pub compare_z_up: Option<Vec<[f64; 3]>>,
    /// Side of the square cloth, m.
    pub size: f64,
}

/// What a string-fit run adds: the fitted parameters.
#[derive(Clone, Debug)]
pub struct FitOutputs {
    /// `parameters.ron`: the fitted model.
    pub parameters_ron: String,
}

/// A second run of the same scene on another solver (wet scenes), with its cost (its metrics
/// are the report's `compare_*` metrics).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Comparison {
    /// `yamada` or `party`.
    pub solver: String,
    /// Its time step, s.
    pub dt_s: f64,
    /// Steps taken.
    pub steps: usize,
    /// Simulated time reached, s.
    pub simulated_s: f64,
    /// Wall time of its steps, s.
    pub wall_s: f64,
    /// Of which the pressure force, s.
    pub pressure_s: f64,
    /// The failure that ended it early (`null`: none).
    pub failure: Option<String>,
    /// Whether its steps converged (its counts `null` when its solver does not report it).
    #[serde(default)]
    pub convergence: Option<Convergence>,
}

impl Comparison {
    /// The warning about the compared run's unconverged steps (`the compared party run: …`),
    /// if some step did not converge.
    pub fn convergence_warning(&self) -> Option<String> {
        let w = self.convergence.as_ref().and_then(Convergence::warning)?;
        Some(format!("the compared {} run: {w}", self.solver))
    }
}
