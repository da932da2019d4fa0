//! `tendril serve --ros2`: the twin as the lab's drivers on its ROS 2 graph ([`Ros2Bridge`]).
//!
//! The twin's thread, each tick, takes the commands that arrived ([`Ros2Bridge::take_commands`])
//! and, every publish period, publishes the state topics ([`Ros2Bridge::publish`]): read, update,
//! write, as a ros2_control hardware interface does, with no thread of its own. A command the twin
//! cannot follow is refused with its reason, printed once per reason; nothing queues beyond the
//! subscription's keep-last history and one command per tick is acted on (the latest).

use super::ros2_clock::CommandClock;
use super::ros2_commands::{MotorDrives, RosCommand, parse_command};
use super::sensor_node::SensorNode;
use super::state::{DeviceState, ProgramState};
use std::collections::BTreeSet;
use std::path::Path;
use tendril_dynamixel::control_table::addr;
use tendril_dynamixel::units::{rad_to_ticks, ticks_to_rad};
use tendril_ros2::bag::CellRecorder;
use tendril_ros2::state::{CellSample, StateMessages, own_references, state_messages};
use tendril_ros2::{Node, Pub, Ros2Config, Sub};
use tendril_ros2msg::{Clock, FbgPeaks, JointState, WrenchStamped};
use tendril_run::scenario::PickPlaceScenario;

/// What `tendril serve --ros2` was asked for besides the scenario's `[ros2]`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Ros2Serving {
    /// Record the node's topics into a bag in this folder (refused if it exists).
    pub bag: Option<std::path::PathBuf>,
}

/// The twin's ROS 2 node.
pub struct Ros2Bridge {
    config: Ros2Config,
    _node: Node,
    joints: Pub<JointState>,
    clock: Pub<Clock>,
    peaks: Pub<FbgPeaks>,
    wrenches: Vec<Pub<WrenchStamped>>,
    tool: Pub<WrenchStamped>,
    commands: Sub<JointState>,
    own_reference: Vec<bool>,
    sensor: SensorNode,
    recorder: Option<CellRecorder>,
    refused: BTreeSet<String>,
    /// Commands acted on, refused.
    pub counts: [u64; 2],
    /// The motors' velocity drives.
    motors: MotorDrives,
    /// When the arm's targets are due.
    arm_clock: CommandClock,
}

impl Ros2Bridge {
    /// The node for `scenario`'s `[ros2]`, publishing the state topics and subscribed to the
    /// commands; with `bag`, recording both there (a folder that exists is refused).
    pub fn new(scenario: &PickPlaceScenario, bag: Option<&Path>) -> anyhow::Result<Ros2Bridge> {
        let config = scenario.ros2.clone();
        let recorder = bag.map(|dir| CellRecorder::create(dir, &config)).transpose()?;
        let mut node = Node::new(&config, &format!("{}_twin", config.node_name))?;
        let (t, q) = (&config.topics, &config.qos);
        let pads = 1 + scenario.array.pads.len();
        let wrenches = (0..pads)
            .map(|k| node.publisher::<WrenchStamped>(&t.fbg_wrench_of(k), q.state))
            .collect::<Result<_, _>>()?;
        Ok(Ros2Bridge {
            joints: node.publisher(&t.joint_states, q.state)?,
            clock: node.publisher(&t.clock, q.clock)?,
            peaks: node.publisher(&t.fbg_peaks, q.state)?,
            wrenches,
            tool: node.publisher(&t.tool_wrench, q.state)?,
            commands: node.subscription(&t.joint_commands, q.command)?,
            own_reference: own_references(&scenario.array),
            sensor: SensorNode::new(&scenario.estimator, scenario.array.pads.len(), &scenario.array.calibrations),
            recorder,
            refused: BTreeSet::new(),
            counts: [0; 2],
            motors: MotorDrives::default(),
            arm_clock: CommandClock::default(),
            _node: node,
            config,
        })
    }

    /// The `[ros2]` settings it runs with.
    pub fn config(&self) -> &Ros2Config {
        &self.config
    }

    /// How often it publishes \[s\].
    pub fn publish_period_s(&self) -> f64 {
        1.0 / self.config.publish_rate_hz
    }

    /// Publishes (and records) the state topics of `sample`, every pad's estimate added.
    pub fn publish(&mut self, mut sample: CellSample) -> anyhow::Result<StateMessages> {
        sample.pad_force_n = self.sensor.estimate(sample.time_s, sample.wavelengths, &sample.array);
        let m = state_messages(&self.config, &self.own_reference, &sample);
        self.clock.publish(&m.clock)?;
        self.joints.publish(&m.joints)?;
        self.peaks.publish(&m.peaks)?;
        for (p, w) in self.wrenches.iter().zip(&m.pad_wrenches) {
            p.publish(w)?;
        }
        if let Some(tool) = &m.tool {
            self.tool.publish(tool)?;
        }
        if let Some(r) = self.recorder.as_mut() {
            r.record_state(&m)?;
        }
        Ok(m)
    }

