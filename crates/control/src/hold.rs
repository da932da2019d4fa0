//! Holds of any length (`[task.hold]`): a long grasp lets go of the object while it waits on the
//! table and wraps it again in time for the arm's move, so the twine motor's travel is not used up by the
//! strip's creep.
//!
//! Why: the strip's tendon path creeps as a standard linear solid (models/README.md, "How the
//! grasp works"). Under a held tension T the path stretches towards T / (f K), twenty times its
//! elastic stretch with the calibrated f = 0.05, with the retardation time τ / f = 380 s; a force
//! loop holding the setpoint winds that stretch in, and after about five minutes the motor reaches
//! the end of its travel (docs/cell/timing.md, "The hour on an idle machine").
//!
//! Which recovery the mechanism allows:
//! - **Release and re-wrap** (this module). The creep grows only while the path carries tension,
//!   and is not given back when the tendon goes slack (the twin's dashpot has nothing to pull it
//!   back; a real standard linear solid recovers with the same 380 s), so a release gains no
//!   travel, but it stops the creep from growing: one re-wrap needs the grip's own twine plus the
//!   creep of the grasp before the release. Released early (after 30 s), the hour costs the travel
//!   of a 30 s grasp. The object waits standing on the table, where it stood before the grasp.
//! - **A light grip instead of a release** does not stop the creep: the pad is loaded only once the
//!   wrap is tight, so a quarter of the setpoint on the pad keeps about two thirds of the wrap's
//!   force and of the tendon's tension (measured on the crimper, on the whole-link default with its
//!   360 s: the pad's 0.62 N cut to 0.16 N,
//!   the grip's 3.65 N only to 2.45 N), and the travel still ran out in the hour (at 442 s instead
//!   of 304 s).
//! - **A growth step** cannot tighten the wrap: the tendon runs along the strip, so feeding strip
//!   out only adds straight strip at the base for the tendon to curl (a looser wrap), and pulling
//!   the wrapped strip back into the guide takes up 0.2 mm of tendon per mm (the 3 mm moment arm
//!   over the 13.5 mm wrap radius) while dragging the strip round the object.
//!
//! While the arm carries the object none of this is possible (a release in the air is a drop): the
//! controller's integral stops at the travel's end (the PID's anti-windup, told by the task's
//! `blocked` flag, [`crate::pid`]), and the run reports when the travel ran out.

use serde::{Deserialize, Serialize};
use tendril_cell::MAX_PHASE_S;
use tendril_config::{Checker, Validate};

/// How a long grasp holds (TOML `[task.hold]`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct HoldConfig {
    /// Whether a long grasp lets go of the waiting object and re-wraps it before the move
    /// (default `true`; `false` holds the setpoint all the grasp, as before: the hour's grasp then
    /// drops the object once the travel runs out).
    pub enabled: bool,
    /// A grasp lets go once it has lasted this long \[s\] (and enough of it is left for a re-wrap,
    /// `rewrap_settle_s`). 30 s: twice the paper's 15 s grasp, so the paper's task never lets go, and a twelfth
    /// of the creep's 380 s retardation time, so the re-wrap needs little more travel than the
    /// first wrap.
    pub release_after_s: f64,
    /// ... or once the twine motor has turned this fraction of its travel
    /// (`gripper.twine_max_deg`) during the grasp [-], whatever the time: a creep faster than the
    /// calibrated one. 0.8: the paper's runs turn at most 25 % of it in the grasp and 35 % in the
    /// whole task (the hammer, the heaviest setpoint; seed 1), and the fifth left covers the
    /// re-wrap's creep and the carry.
    pub release_at_travel: f64,
    /// Time the re-wrap leaves the controller to rise to the setpoint before the arm moves \[s\]:
    /// the re-wrap starts this long plus its guarded close before the move. The close winds at
    /// `task.wrap_speed_deg_s` to first contact, which comes near the twine the grasp let go at (the
    /// creep is not given back), so it is timed as that twine over the close's speed (4 s after an
    /// hour's grasp on the crimper, 10 s when the strip creeps six times faster, on the whole-link
    /// default). 5 s: the paper's
    /// 90 % of the setpoint within 5 s.
    pub rewrap_settle_s: f64,
}

