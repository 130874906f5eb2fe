//! # atelier-python
//!
//! The Python bindings of atelier, built by maturin into the extension module
//! `atelier._atelier` that the Python package `atelier` (`python/atelier/__init__.py`)
//! re-exports (docs/python.md):
//!
//! - [`runs`]: `atelier.run(scenario, out)` (a scenario file run into a folder, as `atelier
//!   run`, returning report.json as a dict), `atelier.drape(fabric, tester)` and
//!   `atelier.cantilever(fabric, direction)` (the scenario kinds' defaults, run with a fabric
//!   given in Python);
//! - [`fabric`]: `atelier.Fabric` (`load`, `from_kes` from plain dicts in KES units, its loops as
//!   numpy arrays);
//! - [`simulation`]: `atelier.Simulation`, a garment scenario stepped from Python;
//! - [`errors`]: `atelier.AtelierError`, the GIL released around every call into the library and
//!   every Rust panic caught; [`values`]: Python values to atelier's types through serde and
//!   back.

use pyo3::prelude::*;

pub mod errors;
pub mod fabric;
pub mod runs;
pub mod simulation;
pub mod values;

/// The extension module `atelier._atelier`.
#[pymodule]
#[pyo3(name = "_atelier")]
fn atelier_module(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("AtelierError", m.py().get_type::<errors::AtelierError>())?;
    m.add_class::<fabric::PyFabric>()?;
    m.add_class::<simulation::PySimulation>()?;
    m.add_function(wrap_pyfunction!(runs::run, m)?)?;
    m.add_function(wrap_pyfunction!(runs::drape, m)?)?;
    m.add_function(wrap_pyfunction!(runs::cantilever, m)?)?;
    m.add_function(wrap_pyfunction!(errors::panic_for_test, m)?)?;
    Ok(())
}
