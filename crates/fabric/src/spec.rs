//! The fabric file format (RON, KES units, string enum names, unknown fields rejected).
//!
//! A [`FabricSpec`] is what a fabric file says, in the units of the KES-F report it was copied from;
//! [`crate::Fabric::from_spec`] converts it to SI once. Every value is checked while it is read, so
//! a bad value is reported at its own line and column (see [`crate::files`]). The format is
//! documented with a complete example in `docs/fabric.md`.
//!
//! Units: mass per area mg/cm², thickness mm; tensile curves as `(force gf/cm, strain %)` pairs;
//! KES tensile summary LT (–), EMT (%), RT (%), WT (gf·cm/cm²), Fm (gf/cm); shear G (gf/(cm·deg)),
//! 2HG and 2HG5 (gf/cm), shear loops as `(angle °, force gf/cm)` pairs; bending B (gf·cm²/cm), 2HB (gf·cm/cm); bending loops as
//! `(curvature cm⁻¹, moment gf·cm/cm)` pairs.

use serde::{Deserialize, Serialize};

use crate::check::{self, Validate, validated};
use crate::error::{ErrorKind, InvalidValue};
use crate::plausibility::FabricClass;
use crate::tensile::TensileSummary;
use crate::units;

/// A fabric file (the RON struct name is `Fabric`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename = "Fabric", deny_unknown_fields)]
pub struct FabricSpec {
    /// Human-readable name.
    #[serde(deserialize_with = "check::non_empty")]
    pub name: String,
    /// Where the values come from and how far they can be trusted.
    pub provenance: Provenance,
    /// The fabric class whose typical bands the plausibility check uses (optional).
    #[serde(default)]
    pub class: Option<FabricClass>,
    /// Mass per area W, mg/cm².
    #[serde(deserialize_with = "check::positive")]
    pub mass_per_area_mg_cm2: f64,
    /// Thickness T, mm.
    #[serde(deserialize_with = "check::positive")]
    pub thickness_mm: f64,
    /// Static friction coefficient of the fabric on itself.
    #[serde(deserialize_with = "check::non_negative")]
    pub friction: f64,
    /// Tensile characteristic per direction.
    pub tensile: TensileSpecs,
    /// Shear: KES values or a measured loop; required when no measured 45° tensile curves are
    /// given.
    #[serde(default)]
    pub shear: Option<ShearSpec>,
    /// Bending characteristic per direction.
    pub bending: BendingSpecs,
}

/// Provenance of a fabric's values: the source, and which properties are measured, which are
/// guesses from typical bands, and which are derived by a documented rule.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(remote = "Self", deny_unknown_fields)]
pub struct Provenance {
    /// Paper, table, report or instrument the values come from.
    pub source: String,
    /// Properties measured on the fabric.
    #[serde(default)]
    pub measured: Vec<Property>,
    /// Properties chosen from typical bands (not measurements).
    #[serde(default)]
    pub banded: Vec<Property>,
    /// Properties derived from others by a rule (for example bias bending).
    #[serde(default)]
    pub derived: Vec<Property>,
    /// Anything else a reader should know.
    #[serde(default)]
    pub notes: String,
}
validated!(Provenance);

impl Validate for Provenance {
    fn validate(&self) -> Result<(), InvalidValue> {
        if self.source.trim().is_empty() {
            return Err(InvalidValue::new(
                ErrorKind::OutOfRange,
                "source",
                "must name a source",
            ));
        }
        let lists = [
            ("measured", &self.measured),
            ("banded", &self.banded),
            ("derived", &self.derived),
        ];
        for (i, (a, la)) in lists.iter().enumerate() {
            for (b, lb) in &lists[i + 1..] {
                if let Some(p) = la.iter().find(|p| lb.contains(p)) {
                    return Err(InvalidValue::new(
                        ErrorKind::Inconsistent,
                        *b,
                        format!("{p:?} is listed as both {a} and {b}"),
                    ));
                }
            }
        }
        Ok(())
    }
}

/// A property a provenance entry speaks of.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Property {
    /// Mass per area W.
    MassPerArea,
    /// Thickness T.
    Thickness,
    /// Friction coefficient.
    Friction,
    /// Warp and weft tensile curves or summary values.
    Tensile,
    /// Bias tensile curves.
    BiasTensile,
    /// KES shear values.
    Shear,
    /// Bending rigidity B.
    BendingRigidity,
    /// Bending hysteresis 2HB.
    BendingHysteresis,
    /// Bias bending values.
    BiasBending,
}

/// Tensile data in the four directions; warp and weft are required, the biases optional.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TensileSpecs {
    /// 0°, along the warp.
    pub warp: TensileSpec,
    /// 90°, along the weft.
    pub weft: TensileSpec,
    /// 45° bias; from `shear` when absent.
    #[serde(default)]
    pub bias45: Option<TensileSpec>,
    /// 135° bias; the 45° data when absent.
    #[serde(default)]
    pub bias135: Option<TensileSpec>,
}

