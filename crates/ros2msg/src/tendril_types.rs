//! tendril's own messages (package `tendril_msgs`), for what no standard message carries: the
//! interrogator's peaks of every grating, and the control side's record of one tick. Their
//! definitions travel with every bag (the schema), and `ros2/tendril_msgs/` is the ROS 2 package
//! a lab builds to echo them live.

use crate::cdr::{CdrError, CdrReader, CdrWriter};
use crate::message::{Message, TypeInfo};
use crate::std_types::Header;

/// `tendril_msgs/msg/FbgPeaks`: one interrogator sample of the sensor pads' gratings.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FbgPeaks {
    /// When the sample was taken; the frame is the pad 0's (`fbg_pad0`).
    pub header: Header,
    /// Which grating each wavelength is: `pad0/fbg1`, `pad0/fbg2`, then each further pad's
    /// `padK/fbg1` (and `padK/fbg2` when it has its own reference grating).
    pub grating: Vec<String>,
    /// Each grating's peak wavelength \[nm\]; NaN when no peak was found in its window.
    pub wavelength_nm: Vec<f64>,
}

impl Message for FbgPeaks {
    const TYPE: TypeInfo = TypeInfo {
        name: "tendril_msgs/msg/FbgPeaks",
        definition: "std_msgs/Header header\nstring[] grating\nfloat64[] wavelength_nm\n",
        nested: &[Header::INFO],
    };
    fn encode(&self, w: &mut CdrWriter) {
        self.header.encode(w);
        w.strings(&self.grating);
        w.f64s(&self.wavelength_nm);
    }
    fn decode(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(FbgPeaks {
            header: Header::decode(r)?,
            grating: r.strings("grating")?,
            wavelength_nm: r.f64s("wavelength_nm")?,
        })
    }
}

/// `tendril_msgs/msg/ControlTick`: what the control side did in one tick, and the twin's ground
/// truth when the cell is the twin (NaN otherwise): a `trace.csv` row.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ControlTick {
    /// The tick's cell time.
    pub header: Header,
    /// The task's phase (`home`, `grow`, `wrap`, `grasp`, `lift`, ...).
    pub phase: String,
    /// Force setpoint \[N\].
    pub setpoint_n: f64,
    /// Pad 0's temperature-compensated estimate, eq. (8) \[N\].
    pub force_n: f64,
    /// Pad 0's estimate without temperature compensation \[N\].
    pub force_uncompensated_n: f64,
    /// Whether the estimate was over the sensor's range.
    pub over_range: bool,
    /// Whether the force controller ran.
    pub controller_on: bool,
    /// The controller's output, the twine motor's speed \[°/s\].
    pub controller_output_deg_s: f64,
    /// The force the controller regulated \[N\] (pad 0's estimate, or a sensor array's total or
    /// largest).
    pub control_force_n: f64,
    /// The tool's load as the wrist force sensor reads it \[N\] (NaN without one).
    pub tool_load_n: f64,
    /// True normal force on pad 0 \[N\] (NaN without ground truth).
    pub true_force_n: f64,
    /// True normal force on each further pad \[N\] (empty without a sensor array).
    pub pad_true_force_n: Vec<f64>,
    /// Each further pad's estimate \[N\] (empty without a sensor array).
    pub pad_force_n: Vec<f64>,
    /// Total grip normal force \[N\] (NaN without ground truth).
    pub grip_force_n: f64,
    /// Object height above the table \[m\] (NaN without ground truth).
    pub object_height_m: f64,
    /// Object speed relative to the hand \[m/s\] (NaN without ground truth).
    pub slip_speed_m_s: f64,
}

impl Message for ControlTick {
    const TYPE: TypeInfo = TypeInfo {
        name: "tendril_msgs/msg/ControlTick",
        definition: "std_msgs/Header header\nstring phase\nfloat64 setpoint_n\nfloat64 force_n\n\
float64 force_uncompensated_n\nbool over_range\nbool controller_on\nfloat64 controller_output_deg_s\n\
float64 control_force_n\nfloat64 tool_load_n\nfloat64 true_force_n\nfloat64[] pad_true_force_n\n\
float64[] pad_force_n\nfloat64 grip_force_n\nfloat64 object_height_m\nfloat64 slip_speed_m_s\n",
        nested: &[Header::INFO],
    };
    fn encode(&self, w: &mut CdrWriter) {
        self.header.encode(w);
        w.string(&self.phase);
        w.f64(self.setpoint_n);
        w.f64(self.force_n);
        w.f64(self.force_uncompensated_n);
        w.bool(self.over_range);
        w.bool(self.controller_on);
        w.f64(self.controller_output_deg_s);
        w.f64(self.control_force_n);
        w.f64(self.tool_load_n);
        w.f64(self.true_force_n);
        w.f64s(&self.pad_true_force_n);
        w.f64s(&self.pad_force_n);
        w.f64(self.grip_force_n);
        w.f64(self.object_height_m);
        w.f64(self.slip_speed_m_s);
    }
    fn decode(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(ControlTick {
            header: Header::decode(r)?,
            phase: r.string("phase")?,
            setpoint_n: r.f64("setpoint_n")?,
            force_n: r.f64("force_n")?,
            force_uncompensated_n: r.f64("force_uncompensated_n")?,
            over_range: r.bool("over_range")?,
            controller_on: r.bool("controller_on")?,
            controller_output_deg_s: r.f64("controller_output_deg_s")?,
            control_force_n: r.f64("control_force_n")?,
            tool_load_n: r.f64("tool_load_n")?,
            true_force_n: r.f64("true_force_n")?,
            pad_true_force_n: r.f64s("pad_true_force_n")?,
            pad_force_n: r.f64s("pad_force_n")?,
            grip_force_n: r.f64("grip_force_n")?,
            object_height_m: r.f64("object_height_m")?,
            slip_speed_m_s: r.f64("slip_speed_m_s")?,
        })
    }
}
