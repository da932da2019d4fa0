//! [`LimitedCell`]: a decorator that enforces our own safety limits on any [`Cell`]'s commands
//! (arci-style: the wrapped cell does not know it is wrapped).
//!
//! - Joint speed and acceleration: each arm target may move at most `max_speed·dt` from the last
//!   one, and its step may change by at most `max_accel·dt²`, `dt` being the cell time between the
//!   last two reads. The task planner already respects its own limits (paper: 45 °/s, 15 °/s²);
//!   these are the backstop against a bad plan or a bug, so a planned trajectory passes unchanged.
//! - Force ceiling: when the force estimated from the latest wavelengths (eq. 8, tared on the
//!   first sample after activation: the finger is retracted then) exceeds the ceiling, the twine
//!   motor may not wind further than its measured position (stop tightening; releasing is allowed).

use crate::control::estimate::{ForceCalibration, ForceEstimator};
use crate::hardware::{ARM_JOINTS, Cell, CellCommand, CellError, CellState, GroundTruth, Lifecycle};

/// The limits a [`LimitedCell`] enforces.
#[derive(Debug, Clone, PartialEq)]
pub struct SafetyLimits {
    /// Largest joint speed [rad/s].
    pub max_speed_rad_s: f64,
    /// Largest joint acceleration [rad/s²].
    pub max_accel_rad_s2: f64,
    /// Force ceiling [N]; below the sensor's range so the reading is still meaningful.
    pub max_force_n: f64,
    /// Calibration for the ceiling's force estimate.
    pub calibration: ForceCalibration,
}

impl SafetyLimits {
    /// Limits 20 % above the task's own (so a planned move is never clipped) and a ceiling at 90 %
    /// of the sensor's range (4.22 N for the paper's 4.69 N).
    pub fn for_task(limits: &crate::control::trajectory::JointLimits, calibration: &ForceCalibration) -> SafetyLimits {
        SafetyLimits {
            max_speed_rad_s: 1.2 * limits.max_speed_deg_s.to_radians(),
            max_accel_rad_s2: 1.2 * limits.max_accel_deg_s2.to_radians(),
            max_force_n: 0.9 * calibration.range_n,
            calibration: calibration.clone(),
        }
    }
}

/// A cell whose commands are limited (see the module docs).
pub struct LimitedCell<C: Cell> {
    inner: C,
    limits: SafetyLimits,
    estimator: ForceEstimator,
    tared: bool,
    last_state: Option<CellState>,
    dt_s: f64,
    last_target: Option<[f64; ARM_JOINTS]>,
    last_step: [f64; ARM_JOINTS],
    over_force: bool,
    /// Commands changed by the limits so far (speed/acceleration, force).
    pub interventions: (u64, u64),
}

impl<C: Cell> LimitedCell<C> {
    /// Wraps `inner`.
    pub fn new(inner: C, limits: SafetyLimits) -> LimitedCell<C> {
        let estimator = ForceEstimator::new(limits.calibration.clone());
        LimitedCell {
            inner,
            limits,
            estimator,
            tared: false,
            last_state: None,
            dt_s: 0.0,
            last_target: None,
            last_step: [0.0; ARM_JOINTS],
            over_force: false,
            interventions: (0, 0),
        }
    }

    /// The wrapped cell.
    pub fn inner(&self) -> &C {
        &self.inner
    }

    /// Limits `target` against the previous target: speed, then acceleration.
    fn limit_arm(&mut self, target: [f64; ARM_JOINTS], measured: [f64; ARM_JOINTS]) -> [f64; ARM_JOINTS] {
        let previous = self.last_target.unwrap_or(measured);
        if self.dt_s <= 0.0 {
            // No interval yet: hold the measured pose for this first tick.
            self.last_target = Some(previous);
            return previous;
        }
        let max_step = self.limits.max_speed_rad_s * self.dt_s;
        let max_change = self.limits.max_accel_rad_s2 * self.dt_s * self.dt_s;
        let mut out = previous;
        let mut clipped = false;
        for j in 0..ARM_JOINTS {
            let wanted = target[j] - previous[j];
            let step =
                wanted.clamp(self.last_step[j] - max_change, self.last_step[j] + max_change).clamp(-max_step, max_step);
            clipped |= (step - wanted).abs() > 1e-12;
            out[j] = previous[j] + step;
            self.last_step[j] = step;
        }
        if clipped {
            self.interventions.0 += 1;
        }
        self.last_target = Some(out);
        out
    }
}

impl<C: Cell> Cell for LimitedCell<C> {
    fn backend(&self) -> &str {
        self.inner.backend()
    }
    fn lifecycle(&self) -> Lifecycle {
        self.inner.lifecycle()
    }
    fn configure(&mut self) -> Result<(), CellError> {
        self.inner.configure()
    }
    fn activate(&mut self) -> Result<(), CellError> {
        self.tared = false;
        self.last_state = None;
        self.last_target = None;
        self.last_step = [0.0; ARM_JOINTS];
        self.inner.activate()
    }
    fn deactivate(&mut self) -> Result<(), CellError> {
        self.inner.deactivate()
    }
    fn read(&mut self) -> Result<CellState, CellError> {
        let s = self.inner.read()?;
        if !self.tared {
            self.estimator.tare(s.wavelengths);
            self.tared = true;
        }
        self.over_force = self.estimator.estimate(s.wavelengths).is_ok_and(|e| e.force_n > self.limits.max_force_n);
        self.dt_s = self.last_state.map_or(0.0, |p| s.time_s - p.time_s);
        self.last_state = Some(s);
        Ok(s)
    }
    fn write(&mut self, command: &CellCommand) -> Result<(), CellError> {
        let measured = self.last_state.map(|s| s.arm_q).unwrap_or(command.arm_q);
        let mut c = *command;
        c.arm_q = self.limit_arm(command.arm_q, measured);
        if self.over_force
            && let Some(s) = self.last_state
            && c.twine_motor_rad > s.twine_motor_rad
        {
            c.twine_motor_rad = s.twine_motor_rad;
            self.interventions.1 += 1;
        }
        self.inner.write(&c)
    }
    fn wait_until(&mut self, time_s: f64) -> Result<(), CellError> {
        self.inner.wait_until(time_s)
    }
    fn ground_truth(&self) -> Option<GroundTruth> {
        self.inner.ground_truth()
    }
}
