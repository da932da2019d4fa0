//! The standard messages tendril uses: time, headers, the clock, joint states, wrenches, strings.

use crate::cdr::{CdrError, CdrReader, CdrWriter};
use crate::message::{Message, TypeInfo};

/// `builtin_interfaces/msg/Time`: a time in seconds and nanoseconds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, PartialOrd, Ord)]
pub struct Time {
    /// Whole seconds.
    pub sec: i32,
    /// Nanoseconds, 0-999 999 999.
    pub nanosec: u32,
}

impl Time {
    /// Its type.
    pub const INFO: TypeInfo =
        TypeInfo { name: "builtin_interfaces/msg/Time", definition: "int32 sec\nuint32 nanosec\n", nested: &[] };

    /// `t` \[s\], rounded to the nanosecond (clamped to what `int32` seconds hold).
    pub fn from_secs_f64(t: f64) -> Time {
        let ns = (t * 1e9).round().clamp(i32::MIN as f64 * 1e9, (i32::MAX as f64 + 1.0) * 1e9 - 1.0) as i64;
        Time { sec: ns.div_euclid(1_000_000_000) as i32, nanosec: ns.rem_euclid(1_000_000_000) as u32 }
    }

    /// Nanoseconds since zero.
    pub fn as_nanos(&self) -> i64 {
        i64::from(self.sec) * 1_000_000_000 + i64::from(self.nanosec)
    }

    /// Seconds since zero.
    pub fn as_secs_f64(&self) -> f64 {
        f64::from(self.sec) + f64::from(self.nanosec) * 1e-9
    }

    fn encode(&self, w: &mut CdrWriter) {
        w.i32(self.sec);
        w.u32(self.nanosec);
    }

    fn decode(r: &mut CdrReader<'_>) -> Result<Time, CdrError> {
        Ok(Time { sec: r.i32("stamp.sec")?, nanosec: r.u32("stamp.nanosec")? })
    }
}

/// `std_msgs/msg/Header`: when and in which frame a measurement was taken.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Header {
    /// When.
    pub stamp: Time,
    /// The frame (`base_link`, `tool0`, ...).
    pub frame_id: String,
}

impl Header {
    /// Its type.
    pub const INFO: TypeInfo = TypeInfo {
        name: "std_msgs/msg/Header",
        definition: "builtin_interfaces/Time stamp\nstring frame_id\n",
        nested: &[Time::INFO],
    };

    /// A header at `t` \[s\] in `frame_id`.
    pub fn at(t: f64, frame_id: &str) -> Header {
        Header { stamp: Time::from_secs_f64(t), frame_id: frame_id.into() }
    }

    pub(crate) fn encode(&self, w: &mut CdrWriter) {
        self.stamp.encode(w);
        w.string(&self.frame_id);
    }

    pub(crate) fn decode(r: &mut CdrReader<'_>) -> Result<Header, CdrError> {
        Ok(Header { stamp: Time::decode(r)?, frame_id: r.string("header.frame_id")? })
    }
}

/// `rosgraph_msgs/msg/Clock`: the simulated time, which nodes with `use_sim_time` follow.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Clock {
    /// The time.
    pub clock: Time,
}

impl Message for Clock {
    const TYPE: TypeInfo = TypeInfo {
        name: "rosgraph_msgs/msg/Clock",
        definition: "builtin_interfaces/Time clock\n",
        nested: &[Time::INFO],
    };
    fn encode(&self, w: &mut CdrWriter) {
        self.clock.encode(w);
    }
    fn decode(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(Clock { clock: Time::decode(r)? })
    }
}

/// `sensor_msgs/msg/JointState`: joints by name, each with its position, velocity and effort (a
/// list may be empty: not measured).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct JointState {
    /// Stamp and frame.
    pub header: Header,
    /// The joints' names.
    pub name: Vec<String>,
    /// Positions \[rad\] (or \[m\] for a prismatic joint).
    pub position: Vec<f64>,
    /// Velocities \[rad/s\].
    pub velocity: Vec<f64>,
    /// Efforts \[N·m\].
    pub effort: Vec<f64>,
}

