//! One run, one tick at a time: [`Session`] owns what a run is (the cell, the sequencer and its
//! controller, the estimator, the slip and drop watches, the trace) and steps it when asked.
//!
//! ```text
//! Session::start(cell, plan, controller, trace)   configure + activate the cell, read tick 0
//! loop {
//!     session.observation()                       the reading: wavelengths, estimate, phase, ...
//!     session.step(action) -> TraceRow            sequence/control → write → record → wait → read
//! }
//! session.finish() -> (RunReport, trace)          deactivate (whatever happened), judge the run
//! ```
//!
//! Every way of running the task drives this one loop body: `tendril run` on the twin or with
//! `--hardware real`, `view`, `sweep`, the studies, `fit` and `tune` (through
//! [`crate::runner::run_task`] and [`crate::execute`]), and a caller that acts itself (a learning
//! controller, a notebook): each [`Action`] either lets the configured controller act or takes its
//! place for the tick.

use super::array_estimates::ArrayEstimates;
use super::bag::RunBag;
use super::drop_watch::DropWatch;
use super::metrics::control_metrics;
use super::plan::ControlPlan;
use super::report::{Drop, Outcome, RunReport};
use super::samples::{InvalidSamples, TareAverager};
use super::trace::{ArrayRow, PadRow, ProduceRow, TraceRow, TraceWriter};
use tendril_cell::{Cell, CellError, CellState, GroundTruth, Phase, Wavelengths};
use tendril_control::array_cue::ArrayCue;
use tendril_control::controller::ForceController;
use tendril_control::slip::{ArmReading, SlipDetector, judge};
use tendril_control::task::{ControlAction, TaskSequencer};
use tendril_fbg::array::{MAX_PADS, PerPad};
use tendril_fbg::estimate::{Estimate, ForceEstimator};

/// What drives the force loop this tick.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Action {
    /// The configured controller acts (what `tendril run` does every tick).
    #[default]
    Controller,
    /// This twine motor speed [°/s] instead of the controller's output, in the phases where the
    /// controller would act (the grasp, and the arm's moves with feedback on). Clamped to the
    /// controller's speed limit as its own output is.
    TwineSpeed(f64),
    /// The configured controller acts on this setpoint \[N\] instead of the scenario's, this tick.
    Setpoint(f64),
}

/// What the caller sees between ticks: the latest reading, which the next [`Session::step`]
/// acts on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Observation {
    /// Cell time of the reading \[s\].
    pub time_s: f64,
    /// The task's phase as the last tick left it (the next step may move it on).
    pub phase: Phase,
    /// The interrogator's sample.
    pub wavelengths: Wavelengths,
    /// The force estimate (eq. 8) the next step uses (held when the sample was not new or was
    /// invalid).
    pub estimate: Estimate,
    /// The further pads' force estimates of a sensor array \[N\] (empty without one).
    pub array_estimate_n: PerPad<f64>,
    /// The force the controller regulates \[N\]: `estimate.force_n`, or with a sensor array the
    /// signal `array.control` names over all pads.
    pub control_force_n: f64,
    /// The task's force setpoint \[N\].
    pub setpoint_n: f64,
    /// Time to the arm's next move \[s\]: counts down in the grasp, 0 while it moves, +∞ when no
    /// move is planned.
    pub time_to_motion_s: f64,
    /// The cell's state: arm joints, motor angles, the wrist's load.
    pub state: CellState,
    /// What only a simulation knows (`None` on the real cell).
    pub truth: Option<GroundTruth>,
}

/// A reading not yet acted on.
struct Pending {
    state: CellState,
    estimate: Estimate,
    /// The further pads' estimates \[N\].
    array: PerPad<f64>,
    /// The force the controller regulates \[N\].
    control_force_n: f64,
}

