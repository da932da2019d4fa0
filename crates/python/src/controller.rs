//! [`PyController`]: a Python object as the run's force controller.
//!
//! [`ForceController::update`] cannot fail, so the first exception (or non-finite return value)
//! is kept in a [`Failure`], the tick gets no twine motion, and the run's check between ticks
//! ([`tendril_run::execute::Driver::check`]) ends the run with it: the cell is deactivated as
//! after any error, and the caller raises it.

use crate::context::ControlContext;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use std::sync::{Arc, Mutex, PoisonError};
use std::time::Instant;
use tendril_control::controller::{self as rust, ForceController};

/// The first error of a Python controller, with its traceback as text.
#[derive(Clone, Default)]
pub struct Failure(Arc<Mutex<Option<(PyErr, String)>>>);

impl Failure {
    fn set(&self, py: Python<'_>, err: PyErr) {
        let mut slot = self.0.lock().unwrap_or_else(PoisonError::into_inner);
        if slot.is_none() {
            let message = describe(py, &err);
            *slot = Some((err, message));
        }
    }

    fn is_set(&self) -> bool {
        self.0.lock().unwrap_or_else(PoisonError::into_inner).is_some()
    }

    /// The error's text, if the controller failed.
    pub fn message(&self) -> Option<String> {
        self.0.lock().unwrap_or_else(PoisonError::into_inner).as_ref().map(|(_, m)| m.clone())
    }

    /// The error and its text, if the controller failed.
    pub fn take(&self) -> Option<(PyErr, String)> {
        self.0.lock().unwrap_or_else(PoisonError::into_inner).take()
    }
}

/// How long the controller's `update` calls took, measured around each call (the GIL's
/// acquisition included: on the real cell the tick waits for both).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct CallTimes {
    /// `update` calls made.
    pub calls: u64,
    /// Their total time \[s\].
    pub total_s: f64,
    /// The longest \[s\].
    pub max_s: f64,
    /// Calls that took longer than the control tick.
    pub over_tick: u64,
    /// The control tick \[s\] (of the last call).
    pub tick_s: f64,
}

impl CallTimes {
    fn add(&mut self, took_s: f64, tick_s: f64) {
        self.calls += 1;
        self.total_s += took_s;
        self.max_s = self.max_s.max(took_s);
        self.over_tick += u64::from(took_s > tick_s);
        self.tick_s = tick_s;
    }

    /// Why the controller is too slow for a real cell, if a call took longer than the tick.
    pub fn too_slow(&self) -> Option<String> {
        (self.over_tick > 0).then(|| {
            format!(
                "update(ctx) took {:.2} ms, longer than the {:.2} ms control tick ({} of {} calls): the \
                 commands would be late",
                self.max_s * 1e3,
                self.tick_s * 1e3,
                self.over_tick,
                self.calls
            )
        })
    }
}

/// The call times, shared between the controller and whoever reports them.
#[derive(Clone, Default)]
pub struct Timing(Arc<Mutex<CallTimes>>);

impl Timing {
    /// The times so far.
    pub fn get(&self) -> CallTimes {
        *self.0.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

/// `err` as Python prints it: the traceback, then `Type: message`.
fn describe(py: Python<'_>, err: &PyErr) -> String {
    let traceback = err.traceback(py).and_then(|t| t.format().ok()).unwrap_or_default();
    format!("{traceback}{err}")
}

/// How the controller is called each tick.
enum Call {
    /// `obj.update(ctx)`.
    Method,
    /// `obj(ctx)`.
    Callable,
}

/// A Python force controller: `update(ctx) -> float` (or the object itself called), the twine
/// motor speed [°/s]; `reset()` when force control starts, if it has one; `max_speed_deg_s` if it
/// has one, else the scenario controller's limit. The output is clamped to ±that limit.
pub struct PyController {
    obj: Py<PyAny>,
    call: Call,
    has_reset: bool,
    max_speed_deg_s: f64,
    failure: Failure,
    timing: Timing,
}

impl std::fmt::Debug for PyController {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "PyController(max_speed_deg_s = {})", self.max_speed_deg_s)
    }
}

impl PyController {
    /// Wraps `obj`; `default_max_speed_deg_s` is the scenario controller's speed limit.
    pub fn new(obj: &Bound<'_, PyAny>, default_max_speed_deg_s: f64) -> PyResult<PyController> {
        let call = if obj.hasattr("update")? {
            Call::Method
        } else if obj.is_callable() {
            Call::Callable
        } else {
            return Err(PyTypeError::new_err(
                "controller: expected an object with an update(ctx) method returning a twine speed in °/s, or a callable",
            ));
        };
        let max_speed_deg_s = match obj.getattr_opt("max_speed_deg_s")? {
            Some(v) if !v.is_none() => {
                let max: f64 = v.extract()?;
                if !(max.is_finite() && max > 0.0) {
                    return Err(PyValueError::new_err(format!(
                        "controller.max_speed_deg_s: must be a finite speed > 0 °/s, got {max}"
                    )));
                }
                max
            }
            _ => default_max_speed_deg_s,
        };
        Ok(PyController {
            obj: obj.clone().unbind(),
            call,
            has_reset: obj.hasattr("reset")?,
            max_speed_deg_s,
            failure: Failure::default(),
            timing: Timing::default(),
        })
    }

    /// Where the controller's call times are kept.
    pub fn timing(&self) -> Timing {
        self.timing.clone()
    }

    /// Where the controller's first error is kept.
    pub fn failure(&self) -> Failure {
        self.failure.clone()
    }

    fn speed(&self, py: Python<'_>, ctx: &rust::ControlContext) -> PyResult<f64> {
        let obj = self.obj.bind(py);
        let ctx = Bound::new(py, ControlContext::from(ctx))?;
        let out = match self.call {
            Call::Method => obj.call_method1("update", (ctx,))?,
            Call::Callable => obj.call1((ctx,))?,
        };
        let speed: f64 = out.extract().map_err(|_| {
            PyTypeError::new_err(format!(
                "update(ctx) returned {}, not a number (the twine speed in °/s)",
                out.repr().map_or_else(|_| "an object".to_string(), |r| r.to_string())
            ))
        })?;
        if !speed.is_finite() {
            return Err(PyValueError::new_err(format!("update(ctx) returned {speed}: the twine speed must be finite")));
        }
        Ok(speed.clamp(-self.max_speed_deg_s, self.max_speed_deg_s))
    }
}

impl ForceController for PyController {
    fn update(&mut self, ctx: &rust::ControlContext) -> f64 {
        if self.failure.is_set() {
            return 0.0;
        }
        let started = Instant::now();
        let speed = Python::attach(|py| {
            self.speed(py, ctx).unwrap_or_else(|e| {
                self.failure.set(py, e);
                0.0
            })
        });
        self.timing.0.lock().unwrap_or_else(PoisonError::into_inner).add(started.elapsed().as_secs_f64(), ctx.dt_s);
        speed
    }

    fn reset(&mut self) {
        if !self.has_reset || self.failure.is_set() {
            return;
        }
        Python::attach(|py| {
            if let Err(e) = self.obj.bind(py).call_method0("reset") {
                self.failure.set(py, e);
            }
        });
    }

    fn max_speed_deg_s(&self) -> f64 {
        self.max_speed_deg_s
    }
}