impl Message for JointState {
    const TYPE: TypeInfo = TypeInfo {
        name: "sensor_msgs/msg/JointState",
        definition: "std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\nfloat64[] effort\n",
        nested: &[Header::INFO],
    };
    fn encode(&self, w: &mut CdrWriter) {
        self.header.encode(w);
        w.strings(&self.name);
        w.f64s(&self.position);
        w.f64s(&self.velocity);
        w.f64s(&self.effort);
    }
    fn decode(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(JointState {
            header: Header::decode(r)?,
            name: r.strings("name")?,
            position: r.f64s("position")?,
            velocity: r.f64s("velocity")?,
            effort: r.f64s("effort")?,
        })
    }
}

/// `geometry_msgs/msg/Vector3`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Vector3 {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
}

impl Vector3 {
    /// Its type.
    pub const INFO: TypeInfo =
        TypeInfo { name: "geometry_msgs/msg/Vector3", definition: "float64 x\nfloat64 y\nfloat64 z\n", nested: &[] };

    fn encode(&self, w: &mut CdrWriter) {
        w.f64(self.x);
        w.f64(self.y);
        w.f64(self.z);
    }

    fn decode(r: &mut CdrReader<'_>) -> Result<Vector3, CdrError> {
        Ok(Vector3 { x: r.f64("x")?, y: r.f64("y")?, z: r.f64("z")? })
    }
}

/// `geometry_msgs/msg/Wrench`: a force \[N\] and a torque \[N·m\].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Wrench {
    /// Force \[N\].
    pub force: Vector3,
    /// Torque \[N·m\].
    pub torque: Vector3,
}

impl Wrench {
    /// Its type.
    pub const INFO: TypeInfo = TypeInfo {
        name: "geometry_msgs/msg/Wrench",
        definition: "Vector3 force\nVector3 torque\n",
        nested: &[Vector3::INFO],
    };
}

/// `geometry_msgs/msg/WrenchStamped`: a wrench in a frame at a time (a force/torque sensor's
/// reading).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct WrenchStamped {
    /// Stamp and frame.
    pub header: Header,
    /// The wrench.
    pub wrench: Wrench,
}

impl WrenchStamped {
    /// A pure force along the frame's z axis \[N\] at `t` \[s\].
    pub fn force_z(t: f64, frame_id: &str, force_n: f64) -> WrenchStamped {
        WrenchStamped {
            header: Header::at(t, frame_id),
            wrench: Wrench { force: Vector3 { z: force_n, ..Vector3::default() }, torque: Vector3::default() },
        }
    }
}

impl Message for WrenchStamped {
    const TYPE: TypeInfo = TypeInfo {
        name: "geometry_msgs/msg/WrenchStamped",
        definition: "std_msgs/Header header\nWrench wrench\n",
        nested: &[Header::INFO, Wrench::INFO],
    };
    fn encode(&self, w: &mut CdrWriter) {
        self.header.encode(w);
        self.wrench.force.encode(w);
        self.wrench.torque.encode(w);
    }
    fn decode(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(WrenchStamped {
            header: Header::decode(r)?,
            wrench: Wrench { force: Vector3::decode(r)?, torque: Vector3::decode(r)? },
        })
    }
}

/// `std_msgs/msg/String`: a text (a lab's task node may publish its phase as one).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct StringMsg {
    /// The text.
    pub data: String,
}

impl Message for StringMsg {
    const TYPE: TypeInfo = TypeInfo { name: "std_msgs/msg/String", definition: "string data\n", nested: &[] };
    fn encode(&self, w: &mut CdrWriter) {
        w.string(&self.data);
    }
    fn decode(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(StringMsg { data: r.string("data")? })
    }
}
