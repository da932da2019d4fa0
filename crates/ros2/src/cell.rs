//! [`Ros2Cell`]: a lab's ROS 2 drivers behind the [`Cell`] trait, so tendril's estimation, control
//! and task sequencing run on a cell whose arm, motors and interrogator are ROS 2 nodes.
//!
//! Read: the joints by name from `joint_states` (several publishers may each send some: a joint's
//! latest value counts), every grating from `fbg/peaks`, the wrist's load from the tool wrench when
//! one is published. Write: one `JointState` command with the arm's six joints and the two motors,
//! by position, on `joint_commands`. Time: the wall clock since activation, or with `use_sim_time`
//! `/clock`, each tick then waiting for the state topics to reach its time (a lock-step twin
//! advances when the command arrives).
//!
//! Safety as on the device path: a topic whose latest message is older than its watchdog
//! ([`TopicWatchdog`]), a joint or grating missing, or a malformed message fails `read` with the
//! topic and the age; the runner then deactivates the cell, which commands the arm to hold where
//! it is and the motors to hold their positions (the motors keep the object gripped). The force
//! ceiling and the joint limits are `tendril_control::limits::LimitedCell`'s, around this cell.

use super::config::Ros2Config;
use super::node::{Node, Pub, Sub};
use super::state::wavelengths_of;
use super::watch::TopicWatchdog;
use std::time::{Duration, Instant};
use tendril_cell::{
    ARM_JOINTS, Cell, CellCommand, CellError, CellState, DeviceTiming, Lifecycle, Spread, require_state,
};
use tendril_fbg::array::ArrayPeaks;
use tendril_fbg::signals::Wavelengths;
use tendril_ros2msg::{Clock, FbgPeaks, Header, JointState, Message, Time, WrenchStamped};

/// What a cell over ROS 2 needs besides `[ros2]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Ros2CellConfig {
    /// Topics, joints, QoS, domain.
    pub ros2: Ros2Config,
    /// Further pads of the scenario's sensor array (each read as `padK/fbg1` and, when it has one,
    /// `padK/fbg2`; a pad without its own reference uses pad 0's).
    pub further_pads: usize,
    /// The watchdog's limits.
    pub watchdog: TopicWatchdog,
    /// How long `configure` waits for the first message of each state topic \[s\]: 10 s, time for
    /// discovery between processes just started (about 1 s on loopback) with a wide margin.
    pub first_message_s: f64,
}

impl Ros2CellConfig {
    /// For a loop ticking at `control_rate_hz` \[Hz\] on the topics `ros2` names, published at its
    /// `publish_rate_hz`.
    pub fn new(ros2: Ros2Config, control_rate_hz: f64, further_pads: usize) -> Ros2CellConfig {
        let watchdog = TopicWatchdog::for_control(1.0 / control_rate_hz, 1.0 / ros2.publish_rate_hz);
        Ros2CellConfig { ros2, further_pads, watchdog, first_message_s: 10.0 }
    }
}

struct Io {
    node: Node,
    joints: Sub<JointState>,
    peaks: Sub<FbgPeaks>,
    tool: Sub<WrenchStamped>,
    clock: Option<Sub<Clock>>,
    commands: Pub<JointState>,
}

/// One value and when it came: its stamp and when the cell took it (both cell-clock seconds).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Stamped<T> {
    value: T,
    stamp_s: f64,
    taken_s: f64,
}

#[derive(Default)]
struct Latest {
    /// The eight joints, in `JointNames::all`'s order.
    joints: [Option<Stamped<f64>>; ARM_JOINTS + 2],
    peaks: Option<Stamped<(Wavelengths, ArrayPeaks)>>,
    tool_load_n: Option<Stamped<f64>>,
    /// The latest `/clock` \[s\] (with `use_sim_time`).
    clock_s: Option<f64>,
    /// FBG peak messages taken so far.
    peaks_taken: u64,
}

/// The cell.
pub struct Ros2Cell {
    config: Ros2CellConfig,
    lifecycle: Lifecycle,
    io: Option<Io>,
    latest: Latest,
    /// Wall clock at activation (or at configure, before it).
    started: Instant,
    /// The same instant as time since the Unix epoch \[s\]: what the commands' stamps count from.
    started_epoch_s: f64,
    /// The cell time of the last read \[s\]: the time a tick's command is for.
    last_read_s: f64,
    /// `/clock` at activation \[s\] (with `use_sim_time`).
    clock_zero_s: f64,
    /// Each tick's age of the oldest joint and of the peaks [s].
    ages: [Vec<f64>; 2],
    /// Peak messages taken up to the last read.
    peaks_read: u64,
    sample_new: bool,
}

