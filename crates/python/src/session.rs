//! [`Session`]: one run on the twin stepped from Python, tick by tick (what `tendril.env.GripEnv`
//! drives): observe, act (the scenario's controller, a twine speed, or a setpoint), repeat.

use crate::columns::row_dict;
use crate::errors::run_error;
use crate::models::ModelCache;
use crate::scenario::Scenario;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use std::sync::{Arc, Mutex, PoisonError};
use tendril_cell::{Cell, Phase};
use tendril_run::clock::RunClock;
use tendril_run::execute::{summarize, summary_json};
use tendril_run::scenario::PickPlaceScenario;
use tendril_run::session::{Action, Observation};
use tendril_run::trace::TraceRow;
use tendril_twin::frames::Snapshot;
use tendril_twin::physics::SceneModel;
use tendril_twin::sim::SimCell;

/// The task's phases in order: an observation's `phase_index` is the position in this list.
pub const PHASES: [Phase; 9] = [
    Phase::Home,
    Phase::Grow,
    Phase::Wrap,
    Phase::Grasp,
    Phase::Lift,
    Phase::Transfer,
    Phase::Lower,
    Phase::Release,
    Phase::Done,
];

/// A run in progress, or the summary it left.
struct State {
    session: Option<tendril_run::session::Session<SimCell>>,
    backend: String,
    started: RunClock,
    summary: Option<String>,
}

/// One run of a scenario on the twin, stepped by the caller. Started at construction (the cell
/// configured and activated, the first tick read); `finish()` deactivates the cell and returns
/// `summary.json`'s text.
#[pyclass(frozen, module = "tendril._native")]
pub struct Session {
    scenario: PickPlaceScenario,
    scene: Arc<SceneModel>,
    max_speed_deg_s: f64,
    state: Mutex<State>,
}

#[pymethods]
impl Session {
    /// Starts a run of `scenario`, its scene model taken from `models` (compiled there on first use).
    #[new]
    #[pyo3(signature = (scenario, models = None))]
    fn new(py: Python<'_>, scenario: &Scenario, models: Option<&ModelCache>) -> PyResult<Session> {
        let scenario = scenario.scenario.clone();
        let own = ModelCache::default();
        let models = models.unwrap_or(&own);
        let controller = scenario.controller.build();
        let max_speed_deg_s = controller.max_speed_deg_s();
        let state = py.detach(|| -> anyhow::Result<(State, Arc<SceneModel>)> {
            let started = RunClock::start();
            let _ = tendril_twin::mujoco_log::take_warnings();
            let scene = models.inner.get(&scenario.scene_spec())?;
            let cell = scenario.sim_cell(scene.clone());
            let backend = cell.backend().to_string();
            let plan = scenario.control_plan();
            let session = tendril_run::session::Session::start(cell, &plan, controller, None);
            Ok((State { session: Some(session), backend, started, summary: None }, scene))
        });
        let (state, scene) = state.map_err(run_error)?;
        Ok(Session { scenario, scene, max_speed_deg_s, state: Mutex::new(state) })
    }

    /// The largest twine speed the controller commands [°/s]: a `twine_speed_deg_s` action is
    /// clamped to ± this.
    #[getter]
    fn max_speed_deg_s(&self) -> f64 {
        self.max_speed_deg_s
    }

    /// The control tick \[s\]: one `step` advances the cell by this much (1 / `control_rate_hz`).
    #[getter]
    fn dt_s(&self) -> f64 {
        1.0 / self.scenario.control_rate_hz
    }

    /// Whether the run is over (task done, or stopped by an error): no further tick runs.
    #[getter]
    fn is_over(&self) -> bool {
        self.lock().session.as_ref().is_none_or(|s| s.is_over())
    }

