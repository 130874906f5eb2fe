//! Runs: `atelier.run` (a scenario file into a folder, as `atelier run`), and the tests of a
//! fabric given in Python, `atelier.drape` and `atelier.cantilever` (the scenario kinds with
//! their defaults, simulated with that fabric by `atelier::run::simulate_with_fabric`).

use std::path::{Path, PathBuf};

use atelier::export::FrameSelection;
use atelier::outcome::Simulated;
use atelier::run::{RunOptions, base_of, simulate_with_fabric};
use atelier::scenario::{CantileverSpec, Scenario, ScenarioKind};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyModule};
use serde_json::{Map, Value};

use crate::errors::{Failure, Signals, detached, guarded, invalid};
use crate::fabric::{Grain, PyFabric};
use crate::values::{array, deserialize, index_array, serialized, to_json};

/// Run a scenario file into the folder `out` (created if missing), as `atelier run SCENARIO
/// --out OUT` does: simulate, check its expectations, write `report.json`, `final.obj`,
/// `final.ply`, `run.glb` and the pictures. Returns the report (report.json as a dict:
/// docs/report.md).
///
/// A run that ends early, misses an expectation or has unconverged steps is not an error:
/// the report says so (`failure`, `expectations_met`, `convergence`), as the files `atelier
/// run` writes with exit status 2 do. A scenario that cannot be read or started (a bad file,
/// a missing fabric, an output folder that cannot be made) raises `AtelierError`, whose
/// message names file:line:column and field. `frames`: keep at most that many frames (≥ 2) in
/// run.glb (`--frames`; default all). The GIL is released while it runs.
#[pyfunction]
#[pyo3(signature = (scenario, out, *, frames = None))]
pub fn run<'py>(
    py: Python<'py>,
    scenario: PathBuf,
    out: PathBuf,
    frames: Option<usize>,
) -> PyResult<Bound<'py, PyAny>> {
    guarded("atelier.run", || {
        if frames.is_some_and(|k| k < 2) {
            return Err(Failure::value("frames", "keep at least 2 frames").into());
        }
        let json = detached(py, "atelier.run", move || {
            let mut signals = Signals::new();
            let s = Scenario::load(&scenario).map_err(Failure::atelier)?;
            let options = RunOptions {
                frames: frames.map_or(FrameSelection::All, FrameSelection::AtMost),
                ..RunOptions::default()
            };
            let report = atelier::run::run(
                &s,
                Some(&scenario),
                &base_of(&scenario),
                &out,
                &options,
                &mut |_| signals.poll(),
            )
            .map_err(|e| Failure::Atelier(format!("{}: {e}", s.name)))?;
            Ok(report.to_json())
        })?;
        PyModule::import(py, "json")?.call_method1("loads", (json,))
    })
}

/// A scenario of `kind` (its fields as JSON, `options` merged in) checked as a file's would
/// be; field paths in errors are the kind's own (`max_time`, not `kind.max_time`).
fn scenario_of<T: serde::de::DeserializeOwned>(
    name: &str,
    mut fields: Map<String, Value>,
    options: Option<&Bound<'_, PyDict>>,
    wrap: impl FnOnce(T) -> ScenarioKind,
) -> Result<Scenario, Failure> {
    if let Some(options) = options {
        for (k, v) in options.iter() {
            let key: String = k
                .extract()
                .map_err(|_| Failure::type_error("", "option names must be strings"))?;
            let value = to_json(&v, &key)?;
            fields.insert(key, value);
        }
    }
    let spec: T = deserialize(Value::Object(fields), "")?;
    let scenario = Scenario {
        name: name.into(),
        reproduces: format!("atelier.{name}() from Python"),
        kind: wrap(spec),
        expectations: Vec::new(),
    };
    scenario.check().map_err(|e| {
        let field = e
            .field
            .strip_prefix("kind.")
            .unwrap_or(&e.field)
            .to_string();
        invalid("", &atelier_fabric::InvalidValue { field, ..e })
    })?;
    Ok(scenario)
}

