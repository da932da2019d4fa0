//! PID force controller with output limits and anti-windup.
//!
//! Output units: the controller drives the twine motor's *speed*. Its output `u` is a twine
//! motor velocity in degrees per second, integrated by the caller into the position target
//! written each tick. With the error `e` in newtons, `kp` is in (°/s)/N, `ki` in (°/s)/(N·s) and
//! `kd` in (°/s)/(N/s). An integrating actuator makes the paper's gains (Kp = 20, Ki = 0.05,
//! Kd = 0) give a first-order rise whose time constant is 1/(Kp·dF/dθ), where dF/dθ is the
//! finger's force gain in N per degree of twine motor: that is the plant scaling the twin
//! calibrates so that 90 % of the setpoint is reached within 5 s, as in the paper.

use super::controller::{ControlContext, ForceController};
use serde::{Deserialize, Serialize};
use tendril_config::{Checker, Validate};

/// PID gains and limits (TOML `[controller]`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PidConfig {
    /// Proportional gain [(°/s)/N]. Paper: 20.
    pub kp: f64,
    /// Integral gain [(°/s)/(N·s)]. Paper: 0.05.
    pub ki: f64,
    /// Derivative gain [(°/s)/(N/s)]. Paper: 0.
    pub kd: f64,
    /// Output limit [°/s], symmetric. 90 °/s is a third of the MX-106's no-load speed at 12 V
    /// (45 rpm = 270 °/s, ROBOTIS datasheet), leaving torque margin while twining.
    pub max_speed_deg_s: f64,
    /// Time constant of the first-order filter on the derivative term \[s\] (only used when kd ≠ 0).
    pub derivative_filter_s: f64,
}

impl Default for PidConfig {
    fn default() -> Self {
        PidConfig { kp: 20.0, ki: 0.05, kd: 0.0, max_speed_deg_s: 90.0, derivative_filter_s: 0.05 }
    }
}

/// Largest PID gain accepted, in the gains' own units (see [`PidConfig`]); why in `validate`.
pub const MAX_GAIN: f64 = 1e4;

impl Validate for PidConfig {
    fn validate(&self, at: &mut Checker) {
        // At kp = 1e4 (°/s)/N the sensor's noise-limited resolution (2.57 mN, paper Sec. IV-B)
        // alone commands 26 °/s: beyond it the loop only amplifies noise into the output limit.
        // The same bound holds for ki and kd (the swept gains reach 80 and 5).
        for (name, gain) in [("kp", self.kp), ("ki", self.ki), ("kd", self.kd)] {
            at.in_range(name, gain, 0.0, MAX_GAIN);
        }
        at.in_range("max_speed_deg_s", self.max_speed_deg_s, 1e-3, tendril_cell::gripper::MX106_MAX_SPEED_DEG_S);
        // 60 s: slower than the whole closed loop (time constant ≈ 2 s), so no filter at all.
        at.in_range("derivative_filter_s", self.derivative_filter_s, 1e-6, 60.0);
    }
}

/// A PID controller's state.
#[derive(Debug, Clone)]
pub struct Pid {
    config: PidConfig,
    integral: f64,
    derivative: f64,
    previous_measurement: Option<f64>,
}

impl Pid {
    /// A controller at rest.
    pub fn new(config: PidConfig) -> Pid {
        Pid { config, integral: 0.0, derivative: 0.0, previous_measurement: None }
    }

    /// The gains and limits in use.
    pub fn config(&self) -> &PidConfig {
        &self.config
    }

    /// The integral of the error so far \[N·s\] (what anti-windup keeps from growing).
    pub fn integral(&self) -> f64 {
        self.integral
    }

    /// Clears the integral and derivative memory (used when the controller is switched on).
    pub fn reset(&mut self) {
        self.integral = 0.0;
        self.derivative = 0.0;
        self.previous_measurement = None;
    }

