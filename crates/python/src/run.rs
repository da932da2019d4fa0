//! `run` and `run_many`: whole runs on the twin, as `tendril run` does them.

use crate::columns::columns;
use crate::controller::{CallTimes, Failure, PyController};
use crate::errors::{ControllerError, run_error, scenario_error};
use crate::overrides::type_name;
use crate::scenario::Scenario;
use pyo3::exceptions::{PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError};
use std::time::Duration;
use tendril_cell::CellError;
use tendril_config::Override;
use tendril_drivers::RealCellConfig;
use tendril_drivers::realtime::RealtimeOptions;
use tendril_run::execute::{Driver, ModelCache, run_on_twin_with, summary_json};
use tendril_run::real::{Devices, run_on_real_with};
use tendril_run::runner::RunReport;
use tendril_run::scenario::PickPlaceScenario;
use tendril_run::summary::RunSummary;
use tendril_twin::physics::Backend;

/// The trace's columns as Python gets them (`(name, kind, data)`, see [`columns`]).
type Columns<'py> = Vec<(String, &'static str, Bound<'py, PyAny>)>;

/// Runs `scenario` (a `Scenario` or a scenario file's path) as `tendril run` does: `seed`,
/// `feedback` (`True`/`False` or `"on"`/`"off"`) and `backend` (`"mujoco"`/`"rapier"`) are
/// overrides after the scenario's own, `out` the folder for `trace.csv`, `summary.json`,
/// `scenario.toml` and `frames.bin` (none written without it). `controller` (an object with
/// `update(ctx) -> float` and optionally `reset()`, or a callable) replaces the scenario's force
/// controller. `hardware="real"` runs on the devices (`ur`, `dxl`, `interrogator`, `port_base`,
/// as `tendril run --hardware real`), or on `tendril serve`'s virtual ones. The GIL is released
/// while the cell runs (and taken back for each call of a Python controller); Ctrl-C stops the
/// run through the cell's safe stop and raises `KeyboardInterrupt` once the trace and summary are
/// written. Returns `(summary, columns, controller_times)`.
#[pyfunction]
#[pyo3(signature = (scenario, seed = None, feedback = None, backend = None, out = None, controller = None, hardware = "sim", ur = "127.0.0.1", dxl = None, interrogator = "127.0.0.1", port_base = None, rt_priority = 0))]
#[allow(clippy::too_many_arguments)]
pub fn run<'py>(
    py: Python<'py>,
    scenario: &Bound<'py, PyAny>,
    seed: Option<&Bound<'py, PyAny>>,
    feedback: Option<&Bound<'py, PyAny>>,
    backend: Option<&str>,
    out: Option<PathBuf>,
    controller: Option<Bound<'py, PyAny>>,
    hardware: &str,
    ur: &str,
    dxl: Option<&str>,
    interrogator: &str,
    port_base: Option<u16>,
    rt_priority: i32,
) -> PyResult<(String, Columns<'py>, Option<Bound<'py, PyDict>>)> {
    let scenario = resolve(scenario, extras(seed, feedback, backend)?)?.scenario;
    let cell = match hardware {
        "sim" => Target::Twin,
        "real" => {
            let dxl = dxl.ok_or_else(|| PyValueError::new_err("hardware=\"real\" needs dxl (the Dynamixel port)"))?;
            scenario.disturbance.refuse_on_real().map_err(PyValueError::new_err)?;
            if !(0..=99).contains(&rt_priority) {
                return Err(PyValueError::new_err(format!(
                    "rt_priority: expected 0 (normal scheduling) or a SCHED_FIFO priority 1-99, got {rt_priority}"
                )));
            }
            let devices = Devices { port_base, ..Devices::new(ur, dxl, interrogator) };
            Target::Real(Box::new(devices.config(&scenario).map_err(|e| PyValueError::new_err(e.to_string()))?))
        }
        other => return Err(PyValueError::new_err(format!("hardware: expected \"sim\" or \"real\", got {other:?}"))),
    };
    if rt_priority != 0 && matches!(cell, Target::Twin) {
        return Err(PyValueError::new_err(
            "rt_priority: only for hardware=\"real\" (the twin does not run in real time)",
        ));
    }
    let controller = match controller.filter(|c| !c.is_none()) {
        None => None,
        Some(obj) => Some(PyController::new(&obj, scenario.controller.build().max_speed_deg_s())?),
    };
    let (failure, timing) = match &controller {
        Some(c) => (Some(c.failure()), Some(c.timing())),
        None => (None, None),
    };
    let real = matches!(cell, Target::Real(_));
    let out = out.as_deref();
    let (scenario_ref, failure_ref, timing_ref) = (&scenario, failure.clone(), timing.clone());
    let result = interruptible(py, move |interrupted| {
        // Between ticks: Ctrl-C, the Python controller's first error, and (on the real cell) a
        // controller slower than the tick end the run through the cell's safe stop.
        let mut check = move || {
            if interrupted.load(Ordering::SeqCst) {
                return Some(CellError::Device { device: "python".into(), cause: INTERRUPTED.into() });
            }
            if let Some(cause) = failure_ref.as_ref().and_then(Failure::message) {
                return Some(CellError::Device { device: "python controller".into(), cause });
            }
            let slow = timing_ref.as_ref().filter(|_| real).and_then(|t| t.get().too_slow());
            slow.map(|cause| CellError::Device { device: "python controller".into(), cause })
        };
        let driver = Driver { controller: controller.map(|c| Box::new(c) as _), check: Some(&mut check), bag: false };
        match cell {
            Target::Twin => run_on_twin_with(scenario_ref, &ModelCache::default(), out, driver),
            Target::Real(config) => {
                // This thread runs the ticks; the cell's IO threads, started from it, inherit its
                // scheduling (as `tendril run --rt-priority`).
                RealtimeOptions { priority: rt_priority, cpu: None, lock_memory: false }
                    .apply_to_current_thread()
                    .map_err(|e| anyhow::anyhow!("rt_priority {rt_priority}: {e}"))?;
                run_on_real_with(scenario_ref, *config, out, driver)
            }
        }
    });
    if let Some((err, message)) = failure.as_ref().and_then(Failure::take) {
        let raised = ControllerError::new_err(format!("the controller failed; the run was stopped:\n{message}"));
        raised.set_cause(py, Some(err));
        return Err(raised);
    }
    let (summary, report) = result?.map_err(run_error)?;
    let (text, columns) = output(py, &summary, &report, &scenario)?;
    let times = timing.map(|t| call_times_dict(py, &t.get())).transpose()?;
    Ok((text, columns, times))
}

