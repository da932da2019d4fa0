//! `[controller] type = "feedforward"`: the paper's PID on a setpoint scheduled from the arm's
//! planned motion (gain scheduling on the plan, not on the sensor).
//!
//! The task knows when the arm will move and how hard before it happens
//! ([`MoveOutlook`](crate::controller::MoveOutlook)), so the grip can be tightened
//! *ahead* of the lift instead of after the load has already pulled the object:
//!
//! ```text
//! σ(t)   = clamp(1 − τ(t) / lead_s, 0, 1)            τ: time until the arm moves (0 while moving)
//! F*(t)  = F_sp · (1 + σ(t) · (margin + accel_gain · q̈_peak))
//! u(t)   = PID(F*(t) − F(t))                        [°/s], the paper's PID (kp, ki, kd, limits)
//! u(t)   ≥ −max_release_deg_s                       while the arm moves
//! ```
//!
//! `q̈_peak` is the largest planned joint acceleration of the current move, or of the next while
//! the arm is still [rad/s²]. σ ramps linearly from 0 to 1 over the `lead_s` before the lift, stays
//! 1 through lift, transfer and lower, and is 0 during the grasp otherwise. Assumptions: the grip
//! needs more force while the arm accelerates the object, in proportion to the planned
//! acceleration; the schedule is open loop (the sensor closes the loop only through the PID). The
//! PID's integral is not reset when the setpoint moves, so the ramp is followed with the
//! integrating loop's ramp error, which `lead_s` leaves time to settle.

use super::controller::{ControlContext, ForceController};
use super::pid::{Pid, PidConfig};
use serde::{Deserialize, Serialize};
use tendril_config::{Checker, Validate};

/// The feedforward controller's keys (TOML `[controller]` with `type = "feedforward"`): the PID's
/// plus the schedule.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FeedforwardConfig {
    /// Proportional gain [(°/s)/N]. Paper: 20.
    pub kp: f64,
    /// Integral gain [(°/s)/(N·s)]. Paper: 0.05.
    pub ki: f64,
    /// Derivative gain [(°/s)/(N/s)]. Paper: 0.
    pub kd: f64,
    /// Output limit [°/s], as the PID's (90 °/s).
    pub max_speed_deg_s: f64,
    /// Derivative filter time constant \[s\], as the PID's.
    pub derivative_filter_s: f64,
    /// Largest loosening speed while the arm moves [°/s] (the output is kept ≥ −this). A knock
    /// on the object saturates the pad for a few tenths of a second; the PID reads that as a grip
    /// far too tight and loosens at up to 60 °/s, and the object, knocked loose, then slips out
    /// (on the twin the crimper survives a 0.3 N·s knock with the twine frozen, not with the
    /// PID). Default 0: never loosen while the arm carries the object (the grip can only need
    /// more while it moves; at the paper's limits without a knock the three objects' runs came
    /// out the same with the clamp at 0, 2, 5 and 90 °/s, seed 1). The output limit switches the
    /// clamp off. While the arm is still the PID's limit applies. The PID's integral is not told
    /// of the clamp (at ki = 0.05 a 3 N spike for 0.3 s adds 0.05 °/s).
    pub max_release_deg_s: f64,
    /// Fractional setpoint increase while the arm moves [-]. Default 0.05: half the issue's 10 %
    /// fluctuation budget, so the raised grip alone cannot exceed it.
    pub margin: f64,
    /// How long before the arm starts moving the setpoint starts to rise \[s\]. Default 2 s: one
    /// closed-loop time constant of the paper's PID on the twin (≈ 2 s), so the grip has reached most of
    /// the raised setpoint when the lift begins.
    pub lead_s: f64,
    /// Further fractional increase per rad/s² of planned peak joint acceleration [s²/rad]. Default
    /// 0.2: at the paper's 15 °/s² (0.26 rad/s²) it adds 5 %.
    pub accel_gain: f64,
}

impl Default for FeedforwardConfig {
    fn default() -> Self {
        let pid = PidConfig::default();
        FeedforwardConfig {
            kp: pid.kp,
            ki: pid.ki,
            kd: pid.kd,
            max_speed_deg_s: pid.max_speed_deg_s,
            derivative_filter_s: pid.derivative_filter_s,
            max_release_deg_s: 0.0,
            margin: 0.05,
            lead_s: 2.0,
            accel_gain: 0.2,
        }
    }
}

impl FeedforwardConfig {
    /// The PID part.
    pub fn pid(&self) -> PidConfig {
        PidConfig {
            kp: self.kp,
            ki: self.ki,
            kd: self.kd,
            max_speed_deg_s: self.max_speed_deg_s,
            derivative_filter_s: self.derivative_filter_s,
        }
    }
}