/// The wall clock as time since the Unix epoch \[s\] (f64 holds it to 0.24 µs).
fn epoch_s() -> f64 {
    std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap_or_default().as_secs_f64()
}

fn device(topic: &str, cause: impl Into<String>) -> CellError {
    CellError::Device { device: format!("ROS 2 topic {topic}"), cause: cause.into() }
}

impl Ros2Cell {
    /// A cell over the topics `config` names (nothing is contacted before [`Cell::configure`]).
    pub fn new(config: Ros2CellConfig) -> Ros2Cell {
        Ros2Cell {
            config,
            lifecycle: Lifecycle::Unconfigured,
            io: None,
            latest: Latest::default(),
            started: Instant::now(),
            started_epoch_s: epoch_s(),
            last_read_s: 0.0,
            clock_zero_s: 0.0,
            ages: [Vec::new(), Vec::new()],
            peaks_read: 0,
            sample_new: false,
        }
    }

    fn sim_time(&self) -> bool {
        self.config.ros2.use_sim_time
    }

    /// The cell's clock \[s\]: wall time since activation, or `/clock` since activation.
    fn now_s(&self) -> f64 {
        if self.sim_time() {
            self.latest.clock_s.map_or(0.0, |c| c - self.clock_zero_s)
        } else {
            self.started.elapsed().as_secs_f64()
        }
    }

    /// A message's stamp on the cell's clock \[s\] (meaningful with `use_sim_time`, where the
    /// stamps are `/clock`'s; on the wall clock a message counts from when it was taken).
    fn stamp_s(&self, h: &Header) -> f64 {
        if self.sim_time() { h.stamp.as_secs_f64() - self.clock_zero_s } else { self.now_s() }
    }

    /// Takes every message that arrived, newest values kept. A malformed message is an error
    /// naming its topic.
    fn drain(&mut self) -> Result<(), CellError> {
        let Some(io) = self.io.as_mut() else { return Ok(()) };
        if let Some(clock) = io.clock.as_mut() {
            for m in clock.take() {
                let m = m.map_err(|e| device(clock.topic(), e.to_string()))?;
                let t = m.clock.as_secs_f64();
                self.latest.clock_s = Some(self.latest.clock_s.map_or(t, |c| c.max(t)));
            }
        }
        let joints = io.joints.take();
        let peaks = io.peaks.take();
        let tool = io.tool.take();
        let (joints_topic, peaks_topic, tool_topic) =
            (io.joints.topic().to_string(), io.peaks.topic().to_string(), io.tool.topic().to_string());
        let now = self.now_s();
        let names = self.config.ros2.joints.all().into_iter().map(String::from).collect::<Vec<_>>();
        for m in joints {
            let m = m.map_err(|e| self.malformed::<JointState>(&joints_topic, e))?;
            let stamp_s = self.stamp_s(&m.header);
            for (name, &q) in m.name.iter().zip(&m.position) {
                if let Some(i) = names.iter().position(|n| n == name) {
                    if !q.is_finite() {
                        return Err(device(&joints_topic, format!("joint {name}: position {q} is not finite")));
                    }
                    self.latest.joints[i] = Some(Stamped { value: q, stamp_s, taken_s: now });
                }
            }
        }
        for m in peaks {
            let m = m.map_err(|e| self.malformed::<FbgPeaks>(&peaks_topic, e))?;
            let stamp_s = self.stamp_s(&m.header);
            let value = wavelengths_of(&m, self.config.further_pads).map_err(|e| device(&peaks_topic, e))?;
            self.latest.peaks = Some(Stamped { value, stamp_s, taken_s: now });
            self.latest.peaks_taken += 1;
        }
        for m in tool {
            let m = m.map_err(|e| self.malformed::<WrenchStamped>(&tool_topic, e))?;
            let stamp_s = self.stamp_s(&m.header);
            // The UR driver's wrench is the external force on the tool in the base frame: the load
            // the tool carries pulls it down (RTDE's `actual_TCP_force`, as the device path reads it).
            self.latest.tool_load_n = Some(Stamped { value: -m.wrench.force.z, stamp_s, taken_s: now });
        }
        Ok(())
    }