/// One run in progress (see the module docs).
pub struct Session<C: Cell> {
    cell: C,
    plan: ControlPlan,
    sequencer: TaskSequencer,
    estimator: ForceEstimator,
    tare: TareAverager,
    array: ArrayEstimates,
    /// The array's slip cue (watches nothing without an array).
    cue: ArrayCue,
    /// When the run acted on the cue (`array.retighten_factor`), cell time \[s\].
    retightened_s: Option<f64>,
    unloaded_n: f64,
    invalid: InvalidSamples,
    slip: SlipDetector,
    drop_watch: DropWatch,
    truth_drop: Option<Drop>,
    dropped_samples: u64,
    last_phase: Option<Phase>,
    dt_s: f64,
    tick: u64,
    rows: Vec<TraceRow>,
    trace: Option<TraceWriter>,
    /// The run's bag, when it records one ([`Session::record_bag`]).
    bag: Option<RunBag>,
    /// The reading the next step acts on.
    pending: Option<Pending>,
    /// Why the run ended early, if it did.
    error: Option<CellError>,
    over: bool,
}

impl<C: Cell> Session<C> {
    /// Starts a run of `plan` on `cell` (configured and activated here) with `controller`,
    /// writing each tick to `trace` when given, and takes the first tick's reading. A cell that
    /// cannot be started ends the run at once: [`Session::step`] then returns `None` and
    /// [`Session::finish`] reports the error.
    pub fn start(
        mut cell: C,
        plan: &ControlPlan,
        controller: Box<dyn ForceController>,
        trace: Option<TraceWriter>,
    ) -> Self {
        let sequencer = TaskSequencer::new(plan.task.clone(), plan.gripper, controller, plan.setpoint_n, plan.feedback);
        let mut slip = SlipDetector::new(plan.slip);
        if let Some(weight) = plan.object_weight_n {
            slip = slip.with_object_weight(weight);
        }
        let error = cell.configure().and_then(|()| cell.activate()).err();
        let mut session = Session {
            estimator: ForceEstimator::new(plan.calibration.clone()),
            plan: plan.clone(),
            sequencer,
            tare: TareAverager::default(),
            array: ArrayEstimates::default(),
            cue: ArrayCue::new(plan.array.cue_transfer, plan.array.cue_tau_s, plan.array.cue_min_load_n),
            retightened_s: None,
            unloaded_n: 0.0,
            invalid: InvalidSamples::default(),
            slip,
            drop_watch: DropWatch::default(),
            truth_drop: None,
            dropped_samples: 0,
            last_phase: None,
            dt_s: 1.0 / plan.rate_hz,
            tick: 0,
            rows: Vec::new(),
            trace,
            bag: None,
            pending: None,
            over: error.is_some(),
            error,
            cell,
        };
        if !session.over {
            session.sense();
        }
        session
    }

    /// Records every tick from now on into `bag` too (a run's `bag/`), ended by
    /// [`Session::finish`] whatever happens.
    pub fn record_bag(&mut self, bag: RunBag) {
        self.bag = Some(bag);
    }

    /// What the caller sees now: the latest reading, not yet acted on (`None` once the run is over).
    pub fn observation(&self) -> Option<Observation> {
        let p = self.pending.as_ref()?;
        Some(Observation {
            time_s: p.state.time_s,
            phase: self.sequencer.phase(),
            wavelengths: p.state.wavelengths,
            estimate: p.estimate,
            array_estimate_n: p.array,
            control_force_n: p.control_force_n,
            setpoint_n: self.sequencer.setpoint_n(),
            time_to_motion_s: self.sequencer.time_to_motion_s(p.state.time_s),
            state: p.state,
            truth: self.cell.ground_truth(),
        })
    }

    /// Acts on the latest reading as `action` says, records the tick, waits for the next tick and
    /// reads it. Returns the tick's trace row (`None` once the run is over: the task done, or an
    /// error, which [`Session::finish`] reports); [`Session::observation`] then holds the next
    /// reading.
    pub fn step(&mut self, action: Action) -> Option<TraceRow> {
        let pending = self.pending.take()?;
        match self.act(pending, action) {
            Ok(row) => {
                if row.phase == Phase::Done {
                    self.over = true;
                } else {
                    self.tick += 1;
                    match self.cell.wait_until(self.tick as f64 * self.dt_s) {
                        Ok(()) => self.sense(),
                        Err(e) => self.fail(e),
                    }
                }
                Some(row)
            }
            Err(e) => {
                self.fail(e);
                None
            }
        }
    }