/// A tensile characteristic: KES summary values or a measured loop.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum TensileSpec {
    /// KES summary values, synthesised into a loop (`method.md` §1.4).
    Kes(KesTensile),
    /// Measured loading and unloading branches.
    Measured(MeasuredLoop),
}

/// KES tensile summary values.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(remote = "Self", deny_unknown_fields)]
pub struct KesTensile {
    /// Linearity LT, in (0, 2).
    #[serde(deserialize_with = "check::positive")]
    pub lt: f64,
    /// Extension at the maximum force EMT, %.
    #[serde(deserialize_with = "check::positive")]
    pub emt_percent: f64,
    /// Resilience RT, %, in (0, 100].
    #[serde(deserialize_with = "check::positive")]
    pub rt_percent: f64,
    /// Tensile energy WT, gf·cm/cm²; when given it must equal Fm·LT·EMT/2 (2.5·LT·EMT at the
    /// standard Fm) within 2 % (published values are rounded).
    #[serde(default, deserialize_with = "check::opt_positive")]
    pub wt_gf_cm_cm2: Option<f64>,
    /// Maximum force Fm, gf/cm (default 500, the KES standard).
    #[serde(default, deserialize_with = "check::opt_positive")]
    pub fm_gf_cm: Option<f64>,
}
validated!(KesTensile);

impl KesTensile {
    /// The same values in SI.
    pub fn summary(&self) -> TensileSummary {
        TensileSummary {
            lt: self.lt,
            emt: units::strain_from_percent(self.emt_percent),
            rt: units::strain_from_percent(self.rt_percent),
            f_max: units::force_from_kes(self.fm_gf_cm.unwrap_or(500.0)),
        }
    }
}

/// A list of `(x, y)` points.
pub type Points = Vec<(f64, f64)>;

/// Relative tolerance of the WT = Fm·LT·EMT/2 identity for published (rounded) values.
pub const WT_TOLERANCE: f64 = 0.02;

impl Validate for KesTensile {
    fn validate(&self) -> Result<(), InvalidValue> {
        self.summary().validate().map_err(|e| InvalidValue {
            field: match e.field.as_str() {
                "emt" => "emt_percent".into(),
                "rt" => "rt_percent".into(),
                "f_max" => "fm_gf_cm".into(),
                other => other.into(),
            },
            ..e
        })?;
        if let Some(wt) = self.wt_gf_cm_cm2 {
            let expected = self.fm_gf_cm.unwrap_or(500.0) * self.lt * self.emt_percent / 200.0;
            if (wt - expected).abs() > WT_TOLERANCE * expected {
                return Err(InvalidValue::new(
                    ErrorKind::Inconsistent,
                    "wt_gf_cm_cm2",
                    format!(
                        "WT = {wt} but Fm·LT·EMT/2 = {expected:.4} (2.5·LT·EMT at Fm = 500); \
                         one of LT, EMT, WT is wrong"
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// A measured tensile loop: `(force gf/cm, strain %)` pairs, force increasing from 0 in both
/// branches, both branches ending at the same maximum force.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(remote = "Self", deny_unknown_fields)]
pub struct MeasuredLoop {
    /// Loading branch.
    #[serde(deserialize_with = "check::branch")]
    pub loading: Vec<(f64, f64)>,
    /// Unloading branch (listed with force increasing, like the loading branch).
    #[serde(deserialize_with = "check::branch")]
    pub unloading: Vec<(f64, f64)>,
}
validated!(MeasuredLoop);

impl MeasuredLoop {
    /// The branches in SI: `(force N/m, strain)`.
    pub fn si_branches(&self) -> (Points, Points) {
        let conv = |v: &[(f64, f64)]| -> Vec<(f64, f64)> {
            v.iter()
                .map(|&(f, e)| (units::force_from_kes(f), units::strain_from_percent(e)))
                .collect()
        };
        (conv(&self.loading), conv(&self.unloading))
    }

    /// Build the loop.
    pub fn to_loop(&self) -> Result<crate::TensileLoop, InvalidValue> {
        let (up, down) = self.si_branches();
        crate::TensileLoop::from_measured(&up, &down)
    }
}

impl Validate for MeasuredLoop {
    fn validate(&self) -> Result<(), InvalidValue> {
        self.to_loop().map(|_| ())
    }
}

/// Shear data: the KES values (G, 2HG, optional 2HG5) or a measured loop (`measured`), one or
/// the other; and the locking angle used when the bias tensile loop is derived from them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(remote = "Self", deny_unknown_fields)]
pub struct ShearSpec {
    /// Shear stiffness G, gf/(cm·deg); required unless `measured` is given.
    #[serde(
        default,
        deserialize_with = "check::opt_positive",
        skip_serializing_if = "Option::is_none"
    )]
    pub g_gf_cm_deg: Option<f64>,
    /// Hysteresis width at 0.5°, 2HG, gf/cm; required unless `measured` is given.
    #[serde(
        default,
        deserialize_with = "check::opt_non_negative",
        skip_serializing_if = "Option::is_none"
    )]
    pub two_hg_gf_cm: Option<f64>,
    /// Hysteresis width at 5°, 2HG5, gf/cm (optional; the width stays 2HG without it).
    #[serde(
        default,
        deserialize_with = "check::opt_non_negative",
        skip_serializing_if = "Option::is_none"
    )]
    pub two_hg5_gf_cm: Option<f64>,
    /// Shear locking (jamming) angle, degrees, in (0, 90); default 40 (an assumption, see
    /// `docs/fabric.md`).
    #[serde(
        default,
        deserialize_with = "check::opt_locking_angle",
        skip_serializing_if = "Option::is_none"
    )]
    pub locking_angle_deg: Option<f64>,
    /// A measured KES-FB1 loop, reduced to G, 2HG and 2HG5 as KES defines them (instead of the
    /// three values).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub measured: Option<MeasuredShear>,
}
validated!(ShearSpec);