    /// A message on `topic` that is not an `M`, as an error: with the types other participants
    /// offer there (a DDS participant may deliver another type's samples under a topic's name).
    fn malformed<M: Message>(&self, topic: &str, e: super::Ros2Error) -> CellError {
        let foreign = self.io.as_ref().map(|io| io.node.foreign_types::<M>(topic)).unwrap_or_default();
        if foreign.is_empty() {
            device(topic, e.to_string())
        } else {
            device(topic, format!("{e}: a publisher offers {} there, not {}", foreign.join(", "), M::TYPE.dds_name()))
        }
    }

    /// Why the latest state cannot be used, if it cannot: what is missing or too old.
    fn stale(&self) -> Option<CellError> {
        let now = self.now_s();
        let w = self.config.watchdog;
        let io = self.io.as_ref()?;
        let names = self.config.ros2.joints.all();
        for (i, j) in self.latest.joints.iter().enumerate() {
            match j {
                None => return Some(device(io.joints.topic(), format!("no position of joint {} received", names[i]))),
                Some(s) if now - s.taken_s > w.joints_stale_s => {
                    return Some(device(
                        io.joints.topic(),
                        format!(
                            "joint {} last received {:.3} s ago (watchdog {:.3} s): its publisher stopped",
                            names[i],
                            now - s.taken_s,
                            w.joints_stale_s
                        ),
                    ));
                }
                _ => {}
            }
        }
        match &self.latest.peaks {
            None => Some(device(io.peaks.topic(), "no FBG peaks received")),
            Some(p) if now - p.taken_s > w.peaks_stale_s => Some(device(
                io.peaks.topic(),
                format!(
                    "FBG peaks last received {:.3} s ago (watchdog {:.3} s): its publisher stopped",
                    now - p.taken_s,
                    w.peaks_stale_s
                ),
            )),
            _ => None,
        }
    }

    /// Waits (up to `limit`, wall clock) until `done` holds of the latest state, draining as
    /// messages come; returns whether it did.
    fn wait_for(&mut self, limit: Duration, done: impl Fn(&Ros2Cell) -> bool) -> Result<bool, CellError> {
        let until = Instant::now() + limit;
        loop {
            self.drain()?;
            if done(self) {
                return Ok(true);
            }
            if Instant::now() >= until {
                return Ok(false);
            }
            // Topics arrive every few milliseconds; a lock-step twin answers within a tick's
            // compute. 50 µs keeps the wait's share of a lock-step tick small.
            std::thread::sleep(Duration::from_micros(50));
        }
    }

    /// Why nothing arrives on `topic` of type `M`, when another participant offers it as another
    /// type.
    fn why_silent<M: Message>(&self, topic: &str) -> String {
        let foreign = self.io.as_ref().map(|io| io.node.foreign_types::<M>(topic)).unwrap_or_default();
        if foreign.is_empty() {
            format!(
                "no message within {} s: is the lab's driver running in ROS domain {}{}?",
                self.config.first_message_s,
                self.config.ros2.domain_id,
                if self.config.ros2.localhost_only { " on this machine (localhost_only)" } else { "" }
            )
        } else {
            format!("a publisher offers {} there, not {} (tendril's type)", foreign.join(", "), M::TYPE.dds_name())
        }
    }

    /// The command for cell time `cell_s`, stamped with it on the cell's clock: `/clock` with
    /// `use_sim_time`, else the wall clock since the epoch. A tick's command is stamped with its
    /// read's time, not with when it is sent, as the device path stamps its RTDE targets: the
    /// target is the plan's at that read, and a commander that places targets at their stamps (the
    /// twin's command clock) then places it there however long the tick waited for the CPU.
    fn command_message(&self, cell_s: f64, arm_q: [f64; ARM_JOINTS], growth: f64, twine: f64) -> JointState {
        let zero_s = if self.sim_time() { self.clock_zero_s } else { self.started_epoch_s };
        JointState {
            header: Header { stamp: Time::from_secs_f64(zero_s + cell_s), frame_id: String::new() },
            name: self.config.ros2.joints.all().into_iter().map(String::from).collect(),
            position: arm_q.iter().copied().chain([growth, twine]).collect(),
            velocity: Vec::new(),
            effort: Vec::new(),
        }
    }
}

impl Cell for Ros2Cell {
    fn backend(&self) -> &str {
        "ros2"
    }

    fn lifecycle(&self) -> Lifecycle {
        self.lifecycle
    }