    /// Runs every remaining tick with the configured controller.
    pub fn run_to_end(&mut self) {
        while self.step(Action::Controller).is_some() {}
    }

    /// Whether the run is over (no further tick will run).
    pub fn is_over(&self) -> bool {
        self.over
    }

    /// The rows so far.
    pub fn rows(&self) -> &[TraceRow] {
        &self.rows
    }

    /// The cell, for what only its own type offers (a real cell's motor statistics, say).
    pub fn cell(&self) -> &C {
        &self.cell
    }

    /// Switches force feedback during the arm's moves on or off from the next tick on (a live
    /// view's key; see [`TaskSequencer::set_feedback`]).
    pub fn set_feedback(&mut self, on: bool) {
        self.sequencer.set_feedback(on);
    }

    /// Whether force feedback is on during the arm's moves.
    pub fn feedback(&self) -> bool {
        self.sequencer.feedback()
    }

    /// The object's loss as ground truth saw it so far (`None`: still held, or a cell without
    /// ground truth): what a caller stepping the run watches for (a learning environment ends an
    /// episode on it).
    pub fn dropped(&self) -> Option<Drop> {
        self.truth_drop
    }

    /// Ends the run with `error` (a controller defined outside the crate that failed, say): no
    /// further tick runs, and [`Session::finish`] deactivates the cell and reports the run as an
    /// [`Outcome::Error`] with this error.
    pub fn abort(&mut self, error: CellError) {
        if self.error.is_none() {
            self.fail(error);
        }
    }

    fn fail(&mut self, e: CellError) {
        self.error = Some(e);
        self.over = true;
        self.pending = None;
    }

    /// Reads the tick's state and estimates the force: the reading the next [`Session::step`]
    /// acts on.
    fn sense(&mut self) {
        match self.read_and_estimate() {
            Ok(p) => self.pending = Some(p),
            Err(e) => self.fail(e),
        }
    }

    fn read_and_estimate(&mut self) -> Result<Pending, CellError> {
        // An operator stop (Ctrl-C, SIGTERM, SIGHUP) ends the run like a device fault: through
        // the cell's safe stop in `finish`, with every row written whole.
        if let Some(signal) = tendril_cell::interrupt::requested() {
            let time_s = self.tick as f64 * self.dt_s;
            return Err(CellError::Stopped { signal: tendril_cell::interrupt::name(signal), time_s });
        }
        let state = self.cell.read()?;
        // No new sample (an interrogator gap): hold the last estimate, as for an invalid sample,
        // but without counting towards the consecutive-invalid limit (see
        // `tendril_twin::disturbance::DropoutConfig`).
        let held = match self.invalid.last_valid {
            Some(e) if !self.cell.sample_is_new() => Some(e),
            _ => None,
        };
        if held.is_none() && self.sequencer.phase() == Phase::Home {
            // Tare on the mean of the samples at home, finger retracted and untouched (a
            // non-finite sample is left out: it would poison the mean for the whole run).
            if state.wavelengths.fbg1_nm.is_finite() && state.wavelengths.fbg2_nm.is_finite() {
                self.tare.add(state.wavelengths);
            }
            let mean = self.tare.mean();
            self.estimator.tare(mean);
            self.unloaded_n = self.estimator.estimate(mean).map_or(0.0, |e| e.force_n);
            self.sequencer.set_unloaded_reading(self.unloaded_n);
            self.array.tare(&state.array, &self.plan.calibration, &self.plan.array.calibrations);
        }
        if self.sequencer.phase() == Phase::Home {
            self.slip.observe_home_load(state.tool_load_n);
        }
        let estimate = match held {
            Some(e) => {
                self.dropped_samples += 1;
                e
            }
            None => self.invalid.check(self.estimator.track(state.wavelengths)).map_err(|cause| CellError::Device {
                device: "estimator".into(),
                cause: format!("at t = {:.3} s: {cause}", state.time_s),
            })?,
        };
        let own = &self.plan.array.calibrations;
        let array =
            self.array.estimate(&state.array, held.is_some(), &self.plan.calibration, own).map_err(|cause| {
                CellError::Device {
                    device: "estimator".into(),
                    cause: format!("at t = {:.3} s: {cause}", state.time_s),
                }
            })?;
        let control_force_n = if array.is_empty() {
            estimate.force_n
        } else {
            let mut all = [0.0; MAX_PADS];
            all[0] = estimate.force_n;
            all[1..=array.len()].copy_from_slice(array.as_slice());
            self.plan.array.control.of(&all[..=array.len()])
        };
        Ok(Pending { state, estimate, array, control_force_n })
    }

