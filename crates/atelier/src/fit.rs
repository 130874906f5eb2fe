//! String-identification scenarios (`ScenarioKind::StringFit`; `docs/fit.md`): the method of
//! Sudoh et al. on one object's observations — the first J shapes fitted, each reproduced, the
//! later shapes predicted by the fitted model and by the initial values — with the errors as
//! metrics, the fitted parameters as `parameters.ron` and the shapes as `final.png`.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use atelier_files::{ErrorKind, InvalidValue, files};
use atelier_fit::experiment::{fit, mean_error, paper_initial, reproduce};
use atelier_fit::fabric_fit::fit_fabric;
pub use atelier_fit::fabric_fit::{
    CantileverObservation, ClothObservations, DirectionFit, Point, TurnedObservation,
};
use atelier_fit::observation::Observations;
use atelier_fit::synthetic::{SyntheticOptions, observe};
use atelier_fit::{StringModel, StringParams};
use serde::{Deserialize, Serialize};

use crate::chart::{Chart, Series};
use crate::export::Animation;
pub use crate::outcome::FitOutputs;
use crate::outcome::{KindOutputs, RunError, Simulated};
pub use crate::scenario::string_fit::{Initial, METRICS, Source, StringFitSpec};
use crate::simulation::Timings;

/// The observations of `spec` (`base`: the scenario's folder).
fn load(spec: &StringFitSpec, base: &Path) -> Result<Observations, RunError> {
    match &spec.observations {
        Source::Synthetic(o) => observe(*o, &SyntheticOptions::default())
            .map(|(obs, _)| obs)
            .map_err(RunError::setup(o.name())),
        Source::File(p) => Observations::load(&base.join(p)).map_err(RunError::from),
    }
}

/// The shapes of one object in image pixels (v up, for the chart): markers and a model shape.
fn polyline(obs: &Observations, xs: &[atelier_fit::V2]) -> Vec<(f64, f64)> {
    xs.iter()
        .map(|x| {
            let p = obs.to_pixels(x);
            (p[0], f64::from(obs.image.1) - p[1])
        })
        .collect()
}