/// Which cell a run drives (the real cell's configuration boxed: with a sensor array's windows it
/// is some 600 bytes).
enum Target {
    Twin,
    Real(Box<RealCellConfig>),
}

/// How often a waiting call looks for Ctrl-C \[s\]: well within a person's patience, and
/// twenty looks a second cost nothing beside a run.
const LOOK: Duration = Duration::from_millis(50);

/// The error a run stopped by Ctrl-C records (its summary's `error`).
const INTERRUPTED: &str = "interrupted (KeyboardInterrupt)";

/// Runs `work` on a thread of its own while this thread, the GIL released between looks, watches
/// for Ctrl-C: Python's handler only sets a flag, which `check_signals` turns into the
/// `KeyboardInterrupt`. On one, `work`'s flag is raised so it can stop cleanly, and once it has,
/// the `KeyboardInterrupt` is raised.
fn interruptible<T: Send>(py: Python<'_>, work: impl FnOnce(&AtomicBool) -> T + Send) -> PyResult<T> {
    let interrupted = AtomicBool::new(false);
    let (done, mut finished) = mpsc::channel();
    std::thread::scope(|scope| {
        let flag = &interrupted;
        scope.spawn(move || {
            let _ = done.send(work(flag));
        });
        let mut raised = None;
        loop {
            // The receiver goes to the detached closure and back: it may not be shared, only moved.
            let (next, back) = py.detach(move || (finished.recv_timeout(LOOK), finished));
            finished = back;
            match next {
                Ok(value) => return raised.map_or(Ok(value), Err),
                Err(RecvTimeoutError::Timeout) => {
                    if raised.is_none()
                        && let Err(e) = py.check_signals()
                    {
                        interrupted.store(true, Ordering::SeqCst);
                        raised = Some(e);
                    }
                }
                Err(RecvTimeoutError::Disconnected) => {
                    return Err(PyRuntimeError::new_err("the run's thread stopped without a result (a panic)"));
                }
            }
        }
    })
}

