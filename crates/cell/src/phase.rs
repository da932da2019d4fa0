//! The phases of the pick-and-place task: what the sequencer is doing, which the cell may react
//! to (a disturbance set off by a phase) and the trace records.

use serde::{Deserialize, Serialize};

/// The phases of the task, in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Phase {
    /// Arm at home above the object, finger retracted; the sensor is tared here.
    Home,
    /// The finger is fed out of its guide.
    Grow,
    /// Guarded close: the twine motor curls the finger until the sensor feels contact.
    Wrap,
    /// Force control to the setpoint for the grasp period.
    Grasp,
    /// The arm lifts the object.
    Lift,
    /// The arm carries the object to the collection site.
    Transfer,
    /// The arm lowers the object at the collection site.
    Lower,
    /// The finger uncurls and lets go.
    Release,
    /// Finished.
    Done,
}

impl Phase {
    /// Lower-case name, as written in traces and summaries.
    pub fn name(self) -> &'static str {
        match self {
            Phase::Home => "home",
            Phase::Grow => "grow",
            Phase::Wrap => "wrap",
            Phase::Grasp => "grasp",
            Phase::Lift => "lift",
            Phase::Transfer => "transfer",
            Phase::Lower => "lower",
            Phase::Release => "release",
            Phase::Done => "done",
        }
    }

    /// Whether the arm is moving the object (the paper's "during the movement").
    pub fn arm_moving(self) -> bool {
        matches!(self, Phase::Lift | Phase::Transfer | Phase::Lower)
    }

    /// Whether the object must be in the hand (from the end of the grasp to the release).
    pub fn holding(self) -> bool {
        matches!(self, Phase::Grasp | Phase::Lift | Phase::Transfer | Phase::Lower)
    }
}

/// Longest any one phase of the task may last \[s\]: an hour. The paper's longest is the 15 s
/// grasp; an hour is what a soak test of the real path holds an object for (the watchdogs must not
/// trip on a stock PC in an hour: docs/cell/timing.md). Longer only fills the disk with trace rows
/// (100 Hz × 3600 s is 360 000 rows, about 55 MB) and keeps a sweep's worker busy for nothing.
pub const MAX_PHASE_S: f64 = 3600.0;