    /// The latest reading, which the next `step` acts on, as a dict (`None` once the run is over):
    /// `time_s`, `phase`, `phase_index`, `fbg1_nm`, `fbg2_nm`, `delta1_pm` and `delta2_pm` (the
    /// gratings' shifts from the tare), `force_n`, `array_force_n` (a sensor array's further pads'
    /// estimates, empty without one), `control_force_n` (what the controller regulates),
    /// `force_uncompensated_n`, `over_range`, `setpoint_n`, `time_to_motion_s`, `arm_q_rad`,
    /// `growth_motor_rad`, `twine_motor_rad`, `tool_load_n` and `truth` (the ground truth: `sensor_force_n`, `grip_force_n`,
    /// `object_height_m`, `slip_speed_m_s`, `in_contact`, and for a produce item `produce`: the
    /// contact pressure now and its peak so far \[kPa\], what pressed there, the bruise threshold
    /// \[kPa\], the area above it \[mm²\], the time above it \[s\], `bruised`, the stem's tension
    /// \[N\] and `on_plant`).
    fn observation<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let seen = self.lock().session.as_ref().and_then(|s| s.observation());
        seen.map(|o| observation_dict(py, &o)).transpose()
    }

    /// Runs one tick: the scenario's controller acts, or `twine_speed_deg_s` replaces its output
    /// (clamped to ±`max_speed_deg_s`) in the phases where it would act, or it acts on
    /// `setpoint_n` instead of the scenario's setpoint. Returns the tick's trace row as a dict
    /// (`None` once the run is over).
    #[pyo3(signature = (twine_speed_deg_s = None, setpoint_n = None))]
    fn step<'py>(
        &self,
        py: Python<'py>,
        twine_speed_deg_s: Option<f64>,
        setpoint_n: Option<f64>,
    ) -> PyResult<Option<Bound<'py, PyDict>>> {
        let action = action(twine_speed_deg_s, setpoint_n)?;
        let row = py.detach(|| self.step_once(action));
        row.map(|r| row_dict(py, &r)).transpose()
    }

    /// When ground truth saw the object lost, as `(cell_time_s, phase)` (`None`: not lost).
    fn dropped(&self) -> Option<(f64, &'static str)> {
        self.lock().session.as_ref().and_then(|s| s.dropped()).map(|d| (d.cell_time_s, d.phase.name()))
    }

    /// Ends the run (the cell deactivated, whatever happened) and returns `summary.json`'s text;
    /// called again, returns the same text.
    fn finish(&self, py: Python<'_>) -> PyResult<String> {
        py.detach(|| {
            let mut state = self.lock();
            if let Some(session) = state.session.take() {
                let (mut report, _) = session.finish();
                let summary = summarize(&self.scenario, &state.backend, &mut report, state.started);
                state.summary = Some(summary_json(&summary, &self.scenario)?);
            }
            Ok(state.summary.clone().unwrap_or_default())
        })
        .map_err(run_error)
    }
}

impl Session {
    /// The compiled scene model the session runs.
    pub fn scene(&self) -> Arc<SceneModel> {
        self.scene.clone()
    }

    /// The scene's current state and the cell time of the last tick \[s\] (`None` once the run
    /// is over or when the physics keeps none).
    pub fn snapshot(&self) -> Option<(Snapshot, f64)> {
        let state = self.lock();
        let session = state.session.as_ref()?;
        let time_s = session.rows().last().map_or(0.0, |r| r.time_s);
        session.cell().snapshot().map(|s| (s, time_s))
    }

