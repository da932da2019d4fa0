//! The control loop over any [`Cell`]: read → estimate → sequence/control → write → wait.
//!
//! This is the code that runs unchanged on the twin and on the real cell.

use super::drop_watch::DropWatch;
use super::metrics::{ControlMetrics, control_metrics};
use super::trace::{TraceRow, TraceWriter};
use crate::control::controller::{ControllerConfig, ForceController};
use crate::control::estimate::{Estimate, EstimateError, ForceCalibration, ForceEstimator};
use crate::control::gripper::GripperConfig;
use crate::control::slip::{Alarms, ArmReading, Judgement, SlipConfig, SlipDetector, SlipEvents, judge};
use crate::control::task::{Phase, TaskConfig, TaskSequencer};
use crate::hardware::{Cell, CellError};
use crate::signals::Wavelengths;
use serde::Serialize;

/// Everything the control side needs for one run (the cell is configured separately).
#[derive(Debug, Clone)]
pub struct ControlPlan {
    /// Force setpoint \[N\].
    pub setpoint_n: f64,
    /// Keep force control on while the arm moves.
    pub feedback: bool,
    /// Control loop rate \[Hz\].
    pub rate_hz: f64,
    /// The force controller (`[controller]`).
    pub controller: ControllerConfig,
    /// Calibration used by the estimator (eq. 8).
    pub calibration: ForceCalibration,
    /// Poses and timing.
    pub task: TaskConfig,
    /// Drive-train geometry.
    pub gripper: GripperConfig,
    /// Slip detector thresholds.
    pub slip: SlipConfig,
    /// The object's weight \[N\], when known (its mass from the scenario): what the wrist must read
    /// once the lift is under way ([`SlipDetector::with_object_weight`]).
    pub object_weight_n: Option<f64>,
}

/// How a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Outcome {
    /// The object stayed in the hand until the release.
    Held,
    /// The object was lost before the release.
    Dropped,
    /// The run stopped on an error (physics divergence, device fault).
    Error,
}

/// When and where the object was lost.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Drop {
    /// Cell time of the loss \[s\].
    pub cell_time_s: f64,
    /// Phase in which it happened.
    pub phase: Phase,
}

/// The result of a run: outcome, events and metrics; the rows are kept for plotting.
#[derive(Debug, Clone)]
pub struct RunReport {
    /// Held, dropped or error.
    pub outcome: Outcome,
    /// The loss, if any (from ground truth when the cell has it, else from the sensor).
    pub drop: Option<Drop>,
    /// Cell time when the arm started moving the object \[s\].
    pub motion_start_s: Option<f64>,
    /// What the sensor-based slip detector saw.
    pub slip: SlipEvents,
    /// The detector's alarm episodes.
    pub alarms: Alarms,
    /// The drop alarms judged against the true drop (`None` on a cell without ground truth).
    pub detection: Option<Judgement>,
    /// Rise time, overshoot, fluctuation, estimate error.
    pub metrics: ControlMetrics,
    /// Cell time reached \[s\].
    pub cell_time_s: f64,
    /// The error that ended the run, with its time.
    pub error: Option<String>,
    /// Sensor samples skipped because they gave no estimate (the last valid one was held).
    pub invalid_samples: u64,
    /// Control ticks without a new interrogator sample ([`Cell::sample_is_new`]): the last
    /// estimate was held. They do not count as invalid samples.
    pub dropped_samples: u64,
    /// Every tick, as written to the trace.
    pub rows: Vec<TraceRow>,
    /// How the device streams kept up (a real cell).
    pub device_timing: Option<crate::hardware::DeviceTiming>,
}

/// Consecutive invalid sensor samples (no estimate: non-finite, or below the calibration curve)
/// that end a run: [`crate::hardware::BLIND_TICKS`]. A lone bad sample is skipped and the last
/// valid estimate held; a sensor that stays bad longer (a broken fibre, an interrogator out of
/// lock) leaves the loop blind and must stop the run.
pub const MAX_CONSECUTIVE_INVALID_SAMPLES: u32 = crate::hardware::BLIND_TICKS;

/// Runs the task on `cell`, writing each tick to `trace` when given. The cell is configured,
/// activated and, whatever happens, deactivated. Cell errors end the run with
/// [`Outcome::Error`]; the rows up to the error are kept. The force controller is the one
/// `plan.controller` describes.
pub fn run_task(cell: &mut dyn Cell, plan: &ControlPlan, trace: Option<&mut TraceWriter>) -> RunReport {
    run_task_with_controller(cell, plan, plan.controller.build(), trace)
}