/// Simulate `scenario` with `fabric`, the GIL released (Ctrl-C interrupts it).
fn simulate(py: Python<'_>, what: &str, scenario: Scenario, fabric: Fabric) -> PyResult<Simulated> {
    detached(py, what, move || {
        let mut signals = Signals::new();
        simulate_with_fabric(&scenario, &fabric.0, Path::new("."), &mut |_| {
            signals.poll()
        })
        .map_err(Failure::atelier)
    })
}

/// The fabric, moved into the section that runs without the GIL.
struct Fabric(atelier_fabric::Fabric);

/// Metrics that count things come back as `int`, 0/1 flags as `bool`, the rest as `float` (or
/// `None`: not measured).
fn metric_value<'py>(py: Python<'py>, name: &str, v: Option<f64>) -> PyResult<Bound<'py, PyAny>> {
    const COUNTS: [&str; 4] = ["nodes", "cloth_triangles", "frames", "node_count"];
    Ok(match v {
        None => py.None().into_bound(py),
        Some(v) if name == "settled" => (v != 0.0).into_pyobject(py)?.to_owned().into_any(),
        Some(v) if COUNTS.contains(&name) && v.fract() == 0.0 => {
            (v as i64).into_pyobject(py)?.into_any()
        }
        Some(v) => v.into_pyobject(py)?.into_any(),
    })
}

/// What every test's dict holds: the metrics (report.json's names and units), the run's cost
/// and outcome, and the final cloth.
fn common<'py>(py: Python<'py>, sim: &Simulated) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("fabric", &sim.fabric)?;
    for (name, v) in &sim.metrics {
        d.set_item(name, metric_value(py, name, *v)?)?;
    }
    d.set_item("steps", sim.steps)?;
    d.set_item("dt_s", sim.dt)?;
    d.set_item("wall_s", sim.wall_seconds)?;
    d.set_item("warnings", sim.warnings.clone())?;
    d.set_item("failure", sim.failure.clone())?;
    d.set_item("convergence", serialized(py, &sim.convergence)?)?;
    let last = sim.cloth.last().unwrap_or(&[]);
    d.set_item("positions", array(py, last)?)?;
    d.set_item("triangles", index_array(py, &sim.cloth_triangles)?)?;
    Ok(d)
}

/// The drape tester `tester` names (`"jis"` or `"thesis"`, any case) as the scenario file writes
/// it.
fn tester_name(tester: &str) -> Result<&'static str, Failure> {
    match tester.to_ascii_lowercase().as_str() {
        "jis" => Ok("Jis"),
        "thesis" => Ok("Thesis"),
        _ => Err(Failure::value(
            "tester",
            format!("`{tester}`: use \"jis\" (Ø 25.4 cm on Ø 12.7 cm) or \"thesis\" (Ø 63.5 cm)"),
        )),
    }
}

