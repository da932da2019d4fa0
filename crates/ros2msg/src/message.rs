//! What every message type gives: its ROS 2 name, its `.msg` definition (with the types it nests,
//! for a bag's schema), and its CDR encoding.

use crate::cdr::{CDR_LE_HEADER, CdrError, CdrReader, CdrWriter};

/// A ROS 2 message type's name and definition.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TypeInfo {
    /// The type's full name, `package/msg/Name` (`sensor_msgs/msg/JointState`).
    pub name: &'static str,
    /// Its `.msg` text, field per line, as ROS 2 ships it (comments left out).
    pub definition: &'static str,
    /// The message types its fields use, directly.
    pub nested: &'static [TypeInfo],
}

/// The line rosbag2 and MCAP put between the definitions of a schema's types.
pub const SCHEMA_SEPARATOR: &str = "================================================================================";

impl TypeInfo {
    /// The DDS type name ROS 2's middleware registers (`sensor_msgs::msg::dds_::JointState_`): what a
    /// participant without ROS must name the type for a ROS 2 node to match it.
    pub fn dds_name(&self) -> String {
        let mut parts: Vec<&str> = self.name.split('/').collect();
        let last = parts.pop().unwrap_or_default();
        format!("{}::dds_::{last}_", parts.join("::"))
    }

    /// The package (`sensor_msgs`).
    pub fn package(&self) -> &'static str {
        self.name.split('/').next().unwrap_or_default()
    }

    /// The definition text a bag's schema carries (MCAP encoding `ros2msg`, rosbag2's
    /// `type_description`): this type's `.msg`, then every type it nests, depth-first, each once,
    /// after a separator line and `MSG: package/Name` (the layout rosbag2 writes).
    pub fn schema(&self) -> String {
        let mut seen: Vec<&'static str> = vec![self.name];
        let mut text = self.definition.to_string();
        fn nested(t: &TypeInfo, seen: &mut Vec<&'static str>, text: &mut String) {
            for n in t.nested {
                if seen.contains(&n.name) {
                    continue;
                }
                seen.push(n.name);
                let short = n.name.replacen("/msg/", "/", 1);
                text.push_str(&format!("{SCHEMA_SEPARATOR}\nMSG: {short}\n{}", n.definition));
                nested(n, seen, text);
            }
        }
        nested(self, &mut seen, &mut text);
        text
    }
}

/// A message tendril publishes, subscribes to or records.
pub trait Message: Sized {
    /// Its type.
    const TYPE: TypeInfo;
    /// Writes its fields, in the definition's order.
    fn encode(&self, w: &mut CdrWriter);
    /// Reads its fields, in the definition's order.
    fn decode(r: &mut CdrReader<'_>) -> Result<Self, CdrError>;
}

/// `m`'s CDR body (no encapsulation header): what a DDS writer hands to RTPS.
pub fn to_body<M: Message>(m: &M) -> Vec<u8> {
    let mut w = CdrWriter::new();
    m.encode(&mut w);
    w.into_bytes()
}

/// `m` as a serialized message: the little-endian encapsulation header and its CDR body, as
/// rosbag2 stores it.
pub fn to_payload<M: Message>(m: &M) -> Vec<u8> {
    let mut payload = CDR_LE_HEADER.to_vec();
    payload.extend(to_body(m));
    payload
}

/// A message from its CDR body (little-endian). Trailing bytes (a body's padding to four bytes)
/// are allowed.
pub fn from_body<M: Message>(body: &[u8]) -> Result<M, CdrError> {
    M::decode(&mut CdrReader::new(body))
}

/// A message from a serialized message (encapsulation header and body, either byte order).
pub fn from_payload<M: Message>(payload: &[u8]) -> Result<M, CdrError> {
    M::decode(&mut CdrReader::with_header(payload)?)
}
