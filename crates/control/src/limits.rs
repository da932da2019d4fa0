//! [`LimitedCell`]: a decorator that enforces our own safety limits on any [`Cell`]'s commands
//! (arci-style: the wrapped cell does not know it is wrapped).
//!
//! - Joint speed and acceleration: the speed from the last arm target to the next (its step over
//!   `dt`, the cell time between the last two reads) may be at most `max_speed` and may change by
//!   at most `max_accel·dt` from the speed before. Speeds, not steps, are compared: on a real cell
//!   the ticks jitter, and a planned step over a tick 3 ms late is a third longer than the one
//!   before at the same speed (comparing steps clipped it as an acceleration of a third of the speed
//!   within a tick). The task planner already respects its own limits (paper: 45 °/s, 15 °/s²);
//!   these are the backstop against a bad plan or a bug, so a planned trajectory passes unchanged.
//! - Force ceiling: when the force estimated from the latest wavelengths (eq. 8, tared on the
//!   first sample after activation: the finger is retracted then) exceeds the ceiling, the twine
//!   motor may not wind further than its measured position (stop tightening; releasing is allowed).
//! - Twine travel: the twine motor is never sent past the end of its travel (or below the straight
//!   finger). The task keeps its commands inside it and stops the controller's integral there
//!   ([`crate::task`]); this is the backstop for a caller that does not.

use crate::task::Phase;
use tendril_cell::{ARM_JOINTS, Cell, CellCommand, CellError, CellState, DeviceTiming, GroundTruth, Lifecycle};
use tendril_fbg::estimate::{ForceCalibration, ForceEstimator};

/// The limits a [`LimitedCell`] enforces.
#[derive(Debug, Clone, PartialEq)]
pub struct SafetyLimits {
    /// Largest joint speed [rad/s].
    pub max_speed_rad_s: f64,
    /// Largest joint acceleration [rad/s²].
    pub max_accel_rad_s2: f64,
    /// Force ceiling \[N\]; below the sensor's range so the reading is still meaningful.
    pub max_force_n: f64,
    /// Calibration for the ceiling's force estimate.
    pub calibration: ForceCalibration,
    /// The twine motor's travel \[rad\] from the straight finger (`gripper.twine_max_deg`).
    pub twine_max_rad: f64,
}

