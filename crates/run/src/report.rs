//! What a run leaves: its [`Outcome`], the loss if any, the events and metrics, every tick.

use super::metrics::ControlMetrics;
use super::trace::TraceRow;
use serde::Serialize;
use tendril_cell::Phase;
use tendril_control::slip::{Alarms, Judgement, SlipEvents};
use tendril_control::task::{GraspOutcome, HoldRecord};

/// How a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Outcome {
    /// The object stayed in the hand until the release.
    Held,
    /// The object was lost before the release.
    Dropped,
    /// The run stopped on an error (physics divergence, device fault).
    Error,
    /// The grasp did not settle within `task.settled_grasp.timeout_s`: the finger let go and the
    /// arm never lifted (a safe failure of the cycle).
    NotGrasped,
}

impl Outcome {
    /// The outcome as `summary.json` and `results.csv` write it.
    pub fn name(self) -> &'static str {
        match self {
            Outcome::Held => "held",
            Outcome::Dropped => "dropped",
            Outcome::Error => "error",
            Outcome::NotGrasped => "not_grasped",
        }
    }
}

/// When and where the object was lost.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Drop {
    /// Cell time of the loss \[s\].
    pub cell_time_s: f64,
    /// Phase in which it happened.
    pub phase: Phase,
}

/// The result of a run: outcome, events and metrics; the rows are kept for plotting.
#[derive(Debug, Clone)]
pub struct RunReport {
    /// Held, dropped or error.
    pub outcome: Outcome,
    /// The loss, if any (from ground truth when the cell has it, else from the sensor).
    pub drop: Option<Drop>,
    /// Cell time when the arm started moving the object \[s\].
    pub motion_start_s: Option<f64>,
    /// What the sensor-based slip detector saw.
    pub slip: SlipEvents,
    /// The detector's alarm episodes.
    pub alarms: Alarms,
    /// The drop alarms judged against the true drop (`None` on a cell without ground truth).
    pub detection: Option<Judgement>,
    /// Rise time, overshoot, fluctuation, estimate error.
    pub metrics: ControlMetrics,
    /// Cell time reached \[s\].
    pub cell_time_s: f64,
    /// The error that ended the run, with its time.
    pub error: Option<String>,
    /// Sensor samples skipped because they gave no estimate (the last valid one was held).
    pub invalid_samples: u64,
    /// Control ticks without a new interrogator sample ([`tendril_cell::Cell::sample_is_new`]): the last
    /// estimate was held. They do not count as invalid samples.
    pub dropped_samples: u64,
    /// Every tick, as written to the trace.
    pub rows: Vec<TraceRow>,
    /// How the device streams kept up (a real cell).
    pub device_timing: Option<tendril_cell::DeviceTiming>,
    /// A sensor array's figures and slip cue (`None` with the paper's single pad).
    pub array: Option<super::array_summary::ArraySummary>,
    /// How the grasp ended and how long it lasted (`None` if the run never got past it).
    pub grasp: Option<GraspOutcome>,
    /// What the long hold did (`task.hold`) and how far the twine went.
    pub hold: HoldRecord,
    /// A produce item's damage and stem at the end of the run (`None` for a rigid object, or
    /// without ground truth).
    pub produce: Option<tendril_cell::ProduceTruth>,
}

/// Consecutive invalid sensor samples (no estimate: non-finite, or below the calibration curve)
/// that end a run: [`tendril_cell::BLIND_TICKS`]. A lone bad sample is skipped and the last
/// valid estimate held; a sensor that stays bad longer (a broken fibre, an interrogator out of
/// lock) leaves the loop blind and must stop the run.
pub const MAX_CONSECUTIVE_INVALID_SAMPLES: u32 = tendril_cell::BLIND_TICKS;
