//! The exceptions the module raises, and how Rust errors become them.

use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;

create_exception!(
    _native,
    ScenarioError,
    PyValueError,
    "A scenario, overlay or `set` override that cannot be loaded: the message names the file, the key and \
     what is wrong, exactly as `tendril run` says it."
);

create_exception!(
    _native,
    ControllerError,
    PyRuntimeError,
    "A Python force controller raised or returned a bad value: the run was stopped (the cell deactivated) \
     and the message holds the original traceback, which is also the exception's `__cause__`."
);

/// A scenario error as [`ScenarioError`], its message the command line's.
pub fn scenario_error(e: tendril_config::ScenarioError) -> PyErr {
    ScenarioError::new_err(e.to_string())
}

/// What prevented a run from starting (a scene that does not compile, a folder that cannot be
/// written) as a `RuntimeError`, with its causes.
pub fn run_error(e: anyhow::Error) -> PyErr {
    PyRuntimeError::new_err(format!("{e:#}"))
}