/// The drape test of `fabric` on `tester` (`"jis"`: JIS L 1096, Ø 25.4 cm specimen on a
/// Ø 12.7 cm support; `"thesis"`: Ø 63.5 cm with a Ø 12.7 cm hole), exactly as the scenario
/// `Drape(fabric: …, tester: …)` with its defaults runs it (docs/report.md, `Drape`); keyword
/// `options` set the scenario's other fields (`max_time`, `n_around`, `n_rings`, `dt`,
/// `until_rest`, `perturbation`, `seed`, `form`, `frame_interval`, `step`). The GIL is released
/// while it runs.
///
/// Returns a dict: the metrics of report.json (`drape_coefficient_percent` %, `node_count`
/// (int), `settled` (bool), `shadow_area_m2`, `rms_speed_m_s`, `min_edge_radius_m`,
/// `max_edge_radius_m`, `nodes`, `cloth_triangles`, `simulated_s`, `frames`,
/// `kinetic_energy_j`, `max_strain_error`, `unconverged_fraction`; `None` when not measured),
/// and report.json's `drape` section: `outline` (numpy (M, 2), m: the specimen's outer edge
/// seen from above, one point per node of its outer ring in ring order, (x, z) in the outputs'
/// y-up frame with the support's centre at the origin), `node_points` (numpy (K, 2), m: the
/// outer-edge point at the top of each of the K counted folds), `support_radius_m`,
/// `specimen_radius_m` (all four `None` when the run failed); `positions` (numpy (N, 3), m, the final cloth, y
/// up), `triangles` (numpy (T, 3), int), `steps`, `dt_s`, `wall_s`, `warnings`, `failure`
/// (`None`, or why the run ended early), `convergence` (as in report.json).
#[pyfunction]
#[pyo3(signature = (fabric, tester = "jis", **options))]
pub fn drape<'py>(
    py: Python<'py>,
    fabric: &PyFabric,
    tester: &str,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    guarded("atelier.drape", || {
        let mut fields = Map::new();
        fields.insert("fabric".into(), Value::String(String::new()));
        fields.insert("tester".into(), Value::String(tester_name(tester)?.into()));
        let scenario = scenario_of("drape", fields, options, ScenarioKind::Drape)?;
        let sim = simulate(py, "atelier.drape", scenario, Fabric(fabric.fabric.clone()))?;
        let d = common(py, &sim)?;
        d.set_item("tester", tester.to_ascii_lowercase())?;
        // report.json's `drape` section (`atelier::outcome::DrapeTop`): absent when the run failed.
        let top = sim.drape_top();
        let none = || py.None().into_bound(py);
        d.set_item(
            "outline",
            top.map_or_else(
                || Ok(none()),
                |t| array(py, &t.outline_m).map(Bound::into_any),
            )?,
        )?;
        d.set_item(
            "node_points",
            top.map_or_else(
                || Ok(none()),
                |t| array(py, &t.node_points_m).map(Bound::into_any),
            )?,
        )?;
        d.set_item("support_radius_m", top.map(|t| t.support_radius_m))?;
        d.set_item("specimen_radius_m", top.map(|t| t.specimen_radius_m))?;
        Ok(d)
    })
}

/// The Peirce cantilever of `fabric` along `direction` (`"warp"` or `"weft"`), exactly as the
/// scenario `Cantilever(fabric: …, direction: …)` with its defaults runs it (docs/report.md,
/// `Cantilever`: 40 cells, overhang 2.0003·c, stopped at rest or 6 s); keyword `options` set
/// its other fields (`segments`, `overhang` m, `damping`, `hysteresis`, `max_time`,
/// `frame_interval`). The GIL is released while it runs.
///
/// Returns a dict: the metrics of report.json (`bending_length_m`, `overhang_m`,
/// `chord_angle_deg`, `chord_angle_error_deg`, `tip_droop_m`, `max_speed_m_s`, `nodes`,
/// `cloth_triangles`, `simulated_s`, `frames`, `kinetic_energy_j`, `max_strain_error`,
/// `unconverged_fraction`), `direction`, `positions` (numpy (N, 3), m, the final strip in the
/// outputs' y-up frame), `triangles`, `steps`, `dt_s`, `wall_s`, `warnings`, `failure`,
/// `convergence`.
#[pyfunction]
#[pyo3(signature = (fabric, direction = "warp", **options))]
pub fn cantilever<'py>(
    py: Python<'py>,
    fabric: &PyFabric,
    direction: &str,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    guarded("atelier.cantilever", || {
        let grain = Grain::parse(direction, "direction")?;
        let mut fields = Map::new();
        fields.insert("fabric".into(), Value::String(String::new()));
        let variant = match grain {
            Grain::Warp => "Warp",
            Grain::Weft => "Weft",
        };
        fields.insert("direction".into(), Value::String(variant.into()));
        let scenario =
            scenario_of::<CantileverSpec>("cantilever", fields, options, ScenarioKind::Cantilever)?;
        let sim = simulate(
            py,
            "atelier.cantilever",
            scenario,
            Fabric(fabric.fabric.clone()),
        )?;
        let d = common(py, &sim)?;
        d.set_item("direction", grain.name())?;
        Ok(d)
    })
}
