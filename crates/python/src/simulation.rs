//! `atelier.Simulation`: a garment scenario stepped from Python, one Δt at a time, through
//! `atelier::Simulation` — the same scene `atelier run` builds (`atelier::Scene::load` from the
//! scenario's `GarmentSpec`) and the same steps, so stepping to the end gives the run's final
//! state.

use std::path::PathBuf;
use std::sync::{Mutex, MutexGuard};

use atelier::pipeline::StepStats;
use atelier::scenario::{Scenario, ScenarioKind};
use atelier::{Scene, Simulation, StepOutcome};
use numpy::PyArray2;
use pyo3::prelude::*;
use serde_json::{Value, json};

use crate::errors::{Failure, Signals, detached, guarded};
use crate::values::{array, index_array, to_python};

/// A garment scenario (kind `Garment`: a garment sewn round a body, settled, worn while the body
/// moves) stepped from Python.
///
/// `Simulation(scenario)` reads the scenario file and sets the scene up (as `atelier run`
/// does); `step()` advances one Δt; `time`, `phase`, `positions` and `report()` say where it is.
/// Other scenario kinds raise `AtelierError`: run them with `atelier.run()`, or test a fabric
/// with `atelier.drape()` / `atelier.cantilever()`. The GIL is released while the scene is set
/// up and while it steps, so other Python threads run meanwhile.
#[pyclass(frozen, module = "atelier", name = "Simulation")]
pub struct PySimulation {
    name: String,
    file: PathBuf,
    /// Locked only inside sections that run without the GIL: no thread holding the GIL ever
    /// waits for it.
    inner: Mutex<Inner>,
    cloth_triangles: Vec<[u32; 3]>,
    body_triangles: Vec<[u32; 3]>,
}

/// The simulation and what its steps so far measured (as `atelier::pipeline::run_scene`
/// counts them for report.json).
struct Inner {
    sim: Simulation,
    /// Counted as `atelier run` counts them.
    stats: StepStats,
    failure: Option<String>,
    ended: bool,
}

impl Inner {
    /// One step; `Ok(None)` once the schedule is over or the run failed. A failing step is
    /// recorded (`failure`) and raised once.
    fn step(&mut self) -> Result<Option<StepOutcome>, Failure> {
        if self.ended {
            return Ok(None);
        }
        let start = self.sim.time();
        match self.sim.step() {
            Ok(Some(o)) => {
                self.stats.add(&o, start);
                Ok(Some(o))
            }
            Ok(None) => {
                self.ended = true;
                Ok(None)
            }
            Err(e) => {
                self.ended = true;
                let message = e.to_string();
                self.failure = Some(message.clone());
                Err(Failure::Atelier(format!(
                    "the step failed (the state is the last good one; the run has ended): {message}"
                )))
            }
        }
    }

    fn positions(&self) -> Vec<[f64; 3]> {
        self.sim
            .state()
            .positions
            .iter()
            .map(|p| [p.x, p.y, p.z])
            .collect()
    }

    /// What is known so far, as JSON.
    fn report(&self, name: &str, file: &str) -> Value {
        let sim = &self.sim;
        let positions = self.positions();
        let (sewn, pairs) = sim.sewing_progress();
        let lowest = positions.iter().map(|p| p[1]).reduce(f64::min);
        let hem =
            atelier_solver::metrics::hem_extent(&positions, atelier_solver::metrics::HEM_BAND);
        let state = sim.state();
        let rms_speed = (!state.velocities.is_empty()).then(|| {
            (state
                .velocities
                .iter()
                .map(|v| v.norm_squared())
                .sum::<f64>()
                / state.velocities.len() as f64)
                .sqrt()
        });
        let stats = &self.stats;
        let convergence = stats.convergence();
        let mut warnings = sim.warnings().to_vec();
        warnings.extend(convergence.warning());
        json!({
            "scenario": {"name": name, "file": file, "kind": "Garment"},
            "fabric": sim.scene().garment.fabric.name,
            "time_s": sim.time(),
            "phase": format!("{:?}", sim.phase()),
            "ended": self.ended,
            "steps": stats.steps,
            "dt_s": sim.scene().settings.dt,
            "planned_s": sim.planned_time(),
            "sewing": {"pairs_sewn": sewn, "pairs": pairs, "sewn_at_s": sim.sewn_at()},
            "warnings": warnings,
            "failure": self.failure,
            "convergence": convergence,
            "metrics": {
                "nodes": positions.len(),
                "cloth_triangles": sim.cloth_triangles().len(),
                "body_triangles": sim.body_triangles().len(),
                "pairs": pairs,
                "pairs_sewn": sewn,
                "unsewn_pairs": pairs.saturating_sub(sewn),
                "sewn_at_s": sim.sewn_at(),
                "max_penetration_m": stats.max_penetration,
                "steps_with_penetration": stats.steps_with_penetration,
                "nodes_inside": stats.inside,
                "max_strain_error": stats.max_strain_error.0,
                "final_strain_error": stats.max_strain_error.1,
                "kinetic_energy_j": stats.kinetic_energy,
                "max_motion_kinetic_energy_j": stats.max_motion_energy,
                "lowest_node_m": lowest,
                "hem_width_m": hem.map(|h| h.width),
                "hem_depth_m": hem.map(|h| h.depth),
                "rms_speed_m_s": rms_speed,
                "unconverged_fraction": convergence.unconverged_fraction(),
            },
        })
    }
}

