//! [`ControlPlan`]: everything the control side needs for one run.

use tendril_cell::gripper::GripperConfig;
use tendril_control::ControllerConfig;
use tendril_control::slip::SlipConfig;
use tendril_control::task::TaskConfig;
use tendril_fbg::array::ArrayConfig;
use tendril_fbg::estimate::ForceCalibration;

/// Everything the control side needs for one run (the cell is configured separately).
#[derive(Debug, Clone)]
pub struct ControlPlan {
    /// Force setpoint \[N\].
    pub setpoint_n: f64,
    /// Keep force control on while the arm moves.
    pub feedback: bool,
    /// Control loop rate \[Hz\].
    pub rate_hz: f64,
    /// The force controller (`[controller]`).
    pub controller: ControllerConfig,
    /// Calibration used by the estimator (eq. 8).
    pub calibration: ForceCalibration,
    /// Poses and timing.
    pub task: TaskConfig,
    /// Drive-train geometry.
    pub gripper: GripperConfig,
    /// Slip detector thresholds.
    pub slip: SlipConfig,
    /// The object's weight \[N\], when known (its mass from the scenario): what the wrist must read
    /// once the lift is under way ([`tendril_control::slip::SlipDetector::with_object_weight`]).
    pub object_weight_n: Option<f64>,
    /// The sensor array (`[array]`): what the controller regulates over its pads (`control`),
    /// the slip cue's thresholds and whether the run acts on it. Empty: the paper's single pad.
    pub array: ArrayConfig,
}