    /// Joins the graph and waits for the first message of every state topic (and of `/clock` with
    /// `use_sim_time`); a topic that stays silent fails with the likely reason.
    fn configure(&mut self) -> Result<(), CellError> {
        require_state(self.lifecycle, Lifecycle::Unconfigured, "configure")?;
        let r = &self.config.ros2;
        let e = |e: super::Ros2Error| CellError::Configure(e.to_string());
        let mut node = Node::new(r, &r.node_name).map_err(e)?;
        let (state, command) = (r.qos.state, r.qos.command);
        let joints = node.subscription::<JointState>(&r.topics.joint_states, state).map_err(e)?;
        let peaks = node.subscription::<FbgPeaks>(&r.topics.fbg_peaks, state).map_err(e)?;
        let tool = node.subscription::<WrenchStamped>(&r.topics.tool_wrench, state).map_err(e)?;
        let clock = if r.use_sim_time {
            Some(node.subscription::<Clock>(&r.topics.clock, r.qos.clock).map_err(e)?)
        } else {
            None
        };
        let commands = node.publisher::<JointState>(&r.topics.joint_commands, command).map_err(e)?;
        self.io = Some(Io { node, joints, peaks, tool, clock, commands });
        self.started = Instant::now();
        let limit = Duration::from_secs_f64(self.config.first_message_s);
        let sim = self.sim_time();
        if !self.wait_for(limit, |c| {
            (!sim || c.latest.clock_s.is_some())
                && c.latest.joints.iter().all(Option::is_some)
                && c.latest.peaks.is_some()
        })? {
            let io = self.io.as_ref().expect("set above");
            let (topic, why) = if sim && self.latest.clock_s.is_none() {
                (
                    io.clock.as_ref().map_or("/clock", |c| c.topic()).to_string(),
                    self.why_silent::<Clock>(io.clock.as_ref().map_or("/clock", |c| c.topic())),
                )
            } else if self.latest.peaks.is_none() {
                (io.peaks.topic().to_string(), self.why_silent::<FbgPeaks>(io.peaks.topic()))
            } else {
                let names = self.config.ros2.joints.all();
                let missing: Vec<&str> =
                    names.iter().zip(&self.latest.joints).filter(|(_, j)| j.is_none()).map(|(n, _)| *n).collect();
                let why = if missing.len() == names.len() {
                    self.why_silent::<JointState>(io.joints.topic())
                } else {
                    format!("no position of joint(s) {} in the messages received", missing.join(", "))
                };
                (io.joints.topic().to_string(), why)
            };
            self.io = None;
            return Err(CellError::Configure(format!("ROS 2 topic {topic}: {why}")));
        }
        self.lifecycle = Lifecycle::Inactive;
        Ok(())
    }

    fn activate(&mut self) -> Result<(), CellError> {
        require_state(self.lifecycle, Lifecycle::Inactive, "activate")?;
        self.drain()?;
        // Re-stamp what was taken before on the new clock: ages count from activation.
        let before = self.now_s();
        self.started = Instant::now();
        self.started_epoch_s = epoch_s();
        self.clock_zero_s = self.latest.clock_s.unwrap_or(0.0);
        let shift = |s: &mut f64| *s -= before;
        for j in self.latest.joints.iter_mut().flatten() {
            shift(&mut j.taken_s);
        }
        if let Some(p) = self.latest.peaks.as_mut() {
            shift(&mut p.taken_s);
        }
        if let Some(t) = self.latest.tool_load_n.as_mut() {
            shift(&mut t.taken_s);
        }
        self.lifecycle = Lifecycle::Active;
        Ok(())
    }

    /// The safe stop: the arm commanded to hold where it is, the motors to hold their positions.
    fn deactivate(&mut self) -> Result<(), CellError> {
        if self.lifecycle != Lifecycle::Active {
            return Ok(());
        }
        self.lifecycle = Lifecycle::Inactive;
        let _ = self.drain();
        let q: Vec<Option<f64>> = self.latest.joints.iter().map(|j| j.map(|s| s.value)).collect();
        if let (Some(io), true) = (self.io.as_ref(), q.iter().all(Option::is_some)) {
            let q: Vec<f64> = q.into_iter().flatten().collect();
            let hold = self.command_message(self.now_s(), std::array::from_fn(|j| q[j]), q[6], q[7]);
            io.commands.publish(&hold).map_err(|e| device(io.commands.topic(), e.to_string()))?;
        }
        Ok(())
    }

