//! Scenario section `[ros2]`: how tendril meets a lab's ROS 2 graph, as `tendril serve --ros2`
//! (the twin as the lab's drivers) and `tendril run --hardware ros2` (tendril's control on the
//! lab's drivers) use it. The defaults are what a Humble lab expects.
//!
//! ```toml
//! [ros2]
//! domain_id = 0                 # ROS_DOMAIN_ID
//! distro = "humble"             # or "jazzy" (the graph's Gid format)
//! localhost_only = true         # as ROS_LOCALHOST_ONLY=1
//! [ros2.topics]
//! joint_states = "/joint_states"
//! joint_commands = "/robot_joint_command"
//! [ros2.joints]
//! arm = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"]
//! ```

use serde::{Deserialize, Serialize};
use tendril_config::{Checker, Validate};
use tendril_ros2msg::graph::GidFormat;
use tendril_ros2msg::names;

/// The ROS 2 distribution of the lab's graph: what its tools expect of a participant's graph
/// information (the Gid's length) and of a bag's `metadata.yaml`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Distro {
    /// Humble Hawksbill (the paper's cell: ROS 2 Humble on Ubuntu 22.04).
    #[default]
    Humble,
    /// Iron Irwini.
    Iron,
    /// Jazzy Jalisco.
    Jazzy,
    /// Kilted Kaiju.
    Kilted,
}

impl Distro {
    /// The Gid format of `ros_discovery_info`.
    pub fn gid_format(self) -> GidFormat {
        if self == Distro::Humble { GidFormat::Humble } else { GidFormat::Iron }
    }

    /// The `metadata.yaml` version rosbag2 of this distribution writes (5 in Humble, 8 from
    /// Jazzy on; Iron's is 6). A newer rosbag2 reads the older versions.
    pub fn bag_version(self) -> u32 {
        match self {
            Distro::Humble => 5,
            Distro::Iron => 6,
            Distro::Jazzy | Distro::Kilted => 8,
        }
    }
}

/// How `tendril serve --ros2` keeps time.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum ClockMode {
    /// The twin runs in real time, as the devices do; `/clock` says where it is.
    #[default]
    Realtime,
    /// The twin advances one publish period for each command it receives on `joint_commands`,
    /// as fast as the commander and the twin go: `/clock` runs ahead of (or behind) the wall
    /// clock, and a commander with `use_sim_time` sees the same run every time.
    Lockstep,
}

/// A topic's quality of service (ROS 2's profile settings).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct QosProfile {
    /// `true`: reliable (every sample retransmitted until acknowledged); `false`: best effort.
    pub reliable: bool,
    /// History depth (keep last N) \[samples\], 1-1000.
    pub depth: u32,
}

impl QosProfile {
    /// ROS 2's default profile (`rmw_qos_profile_default`): reliable, volatile, keep last 10.
    pub const DEFAULT: QosProfile = QosProfile { reliable: true, depth: 10 };
    /// The clock's: keep last 1, reliable (a best-effort `use_sim_time` subscriber matches it).
    pub const CLOCK: QosProfile = QosProfile { reliable: true, depth: 1 };
}

/// The topics' quality of service.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct QosConfig {
    /// State topics (joint states, peaks, wrenches, ticks): ROS 2's default.
    pub state: QosProfile,
    /// The command topic: ROS 2's default.
    pub command: QosProfile,
    /// `/clock`: keep last 1.
    pub clock: QosProfile,
}

impl Default for QosConfig {
    fn default() -> Self {
        QosConfig { state: QosProfile::DEFAULT, command: QosProfile::DEFAULT, clock: QosProfile::CLOCK }
    }
}

/// The topics' names (absolute, or relative to `namespace`).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Topics {
    /// `sensor_msgs/msg/JointState`: the arm's six joints and the two MX-106 motors.
    pub joint_states: String,
    /// `sensor_msgs/msg/JointState` commands by joint name: position (or, for the motors,
    /// velocity). The default is the command topic of ros2_control's topic-based hardware
    /// interfaces (`joint_state_topic_hardware_interface`, `topic_based_ros2_control`), so a lab's
    /// controllers reach the twin with only the URDF's hardware plugin swapped.
    pub joint_commands: String,
    /// `rosgraph_msgs/msg/Clock`.
    pub clock: String,
    /// `tendril_msgs/msg/FbgPeaks`: every grating's peak wavelength.
    pub fbg_peaks: String,
    /// `geometry_msgs/msg/WrenchStamped`: a pad's eq. (8) force estimate as `force.z`, `{pad}`
    /// standing for the pad's number (0 is the paper's pad).
    pub fbg_wrench: String,
    /// `geometry_msgs/msg/WrenchStamped`: the arm's wrist force sensor, as the UR driver's
    /// force/torque broadcaster publishes it (the external force on the tool, base frame).
    pub tool_wrench: String,
    /// `tendril_msgs/msg/ControlTick`: the control side's record of each tick (in bags).
    pub control_tick: String,
}

