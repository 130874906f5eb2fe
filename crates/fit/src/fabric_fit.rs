//! A fabric's bending identified from observed strips (`atelier fit OBSERVATIONS.ron`;
//! `docs/fit.md`, "Carried over to cloth"): cantilever profiles give B through the elastica
//! ([`crate::cloth`]); turned strips give B and 2HB through the spindle strip
//! ([`crate::turned`]) or, when asked, through the PARTY solver's own strip ([`crate::strip`]).
//! The base fabric's every other value is kept. Nothing is written here: the caller writes
//! [`FabricFit::fabric_ron`] and a report.

use std::path::{Path, PathBuf};

use atelier_fabric::Fabric;
use atelier_fabric::spec::{BendingSpec, FabricSpec};
use atelier_fabric::units;
use atelier_files::{ErrorKind, FileError, InvalidValue, files};
use atelier_solver::kes::Direction as StripDirection;
use serde::{Deserialize, Serialize};

use crate::cloth::{ProfilePoint, fit_cantilever};
use crate::strip::{TurnedRun, fit_turned_party};
use crate::turned::{TurnedProfile, fit_turned};

/// Why the observations could not be fitted.
#[derive(Debug, thiserror::Error)]
pub enum FabricFitError {
    /// The observation file or the base fabric cannot be read, or a value in them is refused
    /// (file, line:column, field; a profile that cannot be fitted is named by its field).
    #[error(transparent)]
    File(#[from] FileError),
    /// The base fabric's bending in this direction is a measured loop, not KES values.
    #[error(
        "{}: the base fabric's {direction:?} bending is a measured loop; `atelier fit` replaces KES values only",
        base.display()
    )]
    MeasuredBending {
        /// The base fabric file.
        base: PathBuf,
        /// The direction.
        direction: StripDirection,
    },
    /// The fitted fabric could not be written as RON.
    #[error("writing the fabric: {0}")]
    Write(ron::Error),
    /// The fitted fabric, written, does not read back.
    #[error("the fitted fabric does not read back: {0}")]
    ReadBack(FileError),
}

/// One observed cantilever profile of a fabric strip.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CantileverObservation {
    /// Along which direction the strip was cut.
    pub direction: StripDirection,
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
    pub direction: StripDirection,
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
    /// cells ([`crate::strip`]), started from the continuum strip's fit: the values a PARTY run
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

/// What [`fit_fabric`] found.
#[derive(Clone, Debug, PartialEq)]
pub struct FabricFit {
    /// The observations' name.
    pub name: String,
    /// The base fabric file.
    pub base: PathBuf,
    /// Per direction.
    pub fits: Vec<DirectionFit>,
    /// The fitted fabric as RON (the base with the fitted values; it reads back as a fabric).
    pub fabric_ron: String,
}

/// Fit the bending rigidity (and, from turned strips, the hysteresis) per direction of the
/// profiles in the `observations` file.
pub fn fit_fabric(observations: &Path) -> Result<FabricFit, FabricFitError> {
    let profile = |points: &[Point]| -> Vec<ProfilePoint> {
        points
            .iter()
            .map(|&(s, x, droop)| ProfilePoint { s, x, droop })
            .collect()
    };
    let text = files::read_text(observations)?;
    let obs: ClothObservations = files::parse_ron(&text, observations)?;
    let located = |field: String, message: String| -> FabricFitError {
        FabricFitError::File(files::located(
            observations,
            &text,
            InvalidValue::new(ErrorKind::OutOfRange, field, message),
        ))
    };
    if obs.cantilevers.is_empty() && obs.turned.is_empty() {
        return Err(located("cantilevers".into(), "no profile".into()));
    }
    let base_path = observations
        .parent()
        .unwrap_or(Path::new("."))
        .join(&obs.base);
    let mut spec: FabricSpec = files::load_ron(&base_path)?;
    let base = Fabric::from_spec(&spec).map_err(|e| FileError::from_invalid(&base_path, e))?;
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
            StripDirection::Warp => &mut spec.bending.warp,
            StripDirection::Weft => &mut spec.bending.weft,
        };
        let BendingSpec::Kes(kes) = slot else {
            return Err(FabricFitError::MeasuredBending {
                base: base_path,
                direction,
            });
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
    let fabric_ron = ron::ser::to_string_pretty(&spec, pretty).map_err(FabricFitError::Write)?;
    // The written file must read back as a fabric.
    Fabric::from_ron_str(&fabric_ron, Path::new("fabric.ron")).map_err(FabricFitError::ReadBack)?;
    Ok(FabricFit {
        name: obs.name,
        base: base_path,
        fits,
        fabric_ron,
    })
}
