#![doc = include_str!("../README.md")]
#![warn(missing_docs)]

mod columns;
mod context;
mod controller;
mod errors;
mod models;
mod overrides;
mod render;
mod run;
mod scenario;
mod session;

use pyo3::prelude::*;

/// The extension module `tendril._native`; the package `tendril` (python/tendril) wraps it.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("ScenarioError", py.get_type::<errors::ScenarioError>())?;
    m.add("ControllerError", py.get_type::<errors::ControllerError>())?;
    m.add_class::<scenario::Scenario>()?;
    m.add_class::<context::ControlContext>()?;
    m.add_class::<models::ModelCache>()?;
    m.add_class::<session::Session>()?;
    m.add_class::<render::Renderer>()?;
    m.add_function(wrap_pyfunction!(session::step_all, m)?)?;
    m.add_function(wrap_pyfunction!(scenario::load, m)?)?;
    m.add_function(wrap_pyfunction!(run::run, m)?)?;
    m.add_function(wrap_pyfunction!(run::run_many, m)?)?;
    m.add("TRACE_COLUMNS", columns::names())?;
    m.add("PHASES", session::PHASES.iter().map(|p| p.name()).collect::<Vec<_>>())?;
    Ok(())
}