impl Default for Topics {
    fn default() -> Self {
        Topics {
            joint_states: "/joint_states".into(),
            joint_commands: "/robot_joint_command".into(),
            clock: "/clock".into(),
            fbg_peaks: "/fbg/peaks".into(),
            fbg_wrench: "/fbg/pad{pad}/wrench".into(),
            tool_wrench: "/force_torque_sensor_broadcaster/wrench".into(),
            control_tick: "/tendril/control_tick".into(),
        }
    }
}

impl Topics {
    /// Pad `pad`'s wrench topic.
    pub fn fbg_wrench_of(&self, pad: usize) -> String {
        self.fbg_wrench.replace("{pad}", &pad.to_string())
    }
}

/// The joints' names in `JointState` messages.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct JointNames {
    /// The arm's six, base to wrist: Universal Robots' description's names (`ur_description`,
    /// with an empty `tf_prefix`).
    pub arm: [String; 6],
    /// The growth motor (the MX-106 that feeds the strip out).
    pub growth: String,
    /// The twine motor (the MX-106 that pulls the curl tendon).
    pub twine: String,
}

impl Default for JointNames {
    fn default() -> Self {
        JointNames {
            arm: [
                "shoulder_pan_joint",
                "shoulder_lift_joint",
                "elbow_joint",
                "wrist_1_joint",
                "wrist_2_joint",
                "wrist_3_joint",
            ]
            .map(String::from),
            growth: "growth_motor_joint".into(),
            twine: "twine_motor_joint".into(),
        }
    }
}

impl JointNames {
    /// All eight, arm first, then growth and twine.
    pub fn all(&self) -> Vec<&str> {
        self.arm.iter().map(String::as_str).chain([self.growth.as_str(), self.twine.as_str()]).collect()
    }
}

/// Highest ROS domain id \[-\]: 232, the largest whose RTPS ports (7400 + 250 × id + offsets)
/// stay below 65 536 (ROS 2's "The ROS_DOMAIN_ID" concept page; 101 is its advice on Linux for
/// staying clear of ephemeral ports).
pub const MAX_DOMAIN_ID: u16 = 232;

/// Section `[ros2]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Ros2Config {
    /// ROS domain id \[-\] (`ROS_DOMAIN_ID`), 0-232: participants meet only within one domain.
    pub domain_id: u16,
    /// The lab's ROS 2 distribution (`humble`, `iron`, `jazzy`, `kilted`).
    pub distro: Distro,
    /// Reach only participants on this machine (as `ROS_LOCALHOST_ONLY=1`): discovery and data on
    /// loopback. `false`: every network interface, as a lab's machines need.
    pub localhost_only: bool,
    /// The node's namespace.
    pub namespace: String,
    /// The node's name (`tendril_twin` for `serve`, `tendril` for `run`).
    pub node_name: String,
    /// How often `tendril serve --ros2` publishes the state topics and `/clock` \[Hz\], 1-1000:
    /// 100 Hz, the scenarios' control rate (the UR driver's joint states come at 500 Hz, the
    /// interrogator samples at 1 kHz; a faster rate costs CPU and bandwidth, not accuracy, at a
    /// 100 Hz loop).
    pub publish_rate_hz: f64,
    /// How `tendril serve --ros2` keeps time: `realtime` or `lockstep`.
    pub clock: ClockMode,
    /// Whether `tendril run --hardware ros2` keeps the cell's time from `/clock` (as a ROS node
    /// with `use_sim_time`) instead of the wall clock: needed against a lock-step twin.
    pub use_sim_time: bool,
    /// Topic names.
    pub topics: Topics,
    /// Joint names.
    pub joints: JointNames,
    /// Quality of service.
    pub qos: QosConfig,
}

impl Default for Ros2Config {
    fn default() -> Self {
        Ros2Config {
            domain_id: 0,
            distro: Distro::default(),
            localhost_only: true,
            namespace: "/".into(),
            node_name: "tendril".into(),
            publish_rate_hz: 100.0,
            clock: ClockMode::default(),
            use_sim_time: false,
            topics: Topics::default(),
            joints: JointNames::default(),
            qos: QosConfig::default(),
        }
    }
}