/// As [`run_task`], with the force controller given (`plan.controller` is not used): any
/// [`ForceController`], including one defined outside the crate.
pub fn run_task_with_controller(
    cell: &mut dyn Cell,
    plan: &ControlPlan,
    controller: Box<dyn ForceController>,
    trace: Option<&mut TraceWriter>,
) -> RunReport {
    run_task_observed(cell, plan, controller, trace, &mut |_, _| {})
}

/// Called once per control tick, after the tick's row is written and before the cell waits for
/// the next tick: a live view (`tendril view`) shows the row and may steer the sequencer (switch
/// force feedback). A hook that does nothing leaves the run exactly as [`run_task_with_controller`].
pub type TickHook<'a> = dyn FnMut(&TraceRow, &mut TaskSequencer) + 'a;

/// As [`run_task_with_controller`], with `hook` called on every tick (see [`TickHook`]).
pub fn run_task_observed(
    cell: &mut dyn Cell,
    plan: &ControlPlan,
    controller: Box<dyn ForceController>,
    mut trace: Option<&mut TraceWriter>,
    hook: &mut TickHook<'_>,
) -> RunReport {
    let mut rows = Vec::new();
    let mut sequencer = TaskSequencer::new(plan.task.clone(), plan.gripper, controller, plan.setpoint_n, plan.feedback);
    let mut invalid = InvalidSamples::default();
    let mut slip = SlipDetector::new(plan.slip);
    if let Some(weight) = plan.object_weight_n {
        slip = slip.with_object_weight(weight);
    }
    let mut drop_watch = DropWatch::default();
    let mut truth_drop: Option<Drop> = None;
    let mut dropped_samples = 0u64;
    let mut last_phase: Option<Phase> = None;
    let dt = 1.0 / plan.rate_hz;

    let mut run = || -> Result<(), CellError> {
        cell.configure()?;
        cell.activate()?;
        let mut estimator = ForceEstimator::new(plan.calibration.clone());
        let mut tare = TareAverager::default();
        let mut unloaded_n = 0.0;
        for tick in 0u64.. {
            // An operator stop (Ctrl-C, SIGTERM, SIGHUP) ends the run like a device fault: through
            // the cell's safe stop below, with every row written whole.
            if let Some(signal) = crate::interrupt::requested() {
                return Err(CellError::Stopped { signal: crate::interrupt::name(signal), time_s: tick as f64 * dt });
            }
            let state = cell.read()?;
            // No new sample (an interrogator gap): hold the last estimate, as for an invalid
            // sample, but without counting towards the consecutive-invalid limit (see
            // `crate::cell::disturbance::DropoutConfig`).
            let held = match invalid.last_valid {
                Some(e) if !cell.sample_is_new() => Some(e),
                _ => None,
            };
            if held.is_none() && sequencer.phase() == Phase::Home {
                // Tare on the mean of the samples at home, finger retracted and untouched (a
                // non-finite sample is left out: it would poison the mean for the whole run).
                if state.wavelengths.fbg1_nm.is_finite() && state.wavelengths.fbg2_nm.is_finite() {
                    tare.add(state.wavelengths);
                }
                let mean = tare.mean();
                estimator.tare(mean);
                unloaded_n = estimator.estimate(mean).map_or(0.0, |e| e.force_n);
                sequencer.set_unloaded_reading(unloaded_n);
            }
            if sequencer.phase() == Phase::Home {
                slip.observe_home_load(state.tool_load_n);
            }
            let estimate = match held {
                Some(e) => {
                    dropped_samples += 1;
                    e
                }
                None => invalid.check(estimator.track(state.wavelengths)).map_err(|cause| CellError::Device {
                    device: "estimator".into(),
                    cause: format!("at t = {:.3} s: {cause}", state.time_s),
                })?,
            };
            let decision = sequencer.update(&state, estimate.force_n, dt);
            if last_phase != Some(decision.phase) {
                cell.phase_started(decision.phase, state.time_s);
                last_phase = Some(decision.phase);
            }
            // Slip is watched while the arm carries the object, as in the paper.
            slip.update(
                state.time_s,
                estimate.force_n,
                ArmReading::from_joints(&state.arm_q, state.tool_load_n),
                unloaded_n,
                sequencer.reading_noise_n(),
                plan.setpoint_n,
                decision.phase.arm_moving(),
            );
            cell.write(&decision.command)?;

            let truth = cell.ground_truth();
            if let Some(t) = &truth {
                truth_drop = drop_watch.update(state.time_s, decision.phase, t);
            }
            let nan = f64::NAN;
            let row = TraceRow {
                time_s: state.time_s,
                phase: decision.phase,
                true_force_n: truth.map_or(nan, |t| t.sensor_force_n),
                fbg1_nm: state.wavelengths.fbg1_nm,
                fbg2_nm: state.wavelengths.fbg2_nm,
                force_n: estimate.force_n,
                force_uncompensated_n: estimate.uncompensated_n,
                over_range: estimate.over_range,
                setpoint_n: plan.setpoint_n,
                controller_on: decision.controller_on,
                controller_output_deg_s: decision.controller_output_deg_s,
                growth_motor_rad: state.growth_motor_rad,
                twine_motor_rad: state.twine_motor_rad,
                object_height_m: truth.map_or(nan, |t| t.object_height_m),
                slip_speed_m_s: truth.map_or(nan, |t| t.slip_speed_m_s),
                grip_force_n: truth.map_or(nan, |t| t.grip_force_n),
                tool_load_n: state.tool_load_n.unwrap_or(nan),
            };
            if let Some(w) = trace.as_deref_mut() {
                w.write(&row).map_err(|e| CellError::Device { device: "trace".into(), cause: e.to_string() })?;
            }
            hook(&row, &mut sequencer);
            rows.push(row);
            if decision.phase == Phase::Done {
                return Ok(());
            }
            cell.wait_until((tick + 1) as f64 * dt)?;
        }
        Ok(())
    };
    let result = run();
    let stop = cell.deactivate();
    let device_timing = cell.device_timing();
    if let Some(w) = trace {
        // A failed flush is kept in the writer and reported by the caller with the other write errors.
        let _ = w.flush();
    }
    let error = result.err().or(stop.err()).map(|e| e.to_string());

    let sensor_drop = slip.events().dropped_s.map(|t| Drop { cell_time_s: t, phase: phase_at(&rows, t) });
    let has_truth = rows.first().is_some_and(|r| r.true_force_n.is_finite());
    let drop = if has_truth { truth_drop } else { sensor_drop };
    let outcome = match (&error, drop) {
        (Some(_), _) => Outcome::Error,
        (None, Some(_)) => Outcome::Dropped,
        (None, None) => Outcome::Held,
    };
    let metrics = control_metrics(&rows, drop.map(|d| d.cell_time_s));
    RunReport {
        outcome,
        drop,
        motion_start_s: sequencer.motion_start_s(),
        slip: slip.events(),
        detection: has_truth.then(|| judge(&slip.alarms().drops_s, truth_drop.map(|d| d.cell_time_s))),
        alarms: slip.alarms().clone(),
        metrics,
        cell_time_s: rows.last().map_or(0.0, |r| r.time_s),
        error,
        invalid_samples: invalid.total,
        dropped_samples,
        rows,
        device_timing,
    }
}