/// A step's outcome as JSON.
fn outcome_json(o: &StepOutcome, time: f64) -> Value {
    let r = &o.report;
    json!({
        "time_s": time,
        "phase": format!("{:?}", o.phase),
        "converged": r.converged,
        "shape_converged": r.shape_converged,
        "violation": r.violation,
        "max_strain_error": r.max_strain_error,
        "kinetic_energy_j": r.kinetic_energy,
        "max_speed_m_s": r.max_speed,
        "shape_iterations": r.shape_iterations,
        "nodes_inside": o.inside,
        "depth_m": o.depth,
        "substeps": o.substeps,
        "wall_s": o.timings.total().as_secs_f64(),
    })
}

impl PySimulation {
    fn lock(&self) -> MutexGuard<'_, Inner> {
        // A panic while stepping poisons the lock; the state is then the one the panic left,
        // which the panic's AtelierError said.
        self.inner
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }
}

#[pymethods]
impl PySimulation {
    /// Read the garment scenario file `scenario` and set its scene up: the garment gridded,
    /// placed round the body, every stage prepared. Raises `AtelierError` when the file does not
    /// read (naming file:line:column and field), its files are missing, or it is not a garment
    /// scenario.
    #[new]
    fn new(py: Python<'_>, scenario: PathBuf) -> PyResult<Self> {
        detached(py, "atelier.Simulation", move || {
            let s = Scenario::load(&scenario).map_err(Failure::atelier)?;
            let ScenarioKind::Garment(spec) = &s.kind else {
                return Err(Failure::Atelier(format!(
                    "{}: Simulation steps garment scenarios (kind Garment); `{}` is a {} \
                     scenario: run it with atelier.run(), or test a fabric with \
                     atelier.drape() or atelier.cantilever()",
                    scenario.display(),
                    s.name,
                    s.kind.name()
                )));
            };
            let base = atelier::run::base_of(&scenario);
            let scene = Scene::load(spec, &base)
                .map_err(|e| Failure::Atelier(format!("{}: {e}", s.name)))?;
            let stats = StepStats::new(&scene);
            let sim =
                Simulation::new(scene).map_err(|e| Failure::Atelier(format!("{}: {e}", s.name)))?;
            let cloth_triangles = sim.cloth_triangles().to_vec();
            let body_triangles = sim.body_triangles().to_vec();
            Ok(Self {
                name: s.name.clone(),
                file: scenario.clone(),
                inner: Mutex::new(Inner {
                    sim,
                    stats,
                    failure: None,
                    ended: false,
                }),
                cloth_triangles,
                body_triangles,
            })
        })
    }