    /// Sequences and controls on a reading, writes the command, records the tick.
    fn act(&mut self, p: Pending, action: Action) -> Result<TraceRow, CellError> {
        let (state, estimate, force_n) = (p.state, p.estimate, p.control_force_n);
        self.watch_array(&state, &estimate, &p.array);
        let control = match action {
            Action::Controller => match self.retightened_s {
                Some(_) => ControlAction::Setpoint(self.plan.setpoint_n * self.plan.array.retighten_factor),
                None => ControlAction::Controller,
            },
            Action::TwineSpeed(deg_s) => ControlAction::TwineSpeed(deg_s),
            Action::Setpoint(n) => ControlAction::Setpoint(n),
        };
        let decision = self.sequencer.update_with(&state, force_n, self.dt_s, control);
        if self.last_phase != Some(decision.phase) {
            self.cell.phase_started(decision.phase, state.time_s);
            self.last_phase = Some(decision.phase);
        }
        // Slip is watched while the arm carries the object, as in the paper.
        self.slip.update(
            state.time_s,
            force_n,
            ArmReading::from_joints(&state.arm_q, state.tool_load_n),
            self.unloaded_n,
            self.sequencer.reading_noise_n(),
            self.plan.setpoint_n,
            decision.phase.arm_moving(),
        );
        self.cell.write(&decision.command)?;

        let truth = self.cell.ground_truth();
        if let Some(t) = &truth {
            self.truth_drop = self.drop_watch.update(state.time_s, decision.phase, t);
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
            setpoint_n: decision.setpoint_n,
            controller_on: decision.controller_on,
            controller_output_deg_s: decision.controller_output_deg_s,
            growth_motor_rad: state.growth_motor_rad,
            twine_motor_rad: state.twine_motor_rad,
            object_height_m: truth.map_or(nan, |t| t.object_height_m),
            slip_speed_m_s: truth.map_or(nan, |t| t.slip_speed_m_s),
            grip_force_n: truth.map_or(nan, |t| t.grip_force_n),
            tool_load_n: state.tool_load_n.unwrap_or(nan),
            array: array_row(&state, truth.as_ref(), &p.array, force_n),
            produce: truth.and_then(|t| t.produce).map(|p| ProduceRow {
                pressure_kpa: p.pressure_pa / 1e3,
                bruise_area_mm2: p.area_above_m2 * 1e6,
                stem_tension_n: p.stem_tension_n,
                on_plant: p.harvest && p.detached_s.is_none(),
                bump_force_n: p.pad_bump_force_n,
            }),
        };
        if let Some(w) = self.trace.as_mut() {
            w.write(&row).map_err(|e| CellError::Device { device: "trace".into(), cause: e.to_string() })?;
        }
        if let Some(b) = self.bag.as_mut() {
            b.record(&state, &decision.command, &row)
                .map_err(|e| CellError::Device { device: "bag".into(), cause: e.to_string() })?;
        }
        self.rows.push(row);
        Ok(row)
    }

    /// The array's slip cue on this tick's loads (each pad's estimate above its unloaded
    /// reading), watching while the arm carries the object; its first alarm re-tightens the grip
    /// when the scenario asks (`array.retighten_factor` > 1).
    fn watch_array(&mut self, state: &CellState, estimate: &Estimate, array: &PerPad<f64>) {
        if array.is_empty() {
            return;
        }
        let mut loads = [0.0; MAX_PADS];
        loads[0] = estimate.force_n - self.unloaded_n;
        for (k, f) in array.as_slice().iter().enumerate() {
            loads[k + 1] = f - self.array.unloaded_n(k);
        }
        let watching = self.sequencer.phase().arm_moving();
        if self.cue.update(state.time_s, &loads[..=array.len()], watching)
            && self.retightened_s.is_none()
            && self.plan.array.retighten_factor > 1.0
        {
            self.retightened_s = Some(state.time_s);
        }
    }