/// Skips invalid estimates, holding the last valid one, until too many come in a row.
#[derive(Debug, Default)]
struct InvalidSamples {
    last_valid: Option<Estimate>,
    consecutive: u32,
    total: u64,
}

impl InvalidSamples {
    /// The estimate to use this tick, or why the run must stop: no tare, or
    /// [`MAX_CONSECUTIVE_INVALID_SAMPLES`] invalid samples in a row (or one before any valid).
    fn check(&mut self, estimate: Result<Estimate, EstimateError>) -> Result<Estimate, String> {
        match estimate {
            Ok(e) => {
                self.consecutive = 0;
                self.last_valid = Some(e);
                Ok(e)
            }
            Err(e @ EstimateError::NotTared) => Err(e.to_string()),
            Err(e) => {
                self.consecutive += 1;
                self.total += 1;
                match self.last_valid {
                    Some(held) if self.consecutive < MAX_CONSECUTIVE_INVALID_SAMPLES => Ok(held),
                    Some(_) => Err(format!("{} consecutive invalid samples, the last: {e}", self.consecutive)),
                    None => Err(format!("no valid sample yet: {e}")),
                }
            }
        }
    }
}

/// The phase of the last row at or before `time_s`.
fn phase_at(rows: &[TraceRow], time_s: f64) -> Phase {
    rows.iter().rev().find(|r| r.time_s <= time_s).map_or(Phase::Home, |r| r.phase)
}

/// Running mean of wavelength samples, for the tare.
#[derive(Debug, Default)]
struct TareAverager {
    sum1: f64,
    sum2: f64,
    n: u32,
}

impl TareAverager {
    fn add(&mut self, w: Wavelengths) {
        self.sum1 += w.fbg1_nm;
        self.sum2 += w.fbg2_nm;
        self.n += 1;
    }

    fn mean(&self) -> Wavelengths {
        let n = f64::from(self.n.max(1));
        Wavelengths { fbg1_nm: self.sum1 / n, fbg2_nm: self.sum2 / n }
    }
}