/// The KES values of a shear section, in KES units: `(G gf/(cm·deg), 2HG gf/cm, 2HG5 gf/cm)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KesShearValues {
    /// G, gf/(cm·deg).
    pub g_gf_cm_deg: f64,
    /// 2HG, gf/cm.
    pub two_hg_gf_cm: f64,
    /// 2HG5, gf/cm, when known.
    pub two_hg5_gf_cm: Option<f64>,
}

impl ShearSpec {
    /// A section of KES values (no measured loop, default locking angle).
    pub fn kes(g_gf_cm_deg: f64, two_hg_gf_cm: f64, two_hg5_gf_cm: Option<f64>) -> Self {
        Self {
            g_gf_cm_deg: Some(g_gf_cm_deg),
            two_hg_gf_cm: Some(two_hg_gf_cm),
            two_hg5_gf_cm,
            locking_angle_deg: None,
            measured: None,
        }
    }

    /// The KES values this section gives: as written, or fitted to the measured loop.
    pub fn kes_values(&self) -> Result<KesShearValues, InvalidValue> {
        match (&self.measured, self.g_gf_cm_deg, self.two_hg_gf_cm) {
            (Some(m), None, None) if self.two_hg5_gf_cm.is_none() => {
                let l = m.fit().map_err(|e| e.within("measured"))?.shear_loop;
                let (lo, hi) = crate::shear::KES_SHEAR_ANGLES;
                Ok(KesShearValues {
                    g_gf_cm_deg: units::shear_stiffness_to_kes(l.stiffness()),
                    two_hg_gf_cm: units::force_to_kes(2.0 * l.half_width(lo)),
                    two_hg5_gf_cm: Some(units::force_to_kes(2.0 * l.half_width(hi))),
                })
            }
            (Some(_), _, _) => Err(InvalidValue::new(
                ErrorKind::Inconsistent,
                "measured",
                "give either the KES values (g_gf_cm_deg, two_hg_gf_cm, two_hg5_gf_cm) or a \
                 measured loop, not both",
            )),
            (None, None, _) => Err(InvalidValue::new(
                ErrorKind::MissingField,
                "g_gf_cm_deg",
                "missing field `g_gf_cm_deg` (or give a `measured` loop)",
            )),
            (None, _, None) => Err(InvalidValue::new(
                ErrorKind::MissingField,
                "two_hg_gf_cm",
                "missing field `two_hg_gf_cm` (or give a `measured` loop)",
            )),
            (None, Some(g), Some(two_hg)) => Ok(KesShearValues {
                g_gf_cm_deg: g,
                two_hg_gf_cm: two_hg,
                two_hg5_gf_cm: self.two_hg5_gf_cm,
            }),
        }
    }

    /// The reconstructed shear loop (SI).
    pub fn to_loop(&self) -> Result<crate::ShearLoop, InvalidValue> {
        let k = self.kes_values()?;
        crate::ShearLoop::from_kes_units(k.g_gf_cm_deg, k.two_hg_gf_cm, k.two_hg5_gf_cm).map_err(
            |e| InvalidValue {
                field: match e.field.as_str() {
                    "g" => "g_gf_cm_deg".into(),
                    "two_hg" => "two_hg_gf_cm".into(),
                    "two_hg5" => "two_hg5_gf_cm".into(),
                    other => other.into(),
                },
                ..e
            },
        )
    }
}

impl Validate for ShearSpec {
    fn validate(&self) -> Result<(), InvalidValue> {
        self.to_loop().map(|_| ())
    }
}