impl Ros2Config {
    /// Whether it is all defaults (a scenario without `[ros2]` records none).
    pub fn is_default(&self) -> bool {
        *self == Ros2Config::default()
    }

    /// `topic` resolved in the namespace (the names are checked by validation).
    pub fn resolve(&self, topic: &str) -> String {
        names::resolve_topic(topic, &self.namespace).unwrap_or_else(|_| topic.to_string())
    }
}

impl Validate for Ros2Config {
    fn validate(&self, at: &mut Checker) {
        at.require("domain_id", self.domain_id <= MAX_DOMAIN_ID, || {
            format!("must be 0-{MAX_DOMAIN_ID} (its RTPS ports must stay below 65536), got {}", self.domain_id)
        });
        if let Err(e) = names::namespace(&self.namespace) {
            at.require("namespace", false, || e.to_string());
        }
        if let Err(e) = names::node_name(&self.node_name) {
            at.require("node_name", false, || e.to_string());
        }
        at.in_range("publish_rate_hz", self.publish_rate_hz, 1.0, 1000.0);
        let t = &self.topics;
        for (key, name) in [
            ("topics.joint_states", &t.joint_states),
            ("topics.joint_commands", &t.joint_commands),
            ("topics.clock", &t.clock),
            ("topics.fbg_peaks", &t.fbg_peaks),
            ("topics.tool_wrench", &t.tool_wrench),
            ("topics.control_tick", &t.control_tick),
        ] {
            if let Err(e) = names::resolve_topic(name, &self.namespace) {
                at.require(key, false, || e.to_string());
            }
        }
        at.require("topics.fbg_wrench", t.fbg_wrench.contains("{pad}"), || {
            format!("`{}` must contain `{{pad}}` (each pad has its own topic)", t.fbg_wrench)
        });
        if let Err(e) = names::resolve_topic(&t.fbg_wrench_of(0), &self.namespace) {
            at.require("topics.fbg_wrench", false, || e.to_string());
        }
        let all = self.joints.all();
        for (i, name) in all.iter().enumerate() {
            at.require("joints", !name.is_empty() && !all[..i].contains(name), || {
                format!("joint names must be non-empty and distinct: `{name}` is empty or repeated")
            });
        }
        for (key, q) in
            [("qos.state", self.qos.state), ("qos.command", self.qos.command), ("qos.clock", self.qos.clock)]
        {
            at.require(&format!("{key}.depth"), (1..=1000).contains(&q.depth), || {
                format!("must be 1-1000 samples, got {}", q.depth)
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn first_error(c: &Ros2Config) -> Option<(String, String)> {
        let mut at = Checker::default();
        c.validate(&mut at);
        at.into_first_error()
    }

    #[test]
    fn the_defaults_are_valid_and_bad_values_name_their_key() {
        assert_eq!(first_error(&Ros2Config::default()), None);
        let d = Ros2Config::default();
        let key = |c: Ros2Config| first_error(&c).map(|(k, _)| k);
        assert_eq!(key(Ros2Config { domain_id: 233, ..d.clone() }).as_deref(), Some("domain_id"));
        assert_eq!(key(Ros2Config { namespace: "lab".into(), ..d.clone() }).as_deref(), Some("namespace"));
        assert_eq!(key(Ros2Config { publish_rate_hz: 0.0, ..d.clone() }).as_deref(), Some("publish_rate_hz"));
        let mut c = d.clone();
        c.topics.joint_states = "/joint states".into();
        let (k, why) = first_error(&c).unwrap();
        assert_eq!(k, "topics.joint_states");
        assert!(why.contains("not a valid ROS 2 topic name"), "{why}");
        let mut c = d.clone();
        c.topics.fbg_wrench = "/fbg/wrench".into();
        assert_eq!(key(c).as_deref(), Some("topics.fbg_wrench"));
        let mut c = d.clone();
        c.joints.twine = c.joints.growth.clone();
        assert_eq!(key(c).as_deref(), Some("joints"));
        let mut c = d;
        c.qos.command.depth = 0;
        assert_eq!(key(c).as_deref(), Some("qos.command.depth"));
    }

    #[test]
    fn topics_resolve_in_the_namespace() {
        let c = Ros2Config { namespace: "/cell_1".into(), ..Ros2Config::default() };
        assert_eq!(c.resolve("joint_states"), "/cell_1/joint_states");
        assert_eq!(c.resolve(&c.topics.fbg_wrench_of(2)), "/fbg/pad2/wrench");
        assert_eq!(Distro::Jazzy.gid_format(), GidFormat::Iron);
    }
}
