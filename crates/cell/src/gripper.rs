//! The grow-and-twine gripper's drive train: motor angles to finger inputs.
//!
//! Two MX-106 servos drive the finger (docs/facts.md#gripper-drive-two-mx-106-servos): one feeds the strip out of its guide
//! through a spur pinion (growth), one winds the curl tendon on a spool (twine). The control
//! code thinks in finger terms (growth length, tendon pull); the cell speaks motor angles.

use serde::{Deserialize, Serialize};
use tendril_config::{Checker, Validate};

/// Fastest the MX-106 turns a motor [°/s]: 45 rpm no-load at 12 V (ROBOTIS datasheet).
pub const MX106_MAX_SPEED_DEG_S: f64 = 270.0;

/// Drive-train geometry (TOML `[gripper]`). The real gripper's dimensions are unpublished
/// (docs/facts.md#gripper-dimensions-are-unpublished); these are documented choices.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GripperConfig {
    /// Pitch radius of the growth pinion \[m\]. 12 mm: a module-1 spur gear of 24 teeth, a size
    /// that fits the MX-106 horn; 14 cm of growth is then 1.9 motor turns.
    pub growth_pinion_radius_m: f64,
    /// Radius of the twine tendon spool \[m\]. With the finger's stiffness this sets the force gain
    /// dF/dθ that the paper's PID gains act on (see `control::pid`). Tuned: 16 mm, so that, as in the
    /// paper, Kp = 20 (°/s)/N brings the pad to 90 % of the setpoint within 5 s (twin: 1-4.6 s over
    /// seeds 1-5): 0.28 mm of tendon per motor degree; at the start of the grasp the pad force grows
    /// by ≈ 0.06-0.11 N per degree (crimper / shampoo / hammer, measured on the twin), a loop time
    /// constant 1/(Kp·dF/dθ) ≈ 0.5-0.8 s; the finger's creep then slows the last part of the rise.
    /// (5 mm gave 8-12 s.)
    /// A 32 mm drum on the MX-106 horn is an ordinary size; the motor then winds ≤ 25 mm/s at the
    /// PID's 90 °/s limit.
    pub twine_spool_radius_m: f64,
    /// Twine motor travel limit [°] from the straight finger: 211° winds 59 mm on the 16 mm spool,
    /// just inside the finger's tendon travel (`finger.twine_max_m`, 60 mm).
    pub twine_max_deg: f64,
}

impl Default for GripperConfig {
    fn default() -> Self {
        GripperConfig { growth_pinion_radius_m: 0.012, twine_spool_radius_m: 0.016, twine_max_deg: 211.0 }
    }
}

impl Validate for GripperConfig {
    fn validate(&self, at: &mut Checker) {
        at.positive("growth_pinion_radius_m", self.growth_pinion_radius_m);
        at.positive("twine_spool_radius_m", self.twine_spool_radius_m);
        at.positive("twine_max_deg", self.twine_max_deg);
    }
}

impl GripperConfig {
    /// Growth motor angle \[rad\] that feeds out `length_m` of finger.
    pub fn growth_motor_rad(&self, length_m: f64) -> f64 {
        length_m / self.growth_pinion_radius_m
    }

    /// Finger length fed out \[m\] at growth motor angle `rad`.
    pub fn growth_length_m(&self, rad: f64) -> f64 {
        rad * self.growth_pinion_radius_m
    }

    /// Tendon pulled in \[m\] at twine motor angle `rad`.
    pub fn tendon_pull_m(&self, rad: f64) -> f64 {
        rad * self.twine_spool_radius_m
    }
}