impl Validate for FeedforwardConfig {
    fn validate(&self, at: &mut Checker) {
        self.pid().validate(at);
        // 0 never loosens while moving; above the output limit it changes nothing.
        at.in_range("max_release_deg_s", self.max_release_deg_s, 0.0, tendril_cell::gripper::MX106_MAX_SPEED_DEG_S);
        // Doubling the grip while moving (margin 1) is already more than any object here needs and
        // more than the finger's range leaves for the hammer (1.6 N × 2 = 3.2 N of 4.69 N).
        at.in_range("margin", self.margin, 0.0, 1.0);
        // 0 ramps in at the start of the move; 60 s is four grasps.
        at.in_range("lead_s", self.lead_s, 0.0, 60.0);
        // 10 s²/rad adds 100 % at 0.1 rad/s² (5.7 °/s²): beyond it the schedule is all acceleration.
        at.in_range("accel_gain", self.accel_gain, 0.0, 10.0);
    }
}

/// The feedforward controller's state: the PID and its configuration.
#[derive(Debug, Clone)]
pub struct Feedforward {
    config: FeedforwardConfig,
    pid: Pid,
}

impl Feedforward {
    /// A controller at rest.
    pub fn new(config: FeedforwardConfig) -> Self {
        Feedforward { config, pid: Pid::new(config.pid()) }
    }

    /// The scheduled setpoint F* \[N\] for this tick.
    pub fn scheduled_setpoint_n(&self, ctx: &ControlContext) -> f64 {
        let c = &self.config;
        let sigma = ctx.outlook.lead_ramp(c.lead_s);
        ctx.setpoint_n * (1.0 + sigma * (c.margin + c.accel_gain * ctx.outlook.peak_accel_rad_s2))
    }
}

impl ForceController for Feedforward {
    fn update(&mut self, ctx: &ControlContext) -> f64 {
        let setpoint = self.scheduled_setpoint_n(ctx);
        let u = self.pid.update(setpoint, ctx.force_n, ctx.dt_s, ctx.blocked_towards(setpoint));
        ctx.release_limited(u, self.config.max_release_deg_s)
    }

    fn reset(&mut self) {
        self.pid.reset();
    }

    fn max_speed_deg_s(&self) -> f64 {
        self.config.max_speed_deg_s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::controller::{ArmMotion, MoveOutlook};
    use crate::task::Phase;

    fn ctx(tau: f64, accel: f64) -> ControlContext {
        ControlContext {
            setpoint_n: 1.0,
            force_n: 1.0,
            dt_s: 0.01,
            phase: Phase::Grasp,
            blocked: false,
            arm: ArmMotion::default(),
            outlook: MoveOutlook { time_to_motion_s: tau, peak_accel_rad_s2: accel, peak_speed_rad_s: 0.0 },
        }
    }

    #[test]
    fn the_setpoint_ramps_in_over_the_lead_and_stays_up_while_moving() {
        let c = Feedforward::new(FeedforwardConfig { margin: 0.1, lead_s: 2.0, accel_gain: 0.5, ..Default::default() });
        assert_eq!(c.scheduled_setpoint_n(&ctx(5.0, 0.2)), 1.0);
        assert_eq!(c.scheduled_setpoint_n(&ctx(f64::INFINITY, 0.2)), 1.0);
        assert!((c.scheduled_setpoint_n(&ctx(1.0, 0.2)) - 1.1).abs() < 1e-12);
        assert!((c.scheduled_setpoint_n(&ctx(0.0, 0.2)) - 1.2).abs() < 1e-12);
    }

    #[test]
    fn it_does_not_loosen_while_the_arm_moves_unless_allowed() {
        let mut c = Feedforward::new(FeedforwardConfig::default());
        let mut knocked = ctx(0.0, 0.26);
        knocked.force_n = 4.6;
        assert_eq!(c.update(&knocked), 0.0, "moving: held");
        let mut still = ctx(5.0, 0.26);
        still.force_n = 4.6;
        assert!(c.update(&still) < -50.0, "still: the PID loosens");
        let mut free = Feedforward::new(FeedforwardConfig { max_release_deg_s: 90.0, ..Default::default() });
        assert!(free.update(&knocked) < -50.0);
    }

    #[test]
    fn with_no_margin_it_is_the_pid() {
        let config = FeedforwardConfig { margin: 0.0, accel_gain: 0.0, ..Default::default() };
        let mut ff = Feedforward::new(config);
        let mut pid = Pid::new(config.pid());
        for i in 0..100 {
            let mut c = ctx(1.0 - 0.01 * f64::from(i), 0.3);
            c.force_n = 0.01 * f64::from(i);
            assert_eq!(ff.update(&c).to_bits(), pid.update(1.0, c.force_n, 0.01, false).to_bits());
        }
    }
}
