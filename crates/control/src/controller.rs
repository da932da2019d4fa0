//! The force-controller seam, in the manner of ros2_control's controller interface: the task
//! sequencer owns a [`ForceController`] and, each tick the controller is on, hands it a
//! [`ControlContext`] (setpoint, force estimate, tick period, phase, travel-limit flag and the
//! arm's planned motion) and takes back a twine motor speed [°/s].
//!
//! The scenario section `[controller]` is a [`crate::ControllerConfig`]: `type = "pid"` (the default
//! when `type` is left out, so every scenario written before the seam reads unchanged) plus that
//! type's keys. Adding a controller is one file implementing [`ForceController`] plus one
//! [`crate::ControllerConfig`] variant (its name in [`crate::ControllerConfig::TYPES`], its arm in
//! `deserialize`, `validate` and [`crate::ControllerConfig::build`]).

use tendril_cell::{ARM_JOINTS, Phase};

/// What the task knows of the arm's planned motion at this tick (zero while the arm holds still).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ArmMotion {
    /// Planned joint velocities [rad/s].
    pub qd_rad_s: [f64; ARM_JOINTS],
    /// Planned joint accelerations [rad/s²].
    pub qdd_rad_s2: [f64; ARM_JOINTS],
}

/// What the task knows of the arm's moves ahead: the object-carrying moves (lift, transfer,
/// lower) are planned from poses and limits known before the task starts, so a controller can act
/// before the arm moves.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MoveOutlook {
    /// Time until the arm starts moving the object \[s\]: counts down during the grasp, 0 while
    /// the arm moves, +∞ when no move follows.
    pub time_to_motion_s: f64,
    /// Largest planned joint acceleration (over the joints and the move) of the current move, or
    /// of the next while the arm is still [rad/s²]; 0 when no move follows.
    pub peak_accel_rad_s2: f64,
    /// Largest planned joint speed of the same move [rad/s]; 0 when no move follows.
    pub peak_speed_rad_s: f64,
}

impl Default for MoveOutlook {
    /// No move ahead.
    fn default() -> Self {
        MoveOutlook { time_to_motion_s: f64::INFINITY, peak_accel_rad_s2: 0.0, peak_speed_rad_s: 0.0 }
    }
}

impl MoveOutlook {
    /// A schedule σ in [0, 1] that ramps linearly from 0 to 1 over the `lead_s` seconds before the
    /// arm moves and stays 1 while it moves (0 with no move ahead, or no lead before it starts).
    pub fn lead_ramp(&self, lead_s: f64) -> f64 {
        let tau = self.time_to_motion_s;
        if tau <= 0.0 {
            1.0
        } else if lead_s <= 0.0 || !tau.is_finite() {
            0.0
        } else {
            (1.0 - tau / lead_s).clamp(0.0, 1.0)
        }
    }

    /// Whether the arm is moving the object now.
    pub fn moving(&self) -> bool {
        self.time_to_motion_s <= 0.0
    }
}

impl ControlContext {
    /// The travel-limit flag for a controller that tracks `target_n` instead of the nominal
    /// setpoint: the task computed it for the direction towards the setpoint, so it holds only
    /// when the target lies on the same side of the estimate.
    pub fn blocked_towards(&self, target_n: f64) -> bool {
        self.blocked && ((target_n > self.force_n) == (self.setpoint_n > self.force_n))
    }

    /// `speed_deg_s` with loosening limited to `max_release_deg_s` while the arm moves (the
    /// scheduled controllers' clamp: a knock that saturates the sensor must not make them let go).
    pub fn release_limited(&self, speed_deg_s: f64, max_release_deg_s: f64) -> f64 {
        if self.outlook.moving() { speed_deg_s.max(-max_release_deg_s) } else { speed_deg_s }
    }
}

/// Everything a force controller is told each tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControlContext {
    /// Force setpoint \[N\].
    pub setpoint_n: f64,
    /// Compensated force estimate \[N\] (the sensor's, never the true force).
    pub force_n: f64,
    /// Tick period \[s\].
    pub dt_s: f64,
    /// The task phase this tick belongs to.
    pub phase: Phase,
    /// The tendon is at a travel limit in the direction the controller pushes (towards the
    /// setpoint): an integrating controller should not wind up.
    pub blocked: bool,
    /// The arm's planned joint velocities and accelerations at this tick.
    pub arm: ArmMotion,
    /// The arm's moves ahead (or the current one).
    pub outlook: MoveOutlook,
}

/// A force controller: force estimate in, twine motor speed out.
///
/// `Send` so a run (and its sequencer) can move to a worker thread; `Debug` so the sequencer
/// can print itself.
pub trait ForceController: Send + std::fmt::Debug {
    /// One tick: the twine motor speed [°/s], within ±[`ForceController::max_speed_deg_s`].
    fn update(&mut self, ctx: &ControlContext) -> f64;

    /// Forgets all memory (integral, filters): called when force control starts (the grasp)
    /// and, without feedback while moving, when the arm starts to move.
    fn reset(&mut self);

    /// The largest speed the controller commands [°/s]; the release uncurls at this speed.
    fn max_speed_deg_s(&self) -> f64;
}