    fn read(&mut self) -> Result<CellState, CellError> {
        require_state(self.lifecycle, Lifecycle::Active, "read")?;
        self.drain()?;
        if let Some(e) = self.stale() {
            return Err(e);
        }
        let now = self.now_s();
        self.last_read_s = now;
        let q: Vec<f64> = self.latest.joints.iter().map(|j| j.map_or(f64::NAN, |s| s.value)).collect();
        let peaks = self.latest.peaks.expect("checked by stale");
        self.sample_new = self.latest.peaks_taken > self.peaks_read;
        self.peaks_read = self.latest.peaks_taken;
        let oldest_joint = self.latest.joints.iter().flatten().map(|s| now - s.taken_s).fold(0.0, f64::max);
        self.ages[0].push(oldest_joint);
        self.ages[1].push(now - peaks.taken_s);
        // A wrench older than the joints' watchdog is not a reading of this tick.
        let tool_load_n =
            self.latest.tool_load_n.filter(|t| now - t.taken_s <= self.config.watchdog.joints_stale_s).map(|t| t.value);
        Ok(CellState {
            time_s: now,
            arm_q: std::array::from_fn(|j| q[j]),
            growth_motor_rad: q[ARM_JOINTS],
            twine_motor_rad: q[ARM_JOINTS + 1],
            wavelengths: peaks.value.0,
            array: peaks.value.1,
            tool_load_n,
        })
    }

    fn write(&mut self, command: &CellCommand) -> Result<(), CellError> {
        require_state(self.lifecycle, Lifecycle::Active, "write")?;
        let m =
            self.command_message(self.last_read_s, command.arm_q, command.growth_motor_rad, command.twine_motor_rad);
        let io = self.io.as_ref().expect("an active cell has its node");
        io.commands.publish(&m).map_err(|e| device(io.commands.topic(), e.to_string()))
    }

    /// On the wall clock, sleeps until `time_s`; with `use_sim_time`, waits until `/clock` and the
    /// state topics have reached `time_s` (a lock-step twin steps when the tick's command arrives).
    fn wait_until(&mut self, time_s: f64) -> Result<(), CellError> {
        require_state(self.lifecycle, Lifecycle::Active, "wait")?;
        if !self.sim_time() {
            let deadline = self.started + Duration::from_secs_f64(time_s.max(0.0));
            if let Some(d) = deadline.checked_duration_since(Instant::now()) {
                std::thread::sleep(d);
            }
            return Ok(());
        }
        // Stamps are rounded to the nanosecond: a state stamped within 1 µs of the tick is its.
        let due = time_s - 1e-6;
        let limit = Duration::from_secs_f64(self.config.watchdog.sim_clock_wait_s);
        // The tool wrench too, once the cell has one (a cell may have no wrist sensor).
        let reached = self.wait_for(limit, |c| {
            c.now_s() >= due
                && c.latest.joints.iter().flatten().all(|j| j.stamp_s >= due)
                && c.latest.peaks.is_some_and(|p| p.stamp_s >= due)
                && c.latest.tool_load_n.is_none_or(|t| t.stamp_s >= due)
        })?;
        if reached {
            return Ok(());
        }
        let io = self.io.as_ref().expect("an active cell has its node");
        let topic = if self.now_s() < due {
            io.clock.as_ref().map_or("/clock", |c| c.topic())
        } else if self.latest.peaks.is_some_and(|p| p.stamp_s < due) {
            io.peaks.topic()
        } else {
            io.joints.topic()
        };
        Err(device(
            topic,
            format!(
                "waited {:.1} s (wall clock) for t = {time_s:.3} s, the cell's clock is at {:.3} s: is the lock-step twin running?",
                self.config.watchdog.sim_clock_wait_s,
                self.now_s()
            ),
        ))
    }

    fn device_timing(&self) -> Option<DeviceTiming> {
        let w = self.config.watchdog;
        Some(DeviceTiming {
            sensor_age: Spread::of(&self.ages[1]),
            arm_age: Spread::of(&self.ages[0]),
            motor_age: Spread::of(&self.ages[0]),
            tick_late: Spread::default(),
            watchdog_ms: [w.peaks_stale_s * 1e3, w.joints_stale_s * 1e3, w.joints_stale_s * 1e3],
        })
    }

    fn sample_is_new(&self) -> bool {
        self.sample_new
    }
}
