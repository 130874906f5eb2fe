//! `atelier.Fabric`: a fabric read from its file or built from KES values given as plain dicts,
//! and its own characteristics sampled through one KES cycle as numpy arrays.

use std::path::PathBuf;

use atelier_fabric::spec::Property;
use atelier_fabric::{Fabric, FabricSpec, TensileState, kes_bending_test, kes_shear_test, units};
use numpy::PyArray2;
use pyo3::prelude::*;
use serde_json::{Map, Value, json};

use crate::errors::{Failure, detached, guarded, invalid};
use crate::values::{array, deserialize, to_json, to_json_object};

/// Friction `Fabric.from_kes` assumes when none is given (fabric on fabric, static): the silk
/// and polyester fixtures' banded value. The fabric's provenance then lists `Friction` as
/// banded.
pub const DEFAULT_FRICTION: f64 = 0.3;

/// A fabric: its mass, thickness, friction and measured mechanics (tensile, bending and shear
/// characteristics with their hysteresis, in the warp, weft and bias directions), in SI inside.
///
/// Build one with `Fabric.load(path)` (a fabric RON file, docs/fabric.md) or
/// `Fabric.from_kes(...)` (KES values as plain dicts, the file's field names as keys).
#[pyclass(frozen, module = "atelier", name = "Fabric")]
#[derive(Clone)]
pub struct PyFabric {
    /// The fabric, SI.
    pub fabric: Fabric,
    /// Where it came from: the file, or `from_kes`.
    origin: String,
}

/// A grain direction of the loops: `warp` or `weft`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Grain {
    /// 0°, along the warp.
    Warp,
    /// 90°, along the weft.
    Weft,
}

impl Grain {
    /// Parse `warp` or `weft` (any case); a `ValueError` naming `field` otherwise.
    pub fn parse(text: &str, field: &str) -> Result<Self, Failure> {
        match text.to_ascii_lowercase().as_str() {
            "warp" => Ok(Self::Warp),
            "weft" => Ok(Self::Weft),
            _ => Err(Failure::value(
                field,
                format!("`{text}`: use \"warp\" or \"weft\""),
            )),
        }
    }

    /// The lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Warp => "warp",
            Self::Weft => "weft",
        }
    }
}

/// The most samples a loop may be asked for (per leg: force levels, per cm⁻¹, per degree).
const MAX_SAMPLES: usize = 100_000;

fn samples(n: usize, field: &str) -> Result<usize, Failure> {
    if (1..=MAX_SAMPLES).contains(&n) {
        Ok(n)
    } else {
        Err(Failure::value(
            field,
            format!("{n}: use 1 to {MAX_SAMPLES}"),
        ))
    }
}

/// The tensile, bending and shear entries of `from_kes` as the file's enum variants: a
/// direction given as `{"lt": …}` is `Kes(lt: …)`, one with `loading`/`unloading` (tensile) or
/// `points` (bending) is `Measured(…)`; `{"Kes": {…}}` and `{"Measured": {…}}` are taken as they
/// are.
fn tag_directions(section: &mut Value, measured_keys: &[&str]) {
    let Value::Object(directions) = section else {
        return;
    };
    for (_, entry) in directions.iter_mut() {
        let Value::Object(fields) = entry else {
            continue;
        };
        let tagged = fields.len() == 1 && fields.keys().all(|k| k == "Kes" || k == "Measured");
        if tagged {
            continue;
        }
        let variant = if measured_keys.iter().any(|k| fields.contains_key(*k)) {
            "Measured"
        } else {
            "Kes"
        };
        let inner = std::mem::take(fields);
        let mut wrapped = Map::new();
        wrapped.insert(variant.to_string(), Value::Object(inner));
        *entry = Value::Object(wrapped);
    }
}

impl PyFabric {
    fn from_spec_value(spec: Value, origin: String) -> Result<Self, Failure> {
        let spec: FabricSpec = deserialize(spec, "")?;
        let fabric = Fabric::from_spec(&spec).map_err(|e| invalid("", &e))?;
        Ok(Self { fabric, origin })
    }

    fn tensile(&self, grain: Grain) -> &atelier_fabric::TensileLoop {
        match grain {
            Grain::Warp => &self.fabric.tensile.warp,
            Grain::Weft => &self.fabric.tensile.weft,
        }
    }

    fn bending(&self, grain: Grain) -> &atelier_fabric::Spindle {
        match grain {
            Grain::Warp => &self.fabric.bending.warp,
            Grain::Weft => &self.fabric.bending.weft,
        }
    }
}