impl Default for HoldConfig {
    fn default() -> Self {
        HoldConfig { enabled: true, release_after_s: 30.0, release_at_travel: 0.8, rewrap_settle_s: 5.0 }
    }
}

impl Validate for HoldConfig {
    fn validate(&self, at: &mut Checker) {
        at.in_range("release_after_s", self.release_after_s, 0.0, MAX_PHASE_S);
        // Up to the whole travel: a value of 1 lets go only at the travel's end.
        at.in_range("release_at_travel", self.release_at_travel, 1e-3, 1.0);
        at.in_range("rewrap_settle_s", self.rewrap_settle_s, 0.0, MAX_PHASE_S);
    }
}

impl HoldConfig {
    /// Whether a grasp holding the object lets go this tick: `elapsed_s` into it, `remaining_s`
    /// left, the twine motor at `travel_used` of its travel, a re-wrap's close from there taking
    /// `close_s`. Not when the re-wrap would have to start at once.
    pub fn release(&self, elapsed_s: f64, remaining_s: f64, travel_used: f64, close_s: f64) -> bool {
        self.enabled
            && !self.rewrap(remaining_s, close_s)
            && (elapsed_s >= self.release_after_s || travel_used >= self.release_at_travel)
    }

    /// Whether a released grasp starts its re-wrap, `remaining_s` before the arm moves, its close
    /// taking `close_s`.
    pub fn rewrap(&self, remaining_s: f64, close_s: f64) -> bool {
        remaining_s <= close_s + self.rewrap_settle_s
    }
}

/// Where a grasp stands with its object (`task.hold`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Grip {
    /// The controller holds the setpoint.
    #[default]
    Holding,
    /// Let go: the twine unwinds to the straight finger, the controller off.
    Released,
    /// The guarded close of a re-wrap, until first contact; then [`Grip::Holding`].
    Rewrapping,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_long_grasp_lets_go_after_its_time_or_at_the_travel_and_rewraps_before_the_move() {
        let h = HoldConfig::default();
        // The paper's 15 s grasp never lets go: before 30 s and at 25 % of the travel.
        assert!(!(0..1500).any(|i| h.release(i as f64 * 0.01, 15.0 - i as f64 * 0.01, 0.25, 4.0)));
        // An hour: let go at 30 s, re-wrapped a 4 s close and 5 s before its end.
        assert!(!h.release(29.9, 3570.1, 0.5, 4.0));
        assert!(h.release(30.0, 3570.0, 0.5, 4.0));
        assert!(!h.rewrap(9.1, 4.0) && h.rewrap(9.0, 4.0));
        // Not when the re-wrap would have to start at once, however long the grasp.
        assert!(!h.release(3591.0, 9.0, 0.5, 4.0));
        // A creep fast enough to reach 80 % of the travel lets go at once.
        assert!(h.release(12.0, 100.0, 0.8, 10.0));
        assert!(!HoldConfig { enabled: false, ..h }.release(100.0, 3500.0, 0.9, 4.0));
    }

    #[test]
    fn out_of_range_values_are_refused_by_key() {
        for (c, key) in [
            (HoldConfig { release_at_travel: 0.0, ..HoldConfig::default() }, "hold.release_at_travel"),
            (HoldConfig { release_at_travel: 1.5, ..HoldConfig::default() }, "hold.release_at_travel"),
            (HoldConfig { release_after_s: f64::INFINITY, ..HoldConfig::default() }, "hold.release_after_s"),
            (HoldConfig { rewrap_settle_s: -1.0, ..HoldConfig::default() }, "hold.rewrap_settle_s"),
        ] {
            let mut at = Checker::default();
            at.section("hold", &c);
            assert_eq!(at.into_first_error().map(|e| e.0).as_deref(), Some(key));
        }
    }
}