/// Run a string-fit scenario.
pub fn simulate(spec: &StringFitSpec, base: &Path) -> Result<Simulated, RunError> {
    const SCENE: &str = "string fit";
    let obs = load(spec, base)?;
    let count = obs.shapes.len();
    if spec.observed == 0 || spec.observed > count {
        return Err(RunError::out_of_range(
            SCENE,
            "observed",
            format!("{} must be 1 to the {count} shapes observed", spec.observed),
        ));
    }
    let (s, b) = match (&spec.initial, &spec.observations) {
        (Some(i), _) => (i.stretch, i.bending),
        (None, Source::Synthetic(o)) => o.table2(),
        (None, Source::File(_)) => {
            return Err(RunError::setup(SCENE)(InvalidValue::new(
                ErrorKind::MissingField,
                "initial",
                "(stretch, bending) is needed for an observation file",
            )));
        }
    };
    let initial: StringParams = paper_initial(&obs, 0, s, b).map_err(RunError::setup(SCENE))?;
    let observed: Vec<usize> = (0..spec.observed).collect();
    let unobserved: Vec<usize> = (spec.unobserved_from.max(spec.observed)..count).collect();
    let t0 = std::time::Instant::now();
    let f = fit(&obs, &observed, &initial, &spec.options).map_err(RunError::setup(SCENE))?;
    let fit_wall = t0.elapsed().as_secs_f64();
    let reproduced = reproduce(&f.model, &obs, &f.positions, &observed);
    let predicted = reproduce(&f.model, &obs, &f.positions, &unobserved);
    let guessed = reproduce(
        &StringModel::new(initial),
        &obs,
        &[obs.shape(0)],
        &unobserved,
    );
    let mut warnings = Vec::new();
    for r in reproduced.iter().chain(&predicted) {
        if r.error_px.is_none() {
            warnings.push(format!(
                "shape {}: the fitted model found no equilibrium on the way to it",
                r.shape
            ));
        }
    }
    if !f.converged {
        warnings.push(format!("the fit did not converge: {}", f.termination));
    }
    let errors: Vec<f64> = reproduced.iter().filter_map(|r| r.error_px).collect();
    let mut metrics: BTreeMap<String, Option<f64>> = BTreeMap::new();
    let mut put = |k: &str, v: Option<f64>| {
        metrics.insert(k.into(), v);
    };
    put("shapes", Some(count as f64));
    put("observed_shapes", Some(observed.len() as f64));
    put("unobserved_shapes", Some(unobserved.len() as f64));
    put("iterations", Some(f.iterations as f64));
    put("converged", Some(f64::from(u8::from(f.converged))));
    put("initial_cost", Some(f.initial_cost));
    put("cost", Some(f.cost));
    put(
        "max_observed_error_px",
        (errors.len() == reproduced.len()).then(|| errors.iter().copied().fold(0.0, f64::max)),
    );
    put("mean_observed_error_px", mean_error(&reproduced));
    put("mean_unobserved_error_px", mean_error(&predicted));
    put("initial_unobserved_error_px", mean_error(&guessed));
    put("fit_wall_s", Some(fit_wall));
    // The picture: every observed shape's markers and the model's reproduction (pixels, v up).
    let mut series = Vec::new();
    for r in &reproduced {
        if !r.positions.is_empty() {
            series.push(Series {
                name: format!("model, shape {}", r.shape),
                points: polyline(&obs, &r.positions),
            });
        }
    }
    let markers = Series {
        name: "markers".into(),
        points: observed
            .iter()
            .flat_map(|&j| obs.shapes[j].markers.iter())
            .map(|p| (p[0], f64::from(obs.image.1) - p[1]))
            .collect(),
    };
    let chart = Chart {
        title: format!(
            "{}: {} observed shapes fitted and reproduced",
            obs.name, spec.observed
        ),
        x_label: "u, px".into(),
        y_label: "height in the image, px".into(),
        series,
        markers: Some(markers),
        equal_aspect: true,
    };
    let parameters_ron = {
        let pretty = ron::ser::PrettyConfig::new().depth_limit(2);
        let body = ron::ser::to_string_pretty(&f.model, pretty).map_err(RunError::setup(SCENE))?;
        format!(
            "// The string model fitted to {} ({} shapes; docs/fit.md). SI units: s N, l m, b N·m, φ rad, mass kg.\n{body}\n",
            obs.name, spec.observed
        )
    };
    Ok(Simulated {
        fabric: obs.name.clone(),
        cloth_triangles: Vec::new(),
        cloth: Animation {
            times: Vec::new(),
            frames: Vec::new(),
        },
        solid: None,
        steps: f.iterations,
        dt: 0.0,
        simulated: 0.0,
        wall_seconds: fit_wall,
        timings: Timings::default(),
        metrics,
        warnings,
        failure: None,
        outputs: KindOutputs::Fit(Box::new(FitOutputs { parameters_ron }), chart),
        convergence: None,
        detail: crate::outcome::ClothDetail::default(),
    })
}

// ------------------------------------------------------------------------------------------
// Cloth: `atelier fit OBSERVATIONS.ron` (docs/fit.md, "Carried over to cloth"); the fit is
// `atelier_fit::fabric_fit`, this writes it.

/// What `atelier fit` writes as `fit_report.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ClothFitReport {
    /// `atelier-cloth-fit/1`.
    pub format: String,
    /// The observations' name.
    pub name: String,
    /// The observation file.
    pub observations: PathBuf,
    /// The base fabric file.
    pub base: PathBuf,
    /// Per direction.
    pub fits: Vec<DirectionFit>,
    /// The files written beside it.
    pub outputs: Vec<String>,
}

/// Fit the bending per direction of the profiles in `observations`
/// ([`atelier_fit::fabric_fit::fit_fabric`]) and write `fabric.ron` (the base fabric with the
/// fitted values) and `fit_report.json` into `out`. Every file is written under a temporary
/// name and renamed; nothing is written when the fit fails.
pub fn fit_cloth(observations: &Path, out: &Path) -> Result<ClothFitReport, RunError> {
    let fitted = fit_fabric(observations)?;
    let report = ClothFitReport {
        format: "atelier-cloth-fit/1".into(),
        name: fitted.name,
        observations: observations.to_path_buf(),
        base: fitted.base,
        fits: fitted.fits,
        outputs: vec!["fabric.ron".into(), "fit_report.json".into()],
    };
    let json = serde_json::to_string_pretty(&report).expect("a fit report serialises");
    std::fs::create_dir_all(out).map_err(|source| RunError::Output {
        path: out.to_path_buf(),
        source,
    })?;
    let io = |path: PathBuf| move |source| RunError::Output { path, source };
    let path = out.join("fabric.ron");
    files::write_atomic(&path, fitted.fabric_ron.as_bytes()).map_err(io(path))?;
    let path = out.join("fit_report.json");
    files::write_atomic(&path, json.as_bytes()).map_err(io(path))?;
    Ok(report)
}
