//! `metadata.yaml`, the bag's table of contents, as rosbag2 writes it.

use crate::config::{Distro, QosProfile};

/// One topic's line in the table.
pub struct TopicMeta<'a> {
    pub name: &'a str,
    pub type_name: &'a str,
    pub qos: QosProfile,
    pub count: u64,
}

/// The offered QoS profile as rosbag2 stores it (a YAML list in a string; versions up to 8 write
/// rmw's enum numbers: history 1 keep last, reliability 1 reliable / 2 best effort, durability 2
/// volatile, liveliness 1 automatic; the unset durations as their maxima).
pub fn offered_qos(qos: QosProfile) -> String {
    let never = "\n    sec: 2147483647\n    nsec: 4294967295";
    format!(
        "- history: 1\n  depth: {}\n  reliability: {}\n  durability: 2\n  deadline:{never}\n  lifespan:{never}\n  liveliness: 1\n  liveliness_lease_duration:{never}\n  avoid_ros_namespace_conventions: false",
        qos.depth,
        if qos.reliable { 1 } else { 2 }
    )
}

/// A YAML double-quoted string.
fn quoted(s: &str) -> String {
    format!("\"{}\"", s.replace('\\', "\\\\").replace('"', "\\\"").replace('\n', "\\n"))
}

/// The text of `metadata.yaml` for a bag of one MCAP file `file` whose messages span
/// `start_ns`..`start_ns + duration_ns`.
pub fn metadata_yaml(distro: Distro, file: &str, start_ns: u64, duration_ns: u64, topics: &[TopicMeta<'_>]) -> String {
    let version = distro.bag_version();
    let count: u64 = topics.iter().map(|t| t.count).sum();
    let mut y = format!(
        "rosbag2_bagfile_information:\n  version: {version}\n  storage_identifier: mcap\n  duration:\n    nanoseconds: {duration_ns}\n  starting_time:\n    nanoseconds_since_epoch: {start_ns}\n  message_count: {count}\n  topics_with_message_count:\n"
    );
    for t in topics {
        y.push_str(&format!(
            "    - topic_metadata:\n        name: {}\n        type: {}\n        serialization_format: cdr\n        offered_qos_profiles: {}\n",
            t.name,
            t.type_name,
            quoted(&offered_qos(t.qos))
        ));
        if version >= 7 {
            // The type's RIHS01 hash is left empty: rosbag2 and rosbags read a bag without it.
            y.push_str("        type_description_hash: \"\"\n");
        }
        y.push_str(&format!("      message_count: {}\n", t.count));
    }
    y.push_str(&format!(
        "  compression_format: \"\"\n  compression_mode: \"\"\n  relative_file_paths:\n    - {file}\n  files:\n    - path: {file}\n      starting_time:\n        nanoseconds_since_epoch: {start_ns}\n      duration:\n        nanoseconds: {duration_ns}\n      message_count: {count}\n"
    ));
    if version >= 6 {
        y.push_str("  custom_data: {}\n");
    }
    if version >= 8 {
        y.push_str(&format!("  ros_distro: {}\n", format!("{distro:?}").to_lowercase()));
    }
    y
}
