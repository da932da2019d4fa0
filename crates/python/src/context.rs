//! [`ControlContext`]: what a Python force controller is told each tick.

use pyo3::prelude::*;
use tendril_control::controller as rust;

/// What a force controller is told each tick (`update(ctx)`), as the built-in controllers are
/// told it: the setpoint and the force estimate, the tick period, the phase, the travel-limit
/// flag and the arm's planned motion.
#[pyclass(frozen, module = "tendril._native")]
pub struct ControlContext {
    /// Force setpoint \[N\].
    #[pyo3(get)]
    setpoint_n: f64,
    /// Compensated force estimate \[N\] (the sensor's, never the true force).
    #[pyo3(get)]
    force_n: f64,
    /// Tick period \[s\].
    #[pyo3(get)]
    dt_s: f64,
    /// The task phase (`"grasp"`, `"lift"`, `"transfer"`, `"lower"`).
    #[pyo3(get)]
    phase: &'static str,
    /// The tendon is at a travel limit in the direction towards the setpoint: an integrating
    /// controller should not wind up.
    #[pyo3(get)]
    blocked: bool,
    /// The arm's planned joint velocities at this tick [rad/s] (six; zero while it holds still).
    #[pyo3(get)]
    arm_qd_rad_s: [f64; tendril_cell::ARM_JOINTS],
    /// The arm's planned joint accelerations at this tick [rad/s²].
    #[pyo3(get)]
    arm_qdd_rad_s2: [f64; tendril_cell::ARM_JOINTS],
    /// Time until the arm starts moving the object \[s\]: counts down in the grasp, 0 while it
    /// moves, `inf` when no move follows.
    #[pyo3(get)]
    time_to_motion_s: f64,
    /// Largest planned joint acceleration of the current (or next) move [rad/s²].
    #[pyo3(get)]
    peak_accel_rad_s2: f64,
    /// Largest planned joint speed of the current (or next) move [rad/s].
    #[pyo3(get)]
    peak_speed_rad_s: f64,
}

impl From<&rust::ControlContext> for ControlContext {
    fn from(c: &rust::ControlContext) -> Self {
        ControlContext {
            setpoint_n: c.setpoint_n,
            force_n: c.force_n,
            dt_s: c.dt_s,
            phase: c.phase.name(),
            blocked: c.blocked,
            arm_qd_rad_s: c.arm.qd_rad_s,
            arm_qdd_rad_s2: c.arm.qdd_rad_s2,
            time_to_motion_s: c.outlook.time_to_motion_s,
            peak_accel_rad_s2: c.outlook.peak_accel_rad_s2,
            peak_speed_rad_s: c.outlook.peak_speed_rad_s,
        }
    }
}

#[pymethods]
impl ControlContext {
    fn __repr__(&self) -> String {
        format!(
            "ControlContext(phase={:?}, setpoint_n={}, force_n={}, dt_s={}, blocked={}, time_to_motion_s={})",
            self.phase, self.setpoint_n, self.force_n, self.dt_s, self.blocked, self.time_to_motion_s
        )
    }
}