    /// One update: returns the output in [−max, max] °/s.
    ///
    /// `blocked` tells the controller that the actuator cannot move further in the direction
    /// of the output (for example the twine motor at its travel limit): the integral is then
    /// frozen, like when the output itself saturates (conditional-integration anti-windup).
    /// The derivative acts on the measurement, not the error, so setpoint steps give no kick.
    pub fn update(&mut self, setpoint: f64, measurement: f64, dt_s: f64, blocked: bool) -> f64 {
        let c = &self.config;
        let error = setpoint - measurement;
        if let Some(prev) = self.previous_measurement
            && dt_s > 0.0
        {
            let raw = -(measurement - prev) / dt_s;
            let alpha = dt_s / (c.derivative_filter_s + dt_s);
            self.derivative += alpha * (raw - self.derivative);
        }
        self.previous_measurement = Some(measurement);

        let unclamped = c.kp * error + c.ki * (self.integral + error * dt_s) + c.kd * self.derivative;
        let output = unclamped.clamp(-c.max_speed_deg_s, c.max_speed_deg_s);
        let saturated = output != unclamped;
        let pushing_further = (saturated || blocked) && error.signum() == unclamped.signum();
        if !pushing_further {
            self.integral += error * dt_s;
        }
        output
    }
}

impl ForceController for Pid {
    fn update(&mut self, ctx: &ControlContext) -> f64 {
        Pid::update(self, ctx.setpoint_n, ctx.force_n, ctx.dt_s, ctx.blocked)
    }

    fn reset(&mut self) {
        Pid::reset(self);
    }

    fn max_speed_deg_s(&self) -> f64 {
        self.config().max_speed_deg_s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pid(kp: f64, ki: f64, kd: f64) -> Pid {
        Pid::new(PidConfig { kp, ki, kd, ..PidConfig::default() })
    }

    #[test]
    fn proportional_output_is_gain_times_error() {
        let mut c = pid(20.0, 0.0, 0.0);
        assert_eq!(c.update(1.0, 0.5, 0.01, false), 10.0);
    }

    #[test]
    fn output_is_clamped_to_the_speed_limit() {
        let mut c = pid(1000.0, 0.0, 0.0);
        assert_eq!(c.update(1.0, 0.0, 0.01, false), 90.0);
        assert_eq!(c.update(0.0, 1.0, 0.01, false), -90.0);
    }

    #[test]
    fn integral_accumulates_error_over_time() {
        let mut c = pid(0.0, 2.0, 0.0);
        let mut u = 0.0;
        for _ in 0..100 {
            u = c.update(1.0, 0.0, 0.01, false);
        }
        assert!((u - 2.0).abs() < 1e-9, "{u}");
    }

    #[test]
    fn integral_does_not_wind_up_while_saturated_or_blocked() {
        let mut c = pid(1000.0, 10.0, 0.0);
        for _ in 0..1000 {
            c.update(1.0, 0.0, 0.01, false);
        }
        // Once the error reverses, the output leaves saturation at once.
        assert!(c.update(0.0, 0.01, 0.01, false) < 0.0);

        let mut blocked = pid(0.0, 10.0, 0.0);
        for _ in 0..1000 {
            blocked.update(1.0, 0.0, 0.01, true);
        }
        assert!(blocked.update(1.0, 0.0, 0.01, false) <= 10.0 * 0.01 + 1e-12);
    }

    #[test]
    fn derivative_opposes_a_rising_measurement_without_setpoint_kick() {
        let mut c = pid(0.0, 0.0, 1.0);
        assert_eq!(c.update(5.0, 0.0, 0.01, false), 0.0, "no kick on the first sample");
        assert!(c.update(5.0, 0.1, 0.01, false) < 0.0);
        let mut d = pid(0.0, 0.0, 1.0);
        d.update(0.0, 0.0, 0.01, false);
        assert_eq!(d.update(5.0, 0.0, 0.01, false), 0.0, "setpoint step alone gives nothing");
    }
}