    /// One tick (without the GIL: the caller detaches).
    fn step_once(&self, action: Action) -> Option<TraceRow> {
        self.lock().session.as_mut().and_then(|s| s.step(action))
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

/// The action of a `step(twine_speed_deg_s, setpoint_n)` call.
fn action(twine_speed_deg_s: Option<f64>, setpoint_n: Option<f64>) -> PyResult<Action> {
    match (twine_speed_deg_s, setpoint_n) {
        (None, None) => Ok(Action::Controller),
        (Some(v), None) if v.is_finite() => Ok(Action::TwineSpeed(v)),
        (None, Some(v)) if v.is_finite() => Ok(Action::Setpoint(v)),
        (Some(_), Some(_)) => Err(PyValueError::new_err("step: give twine_speed_deg_s or setpoint_n, not both")),
        _ => Err(PyValueError::new_err("step: the action must be a finite number")),
    }
}

/// Steps every session in `sessions` one tick, in parallel on the worker threads (one per core),
/// without the GIL: `twine_speeds_deg_s[i]` is session i's `twine_speed_deg_s` (`None`: its
/// controller acts). Returns each tick's trace row as `step` does (`None` for a session whose
/// run is over). What a vector environment steps its twins with.
#[pyfunction]
pub fn step_all<'py>(
    py: Python<'py>,
    sessions: Vec<Bound<'py, Session>>,
    twine_speeds_deg_s: Vec<Option<f64>>,
) -> PyResult<Vec<Option<Bound<'py, PyDict>>>> {
    if sessions.len() != twine_speeds_deg_s.len() {
        return Err(PyValueError::new_err(format!(
            "step_all: {} sessions but {} actions",
            sessions.len(),
            twine_speeds_deg_s.len()
        )));
    }
    let actions = twine_speeds_deg_s.into_iter().map(|v| action(v, None)).collect::<PyResult<Vec<_>>>()?;
    for (i, pair) in sessions.iter().enumerate() {
        if sessions[..i].iter().any(|earlier| earlier.is(pair)) {
            return Err(PyValueError::new_err(format!("step_all: session {i} is given twice")));
        }
    }
    let refs: Vec<&Session> = sessions.iter().map(|s| s.get()).collect();
    let rows: Vec<Option<TraceRow>> = py.detach(|| refs.par_iter().zip(actions).map(|(s, a)| s.step_once(a)).collect());
    rows.iter().map(|r| r.as_ref().map(|r| row_dict(py, r)).transpose()).collect()
}

/// An observation as a dict (see [`Session::observation`]).
fn observation_dict<'py>(py: Python<'py>, o: &Observation) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("time_s", o.time_s)?;
    d.set_item("phase", o.phase.name())?;
    d.set_item("phase_index", PHASES.iter().position(|p| *p == o.phase))?;
    d.set_item("fbg1_nm", o.wavelengths.fbg1_nm)?;
    d.set_item("fbg2_nm", o.wavelengths.fbg2_nm)?;
    d.set_item("delta1_pm", o.estimate.delta1_pm)?;
    d.set_item("delta2_pm", o.estimate.delta2_pm)?;
    d.set_item("force_n", o.estimate.force_n)?;
    d.set_item("array_force_n", o.array_estimate_n.as_slice())?;
    d.set_item("control_force_n", o.control_force_n)?;
    d.set_item("force_uncompensated_n", o.estimate.uncompensated_n)?;
    d.set_item("over_range", o.estimate.over_range)?;
    d.set_item("setpoint_n", o.setpoint_n)?;
    d.set_item("time_to_motion_s", o.time_to_motion_s)?;
    d.set_item("arm_q_rad", o.state.arm_q)?;
    d.set_item("growth_motor_rad", o.state.growth_motor_rad)?;
    d.set_item("twine_motor_rad", o.state.twine_motor_rad)?;
    d.set_item("tool_load_n", o.state.tool_load_n)?;
    let truth = match &o.truth {
        None => None,
        Some(t) => {
            let td = PyDict::new(py);
            td.set_item("sensor_force_n", t.sensor_force_n)?;
            td.set_item("grip_force_n", t.grip_force_n)?;
            td.set_item("object_height_m", t.object_height_m)?;
            td.set_item("slip_speed_m_s", t.slip_speed_m_s)?;
            td.set_item("in_contact", t.in_contact)?;
            if let Some(p) = &t.produce {
                // A produce item's damage and stem (summary's units: kPa, mm²).
                let pd = PyDict::new(py);
                pd.set_item("pressure_kpa", p.pressure_pa / 1e3)?;
                pd.set_item("peak_pressure_kpa", p.peak_pa / 1e3)?;
                pd.set_item("peak_at", p.peak_at)?;
                pd.set_item("bruise_threshold_kpa", p.bruise_pa / 1e3)?;
                pd.set_item("bruise_area_mm2", p.area_above_m2 * 1e6)?;
                pd.set_item("time_above_s", p.time_above_s)?;
                pd.set_item("bruised", p.peak_pa > p.bruise_pa)?;
                pd.set_item("stem_tension_n", p.stem_tension_n)?;
                pd.set_item("on_plant", p.harvest && p.detached_s.is_none())?;
                td.set_item("produce", pd)?;
            }
            Some(td)
        }
    };
    d.set_item("truth", truth)?;
    Ok(d)
}