impl SafetyLimits {
    /// Limits 20 % above the task's own (so a planned move is never clipped), a ceiling at 90 %
    /// of the sensor's range (4.22 N for the paper's 4.69 N) and the gripper's twine travel.
    pub fn for_task(
        limits: &crate::trajectory::JointLimits,
        calibration: &ForceCalibration,
        gripper: &tendril_cell::gripper::GripperConfig,
    ) -> SafetyLimits {
        SafetyLimits {
            max_speed_rad_s: 1.2 * limits.max_speed_deg_s.to_radians(),
            max_accel_rad_s2: 1.2 * limits.max_accel_deg_s2.to_radians(),
            max_force_n: 0.9 * calibration.range_n,
            calibration: calibration.clone(),
            twine_max_rad: gripper.twine_max_deg.to_radians(),
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
    /// The speed of the last target's step \[rad/s\].
    last_speed: [f64; ARM_JOINTS],
    over_force: bool,
    /// Commands changed by the limits so far (speed/acceleration, force).
    pub interventions: (u64, u64),
    /// Twine commands held to the motor's travel so far.
    pub travel_interventions: u64,
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
            last_speed: [0.0; ARM_JOINTS],
            over_force: false,
            interventions: (0, 0),
            travel_interventions: 0,
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
        let dt = self.dt_s;
        let (max_speed, max_change) = (self.limits.max_speed_rad_s, self.limits.max_accel_rad_s2 * dt);
        let mut out = previous;
        let mut clipped = false;
        for j in 0..ARM_JOINTS {
            let wanted = (target[j] - previous[j]) / dt;
            let last = self.last_speed[j];
            let speed = wanted.clamp(last - max_change, last + max_change).clamp(-max_speed, max_speed);
            clipped |= ((speed - wanted) * dt).abs() > 1e-12;
            out[j] = previous[j] + speed * dt;
            self.last_speed[j] = speed;
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
        self.last_speed = [0.0; ARM_JOINTS];
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
        let within = c.twine_motor_rad.clamp(0.0, self.limits.twine_max_rad);
        if within != c.twine_motor_rad {
            c.twine_motor_rad = within;
            self.travel_interventions += 1;
        }
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
    fn phase_started(&mut self, phase: Phase, time_s: f64) {
        self.inner.phase_started(phase, time_s);
    }
    fn sample_is_new(&self) -> bool {
        self.inner.sample_is_new()
    }
    fn device_timing(&self) -> Option<DeviceTiming> {
        self.inner.device_timing()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tendril_fbg::signals::Wavelengths;

    /// A cell that records commands; time advances by `periods` in turn (10 ms each by default)
    /// per read; wavelengths are settable.
    struct Recorder {
        t: f64,
        periods: Vec<f64>,
        reads: usize,
        w: Wavelengths,
        twine: f64,
        written: Vec<CellCommand>,
    }

    impl Cell for Recorder {
        fn backend(&self) -> &str {
            "recorder"
        }
        fn lifecycle(&self) -> Lifecycle {
            Lifecycle::Active
        }
        fn configure(&mut self) -> Result<(), CellError> {
            Ok(())
        }
        fn activate(&mut self) -> Result<(), CellError> {
            Ok(())
        }
        fn deactivate(&mut self) -> Result<(), CellError> {
            Ok(())
        }
        fn read(&mut self) -> Result<CellState, CellError> {
            self.t += self.periods[self.reads % self.periods.len()];
            self.reads += 1;
            let q = self.written.last().map_or([0.0; ARM_JOINTS], |c| c.arm_q);
            Ok(CellState {
                time_s: self.t,
                arm_q: q,
                growth_motor_rad: 0.0,
                twine_motor_rad: self.twine,
                wavelengths: self.w,
                array: Default::default(),
                tool_load_n: None,
            })
        }
        fn write(&mut self, c: &CellCommand) -> Result<(), CellError> {
            self.written.push(*c);
            Ok(())
        }
        fn wait_until(&mut self, _: f64) -> Result<(), CellError> {
            Ok(())
        }
    }

    fn limited() -> LimitedCell<Recorder> {
        let w = Wavelengths { fbg1_nm: 1540.0, fbg2_nm: 1550.0 };
        let limits = SafetyLimits {
            max_speed_rad_s: 1.0,
            max_accel_rad_s2: 10.0,
            max_force_n: 2.0,
            calibration: ForceCalibration::default(),
            twine_max_rad: 3.0,
        };
        LimitedCell::new(Recorder { t: 0.0, periods: vec![0.01], reads: 0, w, twine: 1.0, written: Vec::new() }, limits)
    }

    fn command(q0: f64, twine: f64) -> CellCommand {
        let mut arm_q = [0.0; ARM_JOINTS];
        arm_q[0] = q0;
        CellCommand { arm_q, growth_motor_rad: 0.0, twine_motor_rad: twine }
    }

    #[test]
    fn a_jump_in_the_arm_target_is_ramped_within_speed_and_acceleration() {
        let mut c = limited();
        c.activate().unwrap();
        for _ in 0..200 {
            c.read().unwrap();
            c.write(&command(1.0, 1.0)).unwrap();
        }
        let q: Vec<f64> = c.inner().written.iter().map(|w| w.arm_q[0]).collect();
        let dt = 0.01;
        for pair in q.windows(2) {
            assert!((pair[1] - pair[0]).abs() <= 1.0 * dt + 1e-12, "speed limit broken: {pair:?}");
        }
        for triple in q.windows(3) {
            let change = (triple[2] - triple[1]) - (triple[1] - triple[0]);
            assert!(change.abs() <= 10.0 * dt * dt + 1e-12, "acceleration limit broken: {triple:?}");
        }
        assert!((q.last().unwrap() - 1.0).abs() < 1e-9, "the target is reached in the end: {}", q.last().unwrap());
        assert!(c.interventions.0 > 0);
    }

    #[test]
    fn a_planned_move_read_on_jittered_ticks_passes_unchanged() {
        // Ticks 3 ms late then 3 ms early, targets on a move accelerating at 0.5 rad/s² to 0.5 rad/s
        // (within the limits): each step is the plan's over its own interval, so nothing may be
        // clipped (comparing steps instead of speeds clipped most of them).
        let mut c = limited();
        c.inner.periods = vec![0.01, 0.013, 0.007];
        c.activate().unwrap();
        for _ in 0..100 {
            let t = c.read().unwrap().time_s;
            c.write(&command(0.25 * t * t, 1.0)).unwrap();
        }
        assert_eq!(c.interventions.0, 0, "a planned move was clipped");
    }

    #[test]
    fn above_the_force_ceiling_the_twine_may_loosen_but_not_tighten() {
        let mut c = limited();
        c.activate().unwrap();
        c.read().unwrap(); // tare at 1540 / 1550 nm
        c.write(&command(0.0, 1.5)).unwrap();
        assert_eq!(c.inner().written.last().unwrap().twine_motor_rad, 1.5, "below the ceiling: unchanged");
        // About 3 N on eq. (8): 144.99·9 + 527.62·3 − 91.42 ≈ 2796 pm on FBG1 alone.
        c.inner.w.fbg1_nm += 2.796;
        c.read().unwrap();
        c.write(&command(0.0, 1.5)).unwrap();
        assert_eq!(c.inner().written.last().unwrap().twine_motor_rad, 1.0, "held at the measured twine");
        c.write(&command(0.0, 0.5)).unwrap();
        assert_eq!(c.inner().written.last().unwrap().twine_motor_rad, 0.5, "loosening is allowed");
        assert_eq!(c.interventions.1, 1);
    }

    #[test]
    fn the_twine_is_never_sent_past_its_travel() {
        let mut c = limited();
        c.activate().unwrap();
        c.read().unwrap();
        for (asked, sent) in [(2.5, 2.5), (3.5, 3.0), (-0.2, 0.0)] {
            c.write(&command(0.0, asked)).unwrap();
            assert_eq!(c.inner().written.last().unwrap().twine_motor_rad, sent, "asked {asked} rad");
        }
        assert_eq!(c.travel_interventions, 2);
    }
}