/// A measured KES-FB1 shear loop in KES units: the two branches as `(angle °, force gf/cm)`
/// points, each listed with the angle increasing. `upper` is the branch recorded while the angle
/// rises (−γmax → +γmax), `lower` the one recorded while it falls (+γmax → −γmax), read back
/// from −γmax. Each branch: at least 4 points covering −5°…+5°, angles strictly increasing and
/// within ±30°, forces non-decreasing and within ±200 gf/cm; the lower branch never above the
/// upper.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(remote = "Self", deny_unknown_fields)]
pub struct MeasuredShear {
    /// The branch recorded with the angle rising.
    #[serde(deserialize_with = "check::shear_branch")]
    pub upper: Vec<(f64, f64)>,
    /// The branch recorded with the angle falling (listed with the angle increasing).
    #[serde(deserialize_with = "check::shear_branch")]
    pub lower: Vec<(f64, f64)>,
}
validated!(MeasuredShear);

impl MeasuredShear {
    /// The branches in SI: `(angle rad, force N/m)`.
    pub fn si_branches(&self) -> (Points, Points) {
        let conv = |v: &[(f64, f64)]| -> Vec<(f64, f64)> {
            v.iter()
                .map(|&(a, f)| (a.to_radians(), units::force_from_kes(f)))
                .collect()
        };
        (conv(&self.upper), conv(&self.lower))
    }

    /// Reduce the loop to G, 2HG and 2HG5 (see [`crate::shear::fit_shear`]).
    pub fn fit(&self) -> Result<crate::ShearFit, InvalidValue> {
        crate::shear::check_shear_branch(&self.upper).map_err(|e| e.within("upper"))?;
        crate::shear::check_shear_branch(&self.lower).map_err(|e| e.within("lower"))?;
        crate::shear::check_shear_branches_apart(&self.upper, &self.lower)?;
        let (up, down) = self.si_branches();
        crate::shear::fit_checked(&up, &down)
    }
}

impl Validate for MeasuredShear {
    fn validate(&self) -> Result<(), InvalidValue> {
        self.fit().map(|_| ())
    }
}

/// Bending data in the four directions; warp and weft are required, the biases optional.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BendingSpecs {
    /// 0°, along the warp.
    pub warp: BendingSpec,
    /// 90°, along the weft.
    pub weft: BendingSpec,
    /// 45° bias; derived from warp and weft when absent (see `docs/fabric.md`).
    #[serde(default)]
    pub bias45: Option<BendingSpec>,
    /// 135° bias; the 45° data when absent.
    #[serde(default)]
    pub bias135: Option<BendingSpec>,
}

/// A bending characteristic: KES values or a measured loop to fit.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum BendingSpec {
    /// B and 2HB.
    Kes(KesBending),
    /// A measured loop, fitted by least squares.
    Measured(MeasuredBending),
}

/// KES bending values.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KesBending {
    /// Bending rigidity B, gf·cm²/cm.
    #[serde(deserialize_with = "check::positive")]
    pub b_gf_cm2_cm: f64,
    /// Hysteresis width 2HB, gf·cm/cm.
    #[serde(deserialize_with = "check::non_negative")]
    pub two_hb_gf_cm_cm: f64,
}

/// A measured bending loop: `(curvature cm⁻¹, moment gf·cm/cm)` in the order measured.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(remote = "Self", deny_unknown_fields)]
pub struct MeasuredBending {
    /// The loop.
    pub points: Vec<(f64, f64)>,
    /// Curvature band `(low, high)` in cm⁻¹ used by the fit (default the KES band 0.5–1.5).
    #[serde(default)]
    pub fit_band_per_cm: Option<(f64, f64)>,
}
validated!(MeasuredBending);

impl MeasuredBending {
    /// Fit the spindle model.
    pub fn fit(&self) -> Result<crate::bending::SpindleFit, InvalidValue> {
        let pts: Vec<(f64, f64)> = self
            .points
            .iter()
            .map(|&(k, m)| (units::curvature_from_kes(k), units::moment_from_kes(m)))
            .collect();
        let band = self
            .fit_band_per_cm
            .map_or(crate::bending::KES_FIT_BAND, |(a, b)| {
                (units::curvature_from_kes(a), units::curvature_from_kes(b))
            });
        crate::bending::fit_spindle(&pts, band).map_err(|e| e.within("points"))
    }
}

impl Validate for MeasuredBending {
    fn validate(&self) -> Result<(), InvalidValue> {
        if let Some((a, b)) = self.fit_band_per_cm
            && !(a.is_finite() && b.is_finite() && 0.0 <= a && a < b)
        {
            return Err(InvalidValue::new(
                ErrorKind::OutOfRange,
                "fit_band_per_cm",
                format!("({a}, {b}) must satisfy 0 ≤ low < high"),
            ));
        }
        self.fit().map(|_| ())
    }
}