/// Runs `scenarios` (each a `Scenario` or a path) on the twin in parallel on `threads` threads
/// (default: one per core), the GIL released, scene models compiled once and shared. `progress`,
/// if given, is called as `progress(done, total)` after each run ends (on this thread). Returns
/// the runs in the order given; raises on the first that could not start. Ctrl-C stops the runs
/// under way (each through its cell's safe stop), starts no more and raises `KeyboardInterrupt`.
#[pyfunction]
#[pyo3(signature = (scenarios, threads = None, progress = None))]
pub fn run_many<'py>(
    py: Python<'py>,
    scenarios: &Bound<'py, PyAny>,
    threads: Option<usize>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Vec<(String, Columns<'py>)>> {
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
    let total = list.len();
    let (ended, mut ends) = mpsc::channel::<()>();
    let interrupted = AtomicBool::new(false);
    let mut results = Vec::new();
    let mut raised = None;
    std::thread::scope(|scope| -> PyResult<()> {
        let (list, models, pool, flag) = (&list, &models, &pool, &interrupted);
        let worker = scope.spawn(move || {
            pool.install(|| {
                list.par_iter()
                    .map_with(ended, |ended, s| {
                        let mut check = || {
                            flag.load(Ordering::SeqCst)
                                .then(|| CellError::Device { device: "python".into(), cause: INTERRUPTED.into() })
                        };
                        let driver = Driver { controller: None, check: Some(&mut check), bag: false };
                        let r = (!flag.load(Ordering::SeqCst)).then(|| run_on_twin_with(s, models, None, driver));
                        let _ = ended.send(());
                        r
                    })
                    .collect::<Vec<_>>()
            })
        });
        let mut done = 0;
        while done < total {
            let (next, back) = py.detach(move || (ends.recv_timeout(LOOK), ends));
            ends = back;
            match next {
                Ok(()) => {
                    done += 1;
                    if let Some(p) = progress.as_ref().filter(|_| raised.is_none())
                        && let Err(e) = p.call1((done, total))
                    {
                        interrupted.store(true, Ordering::SeqCst);
                        raised = Some(e);
                    }
                }
                Err(RecvTimeoutError::Timeout) => {}
                Err(RecvTimeoutError::Disconnected) => break,
            }
            if raised.is_none()
                && let Err(e) = py.check_signals()
            {
                interrupted.store(true, Ordering::SeqCst);
                raised = Some(e);
            }
        }
        results = py
            .detach(|| worker.join())
            .map_err(|_| PyRuntimeError::new_err("a run's thread stopped without a result (a panic)"))?;
        Ok(())
    })?;
    if let Some(e) = raised {
        return Err(e);
    }
    list.iter()
        .zip(results)
        .map(|(scenario, result)| {
            let (summary, report) = result
                .ok_or_else(|| PyRuntimeError::new_err("a run did not start"))?
                .map_err(|e| run_error(e.context(format!("scenario `{}`", scenario.name))))?;
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

/// A Python controller's call times as a dict: `calls`, `mean_ms`, `max_ms`, `over_tick` (calls
/// longer than the tick), `tick_ms`.
fn call_times_dict<'py>(py: Python<'py>, t: &CallTimes) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("calls", t.calls)?;
    d.set_item("mean_ms", if t.calls > 0 { 1e3 * t.total_s / t.calls as f64 } else { f64::NAN })?;
    d.set_item("max_ms", 1e3 * t.max_s)?;
    d.set_item("over_tick", t.over_tick)?;
    d.set_item("tick_ms", 1e3 * t.tick_s)?;
    Ok(d)
}

/// The Python side of a finished run.
fn output<'py>(
    py: Python<'py>,
    summary: &RunSummary,
    report: &RunReport,
    scenario: &PickPlaceScenario,
) -> PyResult<(String, Columns<'py>)> {
    let text = summary_json(summary, scenario).map_err(run_error)?;
    Ok((text, columns(py, &report.rows)?))
}