    /// One step of Δt through every stage. Returns a dict of what the step did — `time_s` (after
    /// it), `phase` (`Sewing`, `Pushing`, `Settling` or `Motion`), `converged`,
    /// `shape_converged`, `violation`, `max_strain_error`, `kinetic_energy_j`, `max_speed_m_s`,
    /// `shape_iterations`, `nodes_inside`, `depth_m`, `substeps`, `wall_s` — or `None` once the
    /// schedule is over (sewn, settled, moved). A step that fails raises `AtelierError` (phase,
    /// time, stage and node or edge); the state stays the last good one and the run has ended
    /// (later calls return `None`; `report()["failure"]` keeps the reason).
    fn step<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        guarded("Simulation.step", || {
            let done = detached(py, "Simulation.step", || {
                let mut inner = self.lock();
                Ok(inner.step()?.map(|o| outcome_json(&o, inner.sim.time())))
            })?;
            match done {
                Some(v) => to_python(py, &v),
                None => Ok(py.None().into_bound(py)),
            }
        })
    }

    /// Step until the schedule is over, or for `duration` seconds of simulated time when given;
    /// returns the number of steps taken. The GIL is released meanwhile; Ctrl-C stops it between
    /// two steps (raising `KeyboardInterrupt`; the simulation stays usable at the last step
    /// taken). A failing step raises `AtelierError`, as `step()`.
    #[pyo3(signature = (duration = None))]
    fn advance(&self, py: Python<'_>, duration: Option<f64>) -> PyResult<usize> {
        if duration.is_some_and(|d| !(d.is_finite() && d >= 0.0)) {
            return Err(Failure::value("duration", "must be a finite number ≥ 0 (seconds)").into());
        }
        detached(py, "Simulation.advance", || {
            let mut inner = self.lock();
            let until = duration.map(|d| inner.sim.time() + d);
            let dt = inner.sim.scene().settings.dt;
            let mut taken = 0;
            let mut signals = Signals::new();
            while until.is_none_or(|t| inner.sim.time() < t - 0.5 * dt) {
                if inner.step()?.is_none() {
                    break;
                }
                taken += 1;
                signals.poll();
            }
            Ok(taken)
        })
    }

    /// Simulated time, s.
    #[getter]
    fn time(&self, py: Python<'_>) -> PyResult<f64> {
        detached(py, "Simulation.time", || Ok(self.lock().sim.time()))
    }

    /// The phase the next step belongs to: `Sewing`, `Pushing`, `Settling`, `Motion` or
    /// `Done`.
    #[getter]
    fn phase(&self, py: Python<'_>) -> PyResult<String> {
        detached(py, "Simulation.phase", || {
            let inner = self.lock();
            Ok(if inner.ended {
                "Done".to_string()
            } else {
                format!("{:?}", inner.sim.phase())
            })
        })
    }

    /// The scenario's name.
    #[getter]
    fn name(&self) -> String {
        self.name.clone()
    }

    /// The cloth's node positions now: a numpy array of shape (N, 3), float64, m, in the body
    /// frame (x the body's left, y up, z forward) — a copy.
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        guarded("Simulation.positions", || {
            let rows = detached(py, "Simulation.positions", || Ok(self.lock().positions()))?;
            array(py, &rows)
        })
    }

    /// The cloth's triangles: a numpy array of shape (M, 3), int64 (node indices of
    /// `positions`).
    #[getter]
    fn triangles<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        guarded("Simulation.triangles", || {
            index_array(py, &self.cloth_triangles)
        })
    }

    /// The body's vertices now: numpy (V, 3), float64, m, body frame — a copy.
    #[getter]
    fn body_positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        guarded("Simulation.body_positions", || {
            let rows = detached(py, "Simulation.body_positions", || {
                Ok(self
                    .lock()
                    .sim
                    .body_positions()
                    .iter()
                    .map(|p| [p.x, p.y, p.z])
                    .collect::<Vec<_>>())
            })?;
            array(py, &rows)
        })
    }

    /// The body's triangles: numpy (B, 3), int64.
    #[getter]
    fn body_triangles<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        guarded("Simulation.body_triangles", || {
            index_array(py, &self.body_triangles)
        })
    }

    /// What is known so far, as a dict: `scenario`, `fabric`, `time_s`, `phase`, `ended`,
    /// `steps`, `dt_s`, `planned_s` (the longest the schedule can take), `sewing` (`pairs_sewn`,
    /// `pairs`, `sewn_at_s`), `warnings`, `failure`, `convergence` (as report.json's) and
    /// `metrics`: report.json's garment metrics that do not need the recorded frames, measured
    /// now (`nodes`, `cloth_triangles`, `body_triangles`, `pairs`, `pairs_sewn`,
    /// `unsewn_pairs`, `sewn_at_s`, `max_penetration_m`, `steps_with_penetration`,
    /// `nodes_inside` (now), `max_strain_error`, `final_strain_error` (the last step's),
    /// `kinetic_energy_j`, `max_motion_kinetic_energy_j`, `lowest_node_m`, `hem_width_m`,
    /// `hem_depth_m`, `unconverged_fraction`) and `rms_speed_m_s` (the nodes' RMS velocity now).
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        guarded("Simulation.report", || {
            let name = self.name.clone();
            let file = self.file.display().to_string();
            let v = detached(py, "Simulation.report", || {
                Ok(self.lock().report(&name, &file))
            })?;
            to_python(py, &v)
        })
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let (t, phase, steps) = detached(py, "Simulation.__repr__", || {
            let inner = self.lock();
            Ok((
                inner.sim.time(),
                format!("{:?}", inner.sim.phase()),
                inner.stats.steps,
            ))
        })?;
        Ok(format!(
            "<atelier.Simulation {:?}: t = {t:.3} s, {phase}, {steps} steps>",
            self.name
        ))
    }
}