    /// Ends the run: the cell deactivated whatever happened (and the trace flushed), the run
    /// judged. Returns the report and the trace writer (whose write errors the caller reports).
    pub fn finish(mut self) -> (RunReport, Option<TraceWriter>) {
        let stop = self.cell.deactivate();
        let device_timing = self.cell.device_timing();
        if let Some(w) = self.trace.as_mut() {
            // A failed flush is kept in the writer and reported by the caller with the other
            // write errors.
            let _ = w.flush();
        }
        // The bag is ended whatever happened: the ticks recorded stay readable.
        let bag = self.bag.take().map(RunBag::finish).and_then(Result::err);
        let error = self.error.take().or(stop.err()).map(|e| e.to_string()).or(bag.map(|e| format!("bag: {e}")));
        let rows = std::mem::take(&mut self.rows);
        let slip = &self.slip;
        let sensor_drop = slip.events().dropped_s.map(|t| Drop { cell_time_s: t, phase: phase_at(&rows, t) });
        let has_truth = rows.first().is_some_and(|r| r.true_force_n.is_finite());
        let drop = if has_truth { self.truth_drop } else { sensor_drop };
        let grasp = self.sequencer.grasp_outcome();
        let timed_out = grasp.is_some_and(|g| g.end == tendril_control::settle::GraspEnd::TimedOut);
        let outcome = match (&error, drop) {
            (Some(_), _) => Outcome::Error,
            (None, Some(_)) => Outcome::Dropped,
            (None, None) if timed_out => Outcome::NotGrasped,
            (None, None) => Outcome::Held,
        };
        let metrics = control_metrics(&rows, drop.map(|d| d.cell_time_s));
        let array = rows.first().filter(|r| !r.array.pads.is_empty()).map(|_| {
            super::array_summary::summarise(
                &rows,
                self.cue.alarms_s(),
                self.retightened_s,
                drop.map(|d| d.cell_time_s),
                self.sequencer.motion_start_s(),
                self.plan.calibration.range_n,
            )
        });
        let produce = self.cell.ground_truth().and_then(|t| t.produce);
        let report = RunReport {
            produce,
            outcome,
            drop,
            motion_start_s: self.sequencer.motion_start_s(),
            slip: slip.events(),
            detection: has_truth.then(|| judge(&slip.alarms().drops_s, self.truth_drop.map(|d| d.cell_time_s))),
            alarms: slip.alarms().clone(),
            metrics,
            cell_time_s: rows.last().map_or(0.0, |r| r.time_s),
            error,
            invalid_samples: self.invalid.total + self.array.invalid_total(),
            dropped_samples: self.dropped_samples,
            rows,
            device_timing,
            array,
            grasp,
            hold: self.sequencer.hold_record(),
        };
        (report, self.trace.take())
    }
}

/// A sensor array's columns of a tick: each further pad's truth, peaks and estimate.
fn array_row(
    state: &CellState,
    truth: Option<&GroundTruth>,
    estimates: &PerPad<f64>,
    control_force_n: f64,
) -> ArrayRow {
    let mut pads = PerPad::filled(state.array.len(), PadRow::default());
    for (k, row) in pads.as_mut_slice().iter_mut().enumerate() {
        let w = state.array.as_slice()[k];
        *row = PadRow {
            true_force_n: truth.and_then(|t| t.array_force_n.as_slice().get(k).copied()).unwrap_or(f64::NAN),
            fbg1_nm: w.fbg1_nm,
            fbg2_nm: w.fbg2_nm,
            force_n: estimates.as_slice().get(k).copied().unwrap_or(f64::NAN),
        };
    }
    ArrayRow { pads, control_force_n }
}

/// The phase of the last row at or before `time_s`.
fn phase_at(rows: &[TraceRow], time_s: f64) -> Phase {
    rows.iter().rev().find(|r| r.time_s <= time_s).map_or(Phase::Home, |r| r.phase)
}
