//! Errors: `atelier.AtelierError`, the Python exception every failure of atelier itself is
//! raised as, and [`detached`], which runs library code with the GIL released and turns a Rust
//! panic into that exception.
//!
//! Which exception a failure raises:
//!
//! - `TypeError`: a Python value of the wrong type (a string where a number belongs), with the
//!   field's path (`tensile.warp.lt`);
//! - `ValueError`: a value of the right type that atelier refuses (an unknown key, a missing
//!   field, a number out of range, `direction="bias"`), with the field's path;
//! - `AtelierError`: a file that does not read (its message names file:line:column and field,
//!   as every atelier error does), a scene that cannot be set up, a step that failed, and any
//!   panic inside the library (pyo3's own `PanicException` derives from `BaseException`, which
//!   `except Exception` and notebooks do not catch; this one derives from `Exception`).

use std::panic::{AssertUnwindSafe, catch_unwind, resume_unwind};
use std::time::{Duration, Instant};

use pyo3::exceptions::{PyException, PyTypeError, PyValueError};
use pyo3::prelude::*;

pyo3::create_exception!(
    atelier,
    AtelierError,
    PyException,
    "An error of atelier itself: a file that does not read (the message names file:line:column \
     and field), a scene that cannot be set up, a step that failed, or an internal error (a \
     Rust panic, caught: the interpreter goes on)."
);

/// A failure on the Rust side, carried out of a section that runs without the GIL (it must be
/// `Send`) and raised as a Python exception when the GIL is back ([`From`] for [`PyErr`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Failure {
    /// `atelier.AtelierError`.
    Atelier(String),
    /// `ValueError`.
    Value(String),
    /// `TypeError`.
    Type(String),
}

impl Failure {
    /// An `AtelierError` with the error's message (its `Display`, which for file errors names
    /// file:line:column and field).
    pub fn atelier(e: impl std::fmt::Display) -> Self {
        Self::Atelier(e.to_string())
    }

    /// A `ValueError` naming `field` (when not empty).
    pub fn value(field: &str, message: impl std::fmt::Display) -> Self {
        Self::Value(with_field(field, message))
    }

    /// A `TypeError` naming `field` (when not empty).
    pub fn type_error(field: &str, message: impl std::fmt::Display) -> Self {
        Self::Type(with_field(field, message))
    }
}

/// `field `a.b`: message`, or the message alone when the field is empty.
pub fn with_field(field: &str, message: impl std::fmt::Display) -> String {
    if field.is_empty() {
        message.to_string()
    } else {
        format!("field `{field}`: {message}")
    }
}

impl From<Failure> for PyErr {
    fn from(f: Failure) -> Self {
        match f {
            Failure::Atelier(m) => AtelierError::new_err(m),
            Failure::Value(m) => PyValueError::new_err(m),
            Failure::Type(m) => PyTypeError::new_err(m),
        }
    }
}

/// A field's invalid value (`atelier_fabric::InvalidValue`) as a `ValueError` naming the field
/// below `prefix`.
pub fn invalid(prefix: &str, e: &atelier_fabric::InvalidValue) -> Failure {
    let field = join(prefix, &e.field);
    Failure::value(&field, format!("{}: {}", e.kind, e.message))
}

/// Two field paths joined by a dot (an index `[k]` without one), either may be empty.
pub fn join(a: &str, b: &str) -> String {
    match (a.is_empty(), b.is_empty()) {
        (true, _) => b.to_owned(),
        (_, true) => a.to_owned(),
        _ if b.starts_with('[') => format!("{a}{b}"),
        _ => format!("{a}.{b}"),
    }
}

/// Run `f` with the GIL released (`Python::detach`, pyo3 ≥ 0.26's name for `allow_threads`),
/// so other Python threads run meanwhile, and with any panic caught: a panic becomes an
/// `AtelierError` naming `what` and the panic's message, and the interpreter goes on.
pub fn detached<T, F>(py: Python<'_>, what: &str, f: F) -> PyResult<T>
where
    T: Send,
    F: FnOnce() -> Result<T, Failure> + Send,
{
    let outcome = py.detach(move || catch_unwind(AssertUnwindSafe(f)));
    match outcome {
        Ok(result) => result.map_err(PyErr::from),
        Err(payload) => match payload.downcast::<Interrupted>() {
            Ok(interrupted) => Err(interrupted.0),
            Err(payload) => Err(AtelierError::new_err(panic_message(what, payload.as_ref()))),
        },
    }
}

/// The exception a signal handler raised (Ctrl-C's `KeyboardInterrupt`), carried out of a
/// detached section by unwinding ([`Signals::poll`]); [`detached`] raises it as it is.
struct Interrupted(PyErr);

/// How often a long call looks for Ctrl-C.
const SIGNAL_INTERVAL: Duration = Duration::from_millis(200);

/// Lets a long call without the GIL be interrupted: [`Signals::poll`], called between steps
/// (from a run's progress callback), runs Python's signal handlers at most every 0.2 s and,
/// when one raised (Ctrl-C in a notebook or a terminal), unwinds out of the simulation
/// (without the panic hook: nothing is printed) to [`detached`], which raises that exception.
/// Nothing has been written then: a run writes its outputs only once its simulation ends.
pub struct Signals {
    last: Instant,
}

impl Signals {
    /// Start watching.
    pub fn new() -> Self {
        Self {
            last: Instant::now(),
        }
    }

    /// Run the signal handlers if 0.2 s have passed since the last look; unwind with their
    /// exception if one raised.
    pub fn poll(&mut self) {
        if self.last.elapsed() < SIGNAL_INTERVAL {
            return;
        }
        self.last = Instant::now();
        if let Err(e) = Python::attach(|py| py.check_signals()) {
            resume_unwind(Box::new(Interrupted(e)));
        }
    }
}

impl Default for Signals {
    fn default() -> Self {
        Self::new()
    }
}

/// The message of a caught panic.
pub fn panic_message(what: &str, payload: &(dyn std::any::Any + Send)) -> String {
    let detail = payload
        .downcast_ref::<&str>()
        .map(|s| (*s).to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "(no message)".to_string());
    format!(
        "{what}: internal error (a Rust panic, caught; the interpreter is unaffected, but an \
         object it happened in may be left part-way): {detail}"
    )
}

/// Run `f` (which needs the GIL: it touches Python objects) with any panic caught as in
/// [`detached`]. Every function and method of the module that does more than return a field
/// runs its body in one, so no panic reaches pyo3 (whose `PanicException` is a
/// `BaseException`).
pub fn guarded<T>(what: &str, f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(r) => r,
        Err(payload) => Err(AtelierError::new_err(panic_message(what, payload.as_ref()))),
    }
}

/// `atelier._panic_for_test(message)`: panics inside a detached section, as a bug in the library
/// would, so that the tests can check a panic is raised as `AtelierError` and the interpreter
/// goes on. Hidden (not in `__all__`, not documented for users): no input of the public API was
/// found that panics (docs/python.md, tests).
#[pyfunction]
#[pyo3(name = "_panic_for_test")]
pub fn panic_for_test(py: Python<'_>, message: String) -> PyResult<()> {
    detached(
        py,
        "atelier._panic_for_test",
        move || -> Result<(), Failure> { panic!("{message}") },
    )
}
