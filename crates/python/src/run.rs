//! `run` and `run_many`: whole runs on the twin, as `tendril run` does them.

use crate::columns::columns;
use crate::controller::PyController;
use crate::errors::{ControllerError, run_error, scenario_error};
use crate::overrides::type_name;
use crate::scenario::Scenario;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use tendril_cell::CellError;
use tendril_config::Override;
use tendril_run::execute::{Driver, ModelCache, run_on_twin, run_on_twin_with, summary_json};
use tendril_run::runner::RunReport;
use tendril_run::scenario::PickPlaceScenario;
use tendril_run::summary::RunSummary;
use tendril_twin::physics::Backend;

/// What a run gives Python: `summary.json`'s text and the trace's columns (`(name, kind, data)`,
/// see [`columns`]).
type RunOutput<'py> = (String, Vec<(&'static str, &'static str, Bound<'py, PyAny>)>);

/// Runs `scenario` (a `Scenario` or a scenario file's path) on the twin, as `tendril run` does:
/// `seed`, `feedback` (`True`/`False` or `"on"`/`"off"`) and `backend` (`"mujoco"`/`"rapier"`)
/// are overrides after the scenario's own, `out` the folder for `trace.csv`, `summary.json`,
/// `scenario.toml` and `frames.bin` (none written without it). `controller` (an object with
/// `update(ctx) -> float` and optionally `reset()`, or a callable) replaces the scenario's force
/// controller. The GIL is released while the twin runs (and taken back for each call of a Python
/// controller).
#[pyfunction]
#[pyo3(signature = (scenario, seed = None, feedback = None, backend = None, out = None, controller = None))]
pub fn run<'py>(
    py: Python<'py>,
    scenario: &Bound<'py, PyAny>,
    seed: Option<&Bound<'py, PyAny>>,
    feedback: Option<&Bound<'py, PyAny>>,
    backend: Option<&str>,
    out: Option<PathBuf>,
    controller: Option<Bound<'py, PyAny>>,
) -> PyResult<RunOutput<'py>> {
    let scenario = resolve(scenario, extras(seed, feedback, backend)?)?.scenario;
    let out = out.as_deref();
    let (summary, report) = match controller.filter(|c| !c.is_none()) {
        None => py.detach(|| run_on_twin(&scenario, &ModelCache::default(), out)).map_err(run_error)?,
        Some(obj) => run_with_python_controller(py, &scenario, out, obj)?,
    };
    output(py, &summary, &report, &scenario)
}

/// Runs `scenarios` (each a `Scenario` or a path) on the twin in parallel on `threads` threads
/// (default: one per core), the GIL released, scene models compiled once and shared. Returns
/// the runs in the order given; raises on the first that could not start.
#[pyfunction]
#[pyo3(signature = (scenarios, threads = None))]
pub fn run_many<'py>(
    py: Python<'py>,
    scenarios: &Bound<'py, PyAny>,
    threads: Option<usize>,
) -> PyResult<Vec<RunOutput<'py>>> {
    if threads == Some(0) {
        return Err(PyValueError::new_err("threads must be at least 1 (or None: one per core)"));
    }
    let list: Vec<PickPlaceScenario> = scenarios
        .try_iter()
        .map_err(|_| {
            PyTypeError::new_err(format!(
                "scenarios: expected a list of scenarios or paths, got {}",
                type_name(scenarios)
            ))
        })?
        .map(|s| Ok(resolve(&s?, Vec::new())?.scenario))
        .collect::<PyResult<_>>()?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .map_err(|e| run_error(anyhow::anyhow!("cannot start the worker threads: {e}")))?;
    let models = ModelCache::default();
    let results =
        py.detach(|| pool.install(|| list.par_iter().map(|s| run_on_twin(s, &models, None)).collect::<Vec<_>>()));
    list.iter()
        .zip(results)
        .map(|(scenario, result)| {
            let (summary, report) =
                result.map_err(|e| run_error(e.context(format!("scenario `{}`", scenario.name))))?;
            output(py, &summary, &report, scenario)
        })
        .collect()
}

/// `--backend`, `--seed` and `--feedback` as `tendril run` turns them into overrides, in its
/// order (after `--set`).
fn extras(
    seed: Option<&Bound<'_, PyAny>>,
    feedback: Option<&Bound<'_, PyAny>>,
    backend: Option<&str>,
) -> PyResult<Vec<Override>> {
    let mut extra = Vec::new();
    if let Some(name) = backend {
        let backend: Backend = name.parse().map_err(PyValueError::new_err)?;
        extra.push(backend.as_override());
    }
    if let Some(seed) = seed.filter(|s| !s.is_none()) {
        let seed: u64 = seed.extract().map_err(|_| {
            PyValueError::new_err(format!(
                "seed: expected an integer from 0 to 2^64 - 1, got {}",
                seed.repr().map_or_else(|_| type_name(seed), |r| r.to_string())
            ))
        })?;
        extra.push(Override { key: "seed".into(), value: tendril_config::seed::to_toml(seed) });
    }
    if let Some(f) = feedback.filter(|f| !f.is_none()) {
        let on = match (f.extract::<bool>(), f.extract::<String>().as_deref()) {
            (Ok(b), _) => b,
            (_, Ok("on")) => true,
            (_, Ok("off")) => false,
            _ => {
                return Err(PyValueError::new_err(format!(
                    "feedback: expected True, False, \"on\" or \"off\", got {}",
                    f.repr()?
                )));
            }
        };
        extra.push(Override { key: "feedback".into(), value: toml::Value::Boolean(on) });
    }
    Ok(extra)
}

/// A `Scenario`, or a path loaded as one, with `extra` applied.
fn resolve(scenario: &Bound<'_, PyAny>, extra: Vec<Override>) -> PyResult<Scenario> {
    if let Ok(s) = scenario.cast::<Scenario>() {
        return s.get().with(extra).map_err(scenario_error);
    }
    let path: PathBuf = scenario.extract().map_err(|_| {
        PyTypeError::new_err(format!(
            "expected a tendril.Scenario or a scenario file's path, got {}",
            type_name(scenario)
        ))
    })?;
    Scenario::load(&path, None, extra).map_err(scenario_error)
}

/// A run with a Python force controller: stopped, the cell deactivated, at the first exception
/// it raises (or bad value it returns), which is then raised as `ControllerError`.
fn run_with_python_controller(
    py: Python<'_>,
    scenario: &PickPlaceScenario,
    out: Option<&Path>,
    obj: Bound<'_, PyAny>,
) -> PyResult<(RunSummary, RunReport)> {
    let default_max = scenario.controller.build().max_speed_deg_s();
    let controller = PyController::new(&obj, default_max)?;
    let failure = controller.failure();
    let watched = failure.clone();
    let mut check =
        move || watched.message().map(|cause| CellError::Device { device: "python controller".into(), cause });
    let driver = Driver { controller: Some(Box::new(controller)), check: Some(&mut check) };
    let result = py.detach(|| run_on_twin_with(scenario, &ModelCache::default(), out, driver));
    if let Some((err, message)) = failure.take() {
        let raised = ControllerError::new_err(format!("the controller failed; the run was stopped:\n{message}"));
        raised.set_cause(py, Some(err));
        return Err(raised);
    }
    result.map_err(run_error)
}

/// The Python side of a finished run.
fn output<'py>(
    py: Python<'py>,
    summary: &RunSummary,
    report: &RunReport,
    scenario: &PickPlaceScenario,
) -> PyResult<RunOutput<'py>> {
    let text = summary_json(summary, scenario).map_err(run_error)?;
    Ok((text, columns(py, &report.rows)?))
}
