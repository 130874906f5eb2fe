//! String-identification scenarios (`ScenarioKind::StringFit`; `docs/fit.md`): the method of
//! Sudoh et al. on one object's observations — the first J shapes fitted, each reproduced, the
//! later shapes predicted by the fitted model and by the initial values — with the errors as
//! metrics, the fitted parameters as `parameters.ron` and the shapes as `final.png`.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use atelier_fit::experiment::{fit, mean_error, paper_initial, reproduce};
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
            .map_err(|e| RunError::Setup(format!("synthetic {}: {e}", o.name()))),
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
    let setup = |e: String| RunError::Setup(format!("string fit: {e}"));
    let obs = load(spec, base)?;
    let count = obs.shapes.len();
    if spec.observed == 0 || spec.observed > count {
        return Err(setup(format!(
            "`observed` = {} must be 1 to the {count} shapes observed",
            spec.observed
        )));
    }
    let (s, b) = match (&spec.initial, &spec.observations) {
        (Some(i), _) => (i.stretch, i.bending),
        (None, Source::Synthetic(o)) => o.table2(),
        (None, Source::File(_)) => {
            return Err(setup(
                "`initial` (stretch, bending) is needed for an observation file".into(),
            ));
        }
    };
    let initial: StringParams = paper_initial(&obs, 0, s, b).map_err(|e| setup(e.to_string()))?;
    let observed: Vec<usize> = (0..spec.observed).collect();
    let unobserved: Vec<usize> = (spec.unobserved_from.max(spec.observed)..count).collect();
    let t0 = std::time::Instant::now();
    let f = fit(&obs, &observed, &initial, &spec.options).map_err(|e| setup(e.to_string()))?;
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
        let body = ron::ser::to_string_pretty(&f.model, pretty)
            .map_err(|e| setup(format!("writing the parameters: {e}")))?;
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
    })
}

// ------------------------------------------------------------------------------------------
// Cloth: `atelier fit OBSERVATIONS.ron` (docs/fit.md, "Carried over to cloth").

/// One observed cantilever profile of a fabric strip.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CantileverObservation {
    /// Along which direction the strip was cut.
    pub direction: crate::scenario::StripDirection,
    /// Overhang L beyond the platform edge, m.
    pub overhang: f64,
    /// The centreline's points `(s, x, droop)`: arc length from the edge, distance forward,
    /// droop below the edge, m.
    pub points: Vec<Point>,
}

/// One strip observed with its clamp turned downwards (docs/fit.md, bending hysteresis).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TurnedObservation {
    /// Along which direction the strip was cut.
    pub direction: crate::scenario::StripDirection,
    /// Overhang L beyond the clamp's edge, m.
    pub overhang: f64,
    /// The profiles at increasing clamp angles: `(clamp_deg, points)`, points `(s, x, droop)`
    /// in the fixed frame (x forward, droop downwards from the clamp's edge), m.
    pub profiles: Vec<(f64, Vec<Point>)>,
}

/// An observed centreline point `(s, x, droop)`, m.
pub type Point = (f64, f64, f64);

/// Observations of a fabric to fit (RON struct name `ClothObservations`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename = "ClothObservations", deny_unknown_fields)]
pub struct ClothObservations {
    /// What was observed.
    pub name: String,
    /// Where the observations come from.
    pub provenance: String,
    /// The fabric file whose other values are kept (its mass per area gives w), relative to
    /// the observation file.
    pub base: PathBuf,
    /// Cantilever profiles (B), at most one observation per direction in both lists.
    #[serde(default)]
    pub cantilevers: Vec<CantileverObservation>,
    /// Turned-strip profiles (B and 2HB).
    #[serde(default)]
    pub turned: Vec<TurnedObservation>,
    /// Fit the turned strips' B and 2HB through the PARTY solver's own strip of this many
    /// cells (`atelier::strip`), started from the continuum strip's fit: the values a PARTY run
    /// at that resolution needs. None (default): the continuum strip only.
    #[serde(default)]
    pub solver_cells: Option<usize>,
}

