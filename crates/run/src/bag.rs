//! A run's `bag/`: the run as a rosbag2 bag (MCAP storage), on the topics and types the ROS 2
//! participant uses live (`tendril serve --ros2`, `--hardware ros2`), so a lab opens it in
//! `ros2 bag`, Foxglove, PlotJuggler or the `rosbags` package. Each control tick records the
//! state the control side read (joint states, `/clock`, FBG peaks, each pad's estimate, the tool
//! wrench), the command it sent, and its `ControlTick` (every `trace.csv` column).

use super::trace::TraceRow;
use std::path::Path;
use tendril_cell::{CellCommand, CellState};
use tendril_ros2::Ros2Config;
use tendril_ros2::bag::{BagError, BagSummary, CellRecorder};
use tendril_ros2::state::{CellSample, own_references, state_messages};
use tendril_ros2msg::{ControlTick, Header, JointState};

/// The folder a run's bag goes in, inside its run directory.
pub const BAG_DIR: &str = "bag";

/// A run's bag being written.
pub struct RunBag {
    recorder: CellRecorder,
    config: Ros2Config,
    own_reference: Vec<bool>,
}

impl RunBag {
    /// A new bag in `run_dir/bag` with the names and QoS of `ros2`, for a sensor array whose
    /// further pads are `array` (a bag that exists is refused: nothing is overwritten).
    pub fn create(
        run_dir: &Path,
        ros2: &Ros2Config,
        array: &tendril_fbg::array::ArrayConfig,
    ) -> Result<RunBag, BagError> {
        Ok(RunBag {
            recorder: CellRecorder::create(&run_dir.join(BAG_DIR), ros2)?,
            config: ros2.clone(),
            own_reference: own_references(array),
        })
    }

    /// Records one tick: the state read, the command written, the trace row.
    pub fn record(&mut self, state: &CellState, command: &CellCommand, row: &TraceRow) -> Result<(), BagError> {
        let pad_force_n =
            std::iter::once(row.force_n).chain(row.array.pads.as_slice().iter().map(|p| p.force_n)).collect();
        let sample = CellSample {
            time_s: state.time_s,
            arm_q: state.arm_q,
            arm_qd: None,
            motors_rad: [state.growth_motor_rad, state.twine_motor_rad],
            motors_rad_s: None,
            motors_nm: None,
            wavelengths: state.wavelengths,
            array: state.array,
            pad_force_n,
            tool_load_n: state.tool_load_n,
        };
        self.recorder.record_state(&state_messages(&self.config, &self.own_reference, &sample))?;
        let sent = JointState {
            header: Header::at(state.time_s, ""),
            name: self.config.joints.all().into_iter().map(String::from).collect(),
            position: command
                .arm_q
                .iter()
                .copied()
                .chain([command.growth_motor_rad, command.twine_motor_rad])
                .collect(),
            velocity: Vec::new(),
            effort: Vec::new(),
        };
        self.recorder.record_command(state.time_s, &sent)?;
        self.recorder.record_tick(&control_tick(row))
    }

    /// Ends the bag.
    pub fn finish(self) -> Result<BagSummary, BagError> {
        self.recorder.finish()
    }
}

/// A trace row as a `ControlTick` message.
pub fn control_tick(r: &TraceRow) -> ControlTick {
    let pads = r.array.pads.as_slice();
    ControlTick {
        header: Header::at(r.time_s, ""),
        phase: r.phase.name().to_string(),
        setpoint_n: r.setpoint_n,
        force_n: r.force_n,
        force_uncompensated_n: r.force_uncompensated_n,
        over_range: r.over_range,
        controller_on: r.controller_on,
        controller_output_deg_s: r.controller_output_deg_s,
        control_force_n: r.controlled_n(),
        tool_load_n: r.tool_load_n,
        true_force_n: r.true_force_n,
        pad_true_force_n: pads.iter().map(|p| p.true_force_n).collect(),
        pad_force_n: pads.iter().map(|p| p.force_n).collect(),
        grip_force_n: r.grip_force_n,
        object_height_m: r.object_height_m,
        slip_speed_m_s: r.slip_speed_m_s,
    }
}
