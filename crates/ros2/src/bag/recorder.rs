//! [`CellRecorder`]: a cell's topics into a bag, under the live participant's names and types.

use super::{BagError, BagSummary, BagWriter};
use crate::config::Ros2Config;
use crate::state::StateMessages;
use std::path::Path;
use tendril_ros2msg::{Clock, ControlTick, FbgPeaks, JointState, Message, WrenchStamped};

/// Records state messages, commands and control ticks into a bag as they come, each topic added
/// on its first message.
pub struct CellRecorder {
    bag: BagWriter,
    config: Ros2Config,
}

/// `t` \[s\] as a bag's timestamp \[ns\] (negative times, which no run has, at 0).
pub fn time_ns(t: f64) -> u64 {
    (t * 1e9).round().max(0.0) as u64
}

impl CellRecorder {
    /// A new bag in `dir` (refused if it exists) with `config`'s topic names and QoS.
    pub fn create(dir: &Path, config: &Ros2Config) -> Result<CellRecorder, BagError> {
        Ok(CellRecorder { bag: BagWriter::create(dir, config.distro)?, config: config.clone() })
    }

    fn write<M: Message>(&mut self, topic: &str, state: bool, t_ns: u64, m: &M) -> Result<(), BagError> {
        let q = &self.config.qos;
        let qos = if state { q.state } else { q.command };
        let id = self.bag.add_topic::<M>(&self.config.resolve(topic), qos)?;
        self.bag.write(id, t_ns, m)
    }

    /// One sample's state messages (at the clock's time).
    pub fn record_state(&mut self, m: &StateMessages) -> Result<(), BagError> {
        let t = m.clock.clock.as_nanos().max(0) as u64;
        let topics = self.config.topics.clone();
        let clock_qos = self.config.qos.clock;
        let id = self.bag.add_topic::<Clock>(&self.config.resolve(&topics.clock), clock_qos)?;
        self.bag.write(id, t, &m.clock)?;
        self.write::<JointState>(&topics.joint_states, true, t, &m.joints)?;
        self.write::<FbgPeaks>(&topics.fbg_peaks, true, t, &m.peaks)?;
        for (k, w) in m.pad_wrenches.iter().enumerate() {
            self.write::<WrenchStamped>(&topics.fbg_wrench_of(k), true, t, w)?;
        }
        if let Some(tool) = &m.tool {
            self.write::<WrenchStamped>(&topics.tool_wrench, true, t, tool)?;
        }
        Ok(())
    }

    /// A command, received or sent at `t_s` \[s\].
    pub fn record_command(&mut self, t_s: f64, m: &JointState) -> Result<(), BagError> {
        let topic = self.config.topics.joint_commands.clone();
        self.write::<JointState>(&topic, false, time_ns(t_s), m)
    }

    /// The control side's record of a tick (at its header's time).
    pub fn record_tick(&mut self, m: &ControlTick) -> Result<(), BagError> {
        let topic = self.config.topics.control_tick.clone();
        self.write::<ControlTick>(&topic, true, m.header.stamp.as_nanos().max(0) as u64, m)
    }

    /// Ends the bag.
    pub fn finish(self) -> Result<BagSummary, BagError> {
        self.bag.finish()
    }
}