    /// The commands that arrived since the last call, checked, oldest first (at most one
    /// subscription read's worth). Each refused one is counted, and its reason printed the first
    /// time it comes.
    pub fn take_commands(&mut self, now_s: f64) -> Vec<RosCommand> {
        let mut out = Vec::new();
        for m in self.commands.take() {
            let parsed = m.map_err(|e| e.to_string()).and_then(|m| {
                if let Some(r) = self.recorder.as_mut() {
                    let _ = r.record_command(now_s, &m);
                }
                parse_command(&m, &self.config.joints).map_err(|why| format!("{}: {why}", self.commands.topic()))
            });
            match parsed {
                Ok(c) => out.push(c),
                Err(why) => self.refuse(why),
            }
        }
        out
    }

    /// Counts a refused command and prints its reason the first time.
    pub fn refuse(&mut self, why: String) {
        self.counts[1] += 1;
        if self.refused.insert(why.clone()) {
            eprintln!("tendril serve: ROS 2 command refused: {why}");
        }
    }

    /// The motors' position targets \[rad\] after `commands`: see [`MotorDrives::targets`].
    pub fn motor_targets(
        &mut self,
        commands: &[RosCommand],
        now_s: f64,
        dt_s: f64,
        targets: [f64; 2],
    ) -> Option<[f64; 2]> {
        self.motors.targets(commands, now_s, dt_s, targets)
    }

    /// Ends its bag, if it records one; returns where and how many messages.
    pub fn finish(mut self) -> anyhow::Result<Option<tendril_ros2::bag::BagSummary>> {
        Ok(self.recorder.take().map(|r| r.finish()).transpose()?)
    }
}

/// A bag not finished by [`Ros2Bridge::finish`] (the twin failed) is finished here: the messages
/// up to the failure are kept, with their `metadata.yaml`.
impl Drop for Ros2Bridge {
    fn drop(&mut self) {
        if let Some(r) = self.recorder.take()
            && let Err(e) = r.finish()
        {
            eprintln!("tendril serve: ROS 2 bag: {e}");
        }
    }
}

/// Drives the motors by the ROS 2 commands of this tick: their targets written to the MX-106s'
/// Goal Position with torque on, as a bus write would (a client on the bus reads the same goal).
pub fn drive_motors(
    bridge: &mut Ros2Bridge,
    commands: &[RosCommand],
    s: &mut DeviceState,
    ids: [u8; 2],
    now_s: f64,
    dt_s: f64,
) {
    let current = ids.map(|id| s.bus.table(id).map_or(0.0, |t| ticks_to_rad(t.goal_position())));
    let Some(targets) = bridge.motor_targets(commands, now_s, dt_s, current) else { return };
    for (id, rad) in ids.into_iter().zip(targets) {
        if let (Some(t), Ok(ticks)) = (s.bus.table_mut(id), rad_to_ticks(rad)) {
            t.put(addr::TORQUE_ENABLE, &[1]);
            t.put(addr::GOAL_POSITION, &ticks.to_le_bytes());
        }
    }
}

impl Ros2Bridge {
    /// The arm targets of `commands`, taken at twin time `now_s` and wall time `arrived_s` (the
    /// twin's time had it kept real time: later than `now_s` while the twin runs behind), each
    /// with the twin time it is due and how much later the arm passes it (the command clock,
    /// `ros2_clock.rs`), if
    /// the virtual UR5e takes them: not while a URScript program plays (one master at a time, as
    /// on a UR whose external control program owns the arm) or the arm is in a protective stop; a
    /// target beyond the UR5e's range or speed puts it in a protective stop (unlocked on the
    /// dashboard), as RTDE's do.
    pub fn arm_targets(
        &mut self,
        commands: &[RosCommand],
        s: &mut DeviceState,
        now_s: f64,
        arrived_s: f64,
        measured_q: [f64; 6],
    ) -> Vec<([f64; 6], f64, f64)> {
        let mut out = Vec::new();
        for c in commands {
            let Some(q) = c.arm else { continue };
            if !self.arm_allowed(s, now_s, &q, &measured_q) {
                return Vec::new();
            }
            let (due_s, lag_s) = self.arm_clock.place(c.stamp_s, arrived_s);
            out.push((q, due_s, lag_s));
        }
        out
    }

    /// Whether the arm may follow target `q`: see [`Ros2Bridge::arm_targets`].
    fn arm_allowed(&mut self, s: &mut DeviceState, now_s: f64, q: &[f64; 6], measured_q: &[f64; 6]) -> bool {
        let topic = self.commands.topic().to_string();
        if s.program == ProgramState::Playing {
            self.refuse(format!(
                "{topic}: a URScript program plays on the virtual UR5e: the arm follows it, not ROS 2"
            ));
            return false;
        }
        if let Some(why) = &s.protective_stop {
            self.refuse(format!("{topic}: the arm is in a protective stop ({why}): unlock it on the dashboard"));
            return false;
        }
        if let Some(why) = tendril_ur5e::safety::violation(q, measured_q) {
            self.refuse(format!("{topic}: protective stop: {why}"));
            s.protective_stop = Some(why);
            s.ur.protective_stop_at = Some(now_s);
            return false;
        }
        self.counts[0] += 1;
        true
    }
}