/// A number shortly: four significant digits, no trailing zeros.
fn short(v: f64) -> String {
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s.is_empty() || s == "-" {
        "0".into()
    } else {
        s.into()
    }
}

#[pymethods]
impl PyFabric {
    /// Read a fabric file (RON, KES units; docs/fabric.md). Raises `AtelierError` naming the
    /// file, line:column and field when it does not read or a value is refused.
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        detached(py, "Fabric.load", move || {
            let fabric = Fabric::load(&path).map_err(Failure::atelier)?;
            Ok(Self {
                fabric,
                origin: path.display().to_string(),
            })
        })
    }

    /// A fabric from KES values, as a fabric file would give them (KES units, the file's field
    /// names as keys; docs/fabric.md §7):
    ///
    /// - `mass_per_area_mg_cm2` (mg/cm²), `thickness_mm` (mm);
    /// - `tensile`: `{"warp": {...}, "weft": {...}}` (optional `bias45`, `bias135`), each
    ///   `{"lt": –, "emt_percent": %, "rt_percent": %}` (optional `wt_gf_cm_cm2`, `fm_gf_cm`) or
    ///   a measured loop `{"loading": [(gf/cm, %), ...], "unloading": [...]}`;
    /// - `bending`: `{"warp": {"b_gf_cm2_cm": ..., "two_hb_gf_cm_cm": ...}, "weft": {...}}` or
    ///   measured `{"points": [(1/cm, gf·cm/cm), ...]}`;
    /// - `shear`: `{"g_gf_cm_deg": ..., "two_hg_gf_cm": ..., "two_hg5_gf_cm": ...}` (required
    ///   unless a measured `bias45` tensile loop is given);
    /// - `friction` (fabric on fabric; default 0.3, then listed as banded in the provenance),
    ///   `provenance` (`{"source": ..., "measured": [...], "banded": [...], ...}`), `fabric_class`
    ///   (`"Silk"`, `"CottonBroadcloth"`, ... for the plausibility bands).
    ///
    /// An unknown key, a missing field or a refused value raises `ValueError` naming the field
    /// (`tensile.warp.lt`); a value of the wrong type raises `TypeError` naming it.
    #[staticmethod]
    #[pyo3(signature = (name, mass_per_area_mg_cm2, thickness_mm, *, tensile, bending, shear=None, friction=None, provenance=None, fabric_class=None))]
    #[allow(clippy::too_many_arguments)]
    fn from_kes(
        py: Python<'_>,
        name: String,
        mass_per_area_mg_cm2: &Bound<'_, PyAny>,
        thickness_mm: &Bound<'_, PyAny>,
        tensile: &Bound<'_, PyAny>,
        bending: &Bound<'_, PyAny>,
        shear: Option<&Bound<'_, PyAny>>,
        friction: Option<&Bound<'_, PyAny>>,
        provenance: Option<&Bound<'_, PyAny>>,
        fabric_class: Option<String>,
    ) -> PyResult<Self> {
        guarded("Fabric.from_kes", || {
            let mut tensile = to_json_object(tensile, "tensile")?;
            tag_directions(&mut tensile, &["loading", "unloading"]);
            let mut bending = to_json_object(bending, "bending")?;
            tag_directions(&mut bending, &["points"]);
            let shear = shear.map(|s| to_json_object(s, "shear")).transpose()?;
            let friction = friction.map(|f| to_json(f, "friction")).transpose()?;
            let provenance = match provenance {
                Some(p) => to_json_object(p, "provenance")?,
                None => {
                    let banded: Vec<Property> = if friction.is_none() {
                        vec![Property::Friction]
                    } else {
                        Vec::new()
                    };
                    json!({
                        "source": "given in Python to atelier.Fabric.from_kes",
                        "banded": banded,
                        "notes": if friction.is_none() {
                            format!("friction {DEFAULT_FRICTION} assumed (Fabric.from_kes's default)")
                        } else {
                            String::new()
                        },
                    })
                }
            };
            let mut spec = Map::new();
            spec.insert("name".into(), Value::String(name));
            spec.insert("provenance".into(), provenance);
            if let Some(c) = fabric_class {
                spec.insert("class".into(), Value::String(c));
            }
            spec.insert(
                "mass_per_area_mg_cm2".into(),
                to_json(mass_per_area_mg_cm2, "mass_per_area_mg_cm2")?,
            );
            spec.insert(
                "thickness_mm".into(),
                to_json(thickness_mm, "thickness_mm")?,
            );
            spec.insert(
                "friction".into(),
                friction.unwrap_or_else(|| json!(DEFAULT_FRICTION)),
            );
            spec.insert("tensile".into(), tensile);
            if let Some(s) = shear {
                spec.insert("shear".into(), s);
            }
            spec.insert("bending".into(), bending);
            let spec = Value::Object(spec);
            detached(py, "Fabric.from_kes", move || {
                Self::from_spec_value(spec, "Fabric.from_kes".into())
            })
        })
    }

    /// The fabric's name.
    #[getter]
    fn name(&self) -> String {
        self.fabric.name.clone()
    }

    /// Where the fabric came from: its file, or `Fabric.from_kes`.
    #[getter]
    fn origin(&self) -> String {
        self.origin.clone()
    }

    /// Mass per area, kg/m².
    #[getter]
    fn mass_per_area(&self) -> f64 {
        self.fabric.mass_per_area
    }

    /// Thickness, m.
    #[getter]
    fn thickness(&self) -> f64 {
        self.fabric.thickness
    }

    /// Static friction coefficient, fabric on fabric.
    #[getter]
    fn friction(&self) -> f64 {
        self.fabric.friction
    }

    /// The fabric's own tensile loop along `direction` (`"warp"` or `"weft"`), sampled as the
    /// KES-FB1 test loads it: the force per width from 0 to the loop's F_m (the file's `fm_gf_cm`,
    /// default 500 gf/cm = 490.3 N/m) and back to 0 in `levels` equal steps each way, the strain
    /// following the hysteresis model (major loading branch up, unloading branch down).
    ///
    /// Returns a numpy array of shape (2·levels + 1, 2), float64: column 0 the strain
    /// (fraction, not %), column 1 the force per width, N/m. The first row is (0, 0).
    #[pyo3(signature = (direction, levels = 100))]
    fn tensile_loop<'py>(
        &self,
        py: Python<'py>,
        direction: &str,
        levels: usize,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        guarded("Fabric.tensile_loop", || {
            let grain = Grain::parse(direction, "direction")?;
            let levels = samples(levels, "levels")?;
            let l = self.tensile(grain).clone();
            let rows = detached(py, "Fabric.tensile_loop", move || {
                let mut state = TensileState::VIRGIN;
                let mut rows = vec![[0.0, 0.0]];
                for f in atelier_solver::kes::cycle(l.max_force(), levels) {
                    rows.push([state.update(&l, f), f]);
                }
                Ok(rows)
            })?;
            array(py, &rows)
        })
    }

    /// The fabric's own bending loop along `direction` (`"warp"` or `"weft"`: the bending of a
    /// strip cut along it), sampled as the KES-FB2 test bends it (`kes_bending_test`): the
    /// curvature 0 → +2.5 → −2.5 → 0 cm⁻¹ with `steps_per_cm` samples per cm⁻¹ (an even number
    /// samples ±1 cm⁻¹ exactly), the moment following the spindle model with its hysteresis.
    ///
    /// Returns a numpy array of shape (10·steps_per_cm + 1, 2), float64: column 0 the
    /// curvature, 1/m; column 1 the bending moment per width, N·m/m (= N).
    #[pyo3(signature = (direction, steps_per_cm = 20))]
    fn bending_loop<'py>(
        &self,
        py: Python<'py>,
        direction: &str,
        steps_per_cm: usize,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        guarded("Fabric.bending_loop", || {
            let grain = Grain::parse(direction, "direction")?;
            let steps = samples(steps_per_cm, "steps_per_cm")?;
            let s = *self.bending(grain);
            let rows = detached(py, "Fabric.bending_loop", move || {
                Ok(kes_bending_test(&s, steps)
                    .loop_points
                    .iter()
                    .map(|&(k, m)| [k, m])
                    .collect::<Vec<_>>())
            })?;
            array(py, &rows)
        })
    }

    /// The fabric's own in-plane shear loop as the KES-FB1 shear test reads it
    /// (`kes_shear_test`, pretension term included, docs/fabric.md §9): the shear angle
    /// 0 → +8° → −8° → +8° with `steps_per_deg` samples per degree, the force following the
    /// loop's hysteresis.
    ///
    /// Returns a numpy array of shape (40·steps_per_deg + 1, 2), float64: column 0 the shear
    /// angle, rad; column 1 the shear force per width, N/m.
    #[pyo3(signature = (steps_per_deg = 10))]
    fn shear_loop<'py>(
        &self,
        py: Python<'py>,
        steps_per_deg: usize,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        guarded("Fabric.shear_loop", || {
            let steps = samples(steps_per_deg, "steps_per_deg")?;
            let fabric = self.fabric.clone();
            let rows = detached(py, "Fabric.shear_loop", move || {
                let l = fabric.shear_loop().map_err(|e| invalid("", &e))?;
                Ok(kes_shear_test(&l, steps)
                    .loop_points
                    .iter()
                    .map(|&(g, t)| [g, t])
                    .collect::<Vec<_>>())
            })?;
            array(py, &rows)
        })
    }

    /// The fabric's KES values (KES units), warp and weft: a dict with `mass_per_area_mg_cm2`,
    /// `thickness_mm`, `friction`, and per direction `emt_percent`, `lt`, `wt_gf_cm_cm2`,
    /// `rt_percent` (of the tensile loop as built), `b_gf_cm2_cm`, `two_hb_gf_cm_cm`; and
    /// `g_gf_cm_deg`, `two_hg_gf_cm`, `two_hg5_gf_cm` when the fabric has a shear section.
    fn kes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        guarded("Fabric.kes", || {
            let f = &self.fabric;
            let mut out = Map::new();
            out.insert(
                "mass_per_area_mg_cm2".into(),
                json!(units::mass_per_area_to_kes(f.mass_per_area)),
            );
            out.insert(
                "thickness_mm".into(),
                json!(units::thickness_to_kes(f.thickness)),
            );
            out.insert("friction".into(), json!(f.friction));
            for grain in [Grain::Warp, Grain::Weft] {
                let t = self.tensile(grain).summary();
                let b = self.bending(grain);
                out.insert(
                    grain.name().into(),
                    json!({
                        "emt_percent": units::strain_to_percent(t.emt),
                        "lt": t.lt,
                        "wt_gf_cm_cm2": units::energy_to_kes(t.wt()),
                        "rt_percent": units::strain_to_percent(t.rt),
                        "b_gf_cm2_cm": units::rigidity_to_kes(b.rigidity()),
                        "two_hb_gf_cm_cm": units::moment_to_kes(2.0 * b.residual_moment()),
                    }),
                );
            }
            if let Some(s) = &f.shear {
                out.insert(
                    "g_gf_cm_deg".into(),
                    json!(units::shear_stiffness_to_kes(s.stiffness)),
                );
                out.insert(
                    "two_hg_gf_cm".into(),
                    json!(units::force_to_kes(s.hysteresis)),
                );
                out.insert(
                    "two_hg5_gf_cm".into(),
                    json!(s.hysteresis_5deg.map(units::force_to_kes)),
                );
            }
            crate::values::to_python(py, &Value::Object(out))
        })
    }

    fn __repr__(&self) -> String {
        let f = &self.fabric;
        let (w, t) = (
            self.tensile(Grain::Warp).summary(),
            self.tensile(Grain::Weft).summary(),
        );
        let (bw, bt) = (self.bending(Grain::Warp), self.bending(Grain::Weft));
        let shear = f.shear.map_or(String::new(), |s| {
            format!(
                ", G {} gf/(cm·deg)",
                short(units::shear_stiffness_to_kes(s.stiffness))
            )
        });
        format!(
            "<atelier.Fabric {:?}: W {} mg/cm², T {} mm, EMT {}/{} %, B {}/{} gf·cm²/cm, 2HB {}/{} gf·cm/cm (warp/weft){shear}; from {}>",
            f.name,
            short(units::mass_per_area_to_kes(f.mass_per_area)),
            short(units::thickness_to_kes(f.thickness)),
            short(units::strain_to_percent(w.emt)),
            short(units::strain_to_percent(t.emt)),
            short(units::rigidity_to_kes(bw.rigidity())),
            short(units::rigidity_to_kes(bt.rigidity())),
            short(units::moment_to_kes(2.0 * bw.residual_moment())),
            short(units::moment_to_kes(2.0 * bt.residual_moment())),
            self.origin,
        )
    }

    /// Equal mechanics: mass, thickness, friction and every loop (tensile, bending, shear)
    /// equal; the name, provenance and class are not compared.
    fn __eq__(&self, other: &Self) -> bool {
        let mut a = self.fabric.clone();
        a.name.clone_from(&other.fabric.name);
        a.provenance = other.fabric.provenance.clone();
        a.class = other.fabric.class;
        a == other.fabric
    }
}