/// The fit of one direction.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DirectionFit {
    /// `Warp` or `Weft`.
    pub direction: String,
    /// Bending rigidity fitted, N·m (and in KES units, gf·cm²/cm).
    pub b_n_m: f64,
    /// The same in gf·cm²/cm.
    pub b_gf_cm2_cm: f64,
    /// The base fabric's, gf·cm²/cm.
    pub base_b_gf_cm2_cm: f64,
    /// Bending length c = (B/w)^(1/3), m.
    pub bending_length_m: f64,
    /// λ = wL³/B of the fitted elastica.
    pub lambda: f64,
    /// RMS distance of the points from the fitted elastica, m.
    pub rms_m: f64,
    /// Points used.
    pub points: usize,
    /// `cantilever` (the elastica: B) or `turned` (the spindle strip: B and 2HB).
    pub observation: String,
    /// Hysteresis 2HB fitted, gf·cm/cm (turned strips only).
    pub two_hb_gf_cm_cm: Option<f64>,
    /// The base fabric's 2HB, gf·cm/cm (turned strips only).
    pub base_two_hb_gf_cm_cm: Option<f64>,
    /// RMS of the best elastic strip to the same profiles, m (turned strips only).
    pub elastic_rms_m: Option<f64>,
    /// The forward model: `elastica`, `spindle strip`, or `PARTY solver, N cells` (then the
    /// RMS is the solver strip's).
    pub forward_model: String,
}

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

/// Fit the bending rigidity per direction of the cantilever profiles in `observations` and
/// write `fabric.ron` (the base fabric with those B) and `fit_report.json` into `out`. Every
/// file is written under a temporary name and renamed; nothing is written when the fit fails.
pub fn fit_cloth(observations: &Path, out: &Path) -> Result<ClothFitReport, RunError> {
    use crate::strip::{TurnedRun, fit_turned_party};
    use atelier_fabric::spec::{BendingSpec, FabricSpec};
    use atelier_fabric::units;
    use atelier_fabric::{ErrorKind, FileError, InvalidValue, files};
    use atelier_fit::cloth::{ProfilePoint, fit_cantilever};
    use atelier_fit::turned::{TurnedProfile, fit_turned};
    let setup = |e: String| RunError::Setup(e);
    let profile = |points: &[Point]| -> Vec<ProfilePoint> {
        points
            .iter()
            .map(|&(s, x, droop)| ProfilePoint { s, x, droop })
            .collect()
    };
    let text = files::read_text(observations).map_err(|e| setup(e.to_string()))?;
    let obs: ClothObservations =
        files::parse_ron(&text, observations).map_err(|e| setup(e.to_string()))?;
    let located = |field: String, message: String| -> RunError {
        let e: FileError = files::located(
            observations,
            &text,
            InvalidValue::new(ErrorKind::OutOfRange, field, message),
        );
        setup(e.to_string())
    };
    if obs.cantilevers.is_empty() && obs.turned.is_empty() {
        return Err(located("cantilevers".into(), "no profile".into()));
    }
    let base_path = observations
        .parent()
        .unwrap_or(Path::new("."))
        .join(&obs.base);
    let mut spec: FabricSpec = files::load_ron(&base_path).map_err(|e| setup(e.to_string()))?;
    let base = atelier_fabric::Fabric::from_spec(&spec)
        .map_err(|e| setup(FileError::from_invalid(&base_path, e).to_string()))?;
    let w = base.weight_per_area();
    // Every observation fitted first: (direction, field, B, Some(M₀) for turned, fit record).
    let mut fitted = Vec::new();
    for (k, c) in obs.cantilevers.iter().enumerate() {
        let fit = fit_cantilever(&profile(&c.points), c.overhang)
            .map_err(|e| located(format!("cantilevers[{k}]"), e.to_string()))?;
        let b = w * fit.bending_length.powi(3);
        let record = (
            fit.lambda,
            fit.bending_length,
            fit.rms,
            None,
            c.points.len(),
            "elastica".to_string(),
        );
        fitted.push((c.direction, format!("cantilevers[{k}]"), b, None, record));
    }
    for (k, t) in obs.turned.iter().enumerate() {
        let profiles: Vec<TurnedProfile> = t
            .profiles
            .iter()
            .map(|(clamp_deg, points)| TurnedProfile {
                clamp_deg: *clamp_deg,
                points: profile(points),
            })
            .collect();
        let fit = fit_turned(&profiles, t.overhang, w)
            .map_err(|e| located(format!("turned[{k}]"), e.to_string()))?;
        let (b, m0, rms, model) = match obs.solver_cells {
            None => (
                fit.rigidity,
                fit.residual_moment,
                fit.rms,
                "spindle strip".to_string(),
            ),
            Some(segments) => {
                let run = TurnedRun {
                    segments,
                    ..TurnedRun::default()
                };
                let party = fit_turned_party(
                    &profiles,
                    t.overhang,
                    &base,
                    t.direction,
                    &run,
                    (fit.rigidity, fit.residual_moment),
                )
                .map_err(|e| located(format!("turned[{k}]"), e.to_string()))?;
                (
                    party.rigidity,
                    party.residual_moment,
                    party.rms,
                    format!("PARTY solver, {segments} cells"),
                )
            }
        };
        let c = (b / w).cbrt();
        let n = t.profiles.iter().map(|p| p.1.len()).sum();
        let record = (
            w * t.overhang.powi(3) / b,
            c,
            rms,
            Some(fit.elastic_rms),
            n,
            model,
        );
        fitted.push((t.direction, format!("turned[{k}]"), b, Some(m0), record));
    }
    let mut fits: Vec<DirectionFit> = Vec::new();
    for (direction, field, b, m0, (lambda, c, rms, elastic_rms, points, forward_model)) in fitted {
        let name = format!("{direction:?}");
        if fits.iter().any(|f| f.direction == name) {
            return Err(located(
                format!("{field}.direction"),
                format!("a second {name} observation"),
            ));
        }
        let slot = match direction {
            crate::scenario::StripDirection::Warp => &mut spec.bending.warp,
            crate::scenario::StripDirection::Weft => &mut spec.bending.weft,
        };
        let BendingSpec::Kes(kes) = slot else {
            return Err(setup(format!(
                "{}: the base fabric's {name} bending is a measured loop; `atelier fit` replaces KES values only",
                base_path.display()
            )));
        };
        let (base_b, base_two_hb) = (kes.b_gf_cm2_cm, kes.two_hb_gf_cm_cm);
        kes.b_gf_cm2_cm = b / units::BENDING_RIGIDITY;
        let two_hb = m0.map(|m0| 2.0 * m0 / units::BENDING_MOMENT);
        if let Some(h) = two_hb {
            kes.two_hb_gf_cm_cm = h;
        }
        fits.push(DirectionFit {
            direction: name,
            b_n_m: b,
            b_gf_cm2_cm: b / units::BENDING_RIGIDITY,
            base_b_gf_cm2_cm: base_b,
            bending_length_m: c,
            lambda,
            rms_m: rms,
            points,
            observation: if m0.is_some() { "turned" } else { "cantilever" }.into(),
            two_hb_gf_cm_cm: two_hb,
            base_two_hb_gf_cm_cm: m0.map(|_| base_two_hb),
            elastic_rms_m: elastic_rms,
            forward_model,
        });
    }
    spec.name = format!("{} (fitted to {})", spec.name, obs.name);
    spec.provenance.notes = format!(
        "{} Fitted by `atelier fit`: {} to the profiles of {} ({}); every other value as in {}.",
        spec.provenance.notes,
        fits.iter()
            .map(|f| format!(
                "{} {}",
                f.direction.to_lowercase(),
                if f.two_hb_gf_cm_cm.is_some() {
                    "B and 2HB (turned strip)"
                } else {
                    "B (cantilever)"
                }
            ))
            .collect::<Vec<_>>()
            .join(", "),
        observations.display(),
        obs.provenance,
        obs.base.display()
    );
    let pretty = ron::ser::PrettyConfig::new().depth_limit(4).extensions(
        ron::extensions::Extensions::IMPLICIT_SOME
            | ron::extensions::Extensions::UNWRAP_VARIANT_NEWTYPES,
    );
    let fabric_text = ron::ser::to_string_pretty(&spec, pretty)
        .map_err(|e| setup(format!("writing the fabric: {e}")))?;
    // The written file must read back as a fabric.
    atelier_fabric::Fabric::from_ron_str(&fabric_text, Path::new("fabric.ron"))
        .map_err(|e| setup(format!("the fitted fabric does not read back: {e}")))?;
    std::fs::create_dir_all(out).map_err(|source| RunError::Output {
        path: out.to_path_buf(),
        source,
    })?;
    let io = |path: PathBuf| move |source| RunError::Output { path, source };
    let path = out.join("fabric.ron");
    files::write_atomic(&path, fabric_text.as_bytes()).map_err(io(path))?;
    let report = ClothFitReport {
        format: "atelier-cloth-fit/1".into(),
        name: obs.name.clone(),
        observations: observations.to_path_buf(),
        base: base_path,
        fits,
        outputs: vec!["fabric.ron".into(), "fit_report.json".into()],
    };
    let json = serde_json::to_string_pretty(&report)
        .map_err(|e| setup(format!("writing the report: {e}")))?;
    let path = out.join("fit_report.json");
    files::write_atomic(&path, json.as_bytes()).map_err(io(path))?;
    Ok(report)
}
