//! The ROS 2 package `ros2/tendril_msgs` (what a lab builds to echo tendril's own messages live)
//! declares the same fields as the messages tendril puts on the wire and in its bags.

use tendril_ros2msg::{ControlTick, FbgPeaks, Message, TypeInfo};

/// The field lines of a `.msg` text: comments and blank lines left out.
fn fields(text: &str) -> Vec<String> {
    text.lines()
        .map(|l| l.split('#').next().unwrap_or_default().trim())
        .filter(|l| !l.is_empty())
        .map(|l| l.split_whitespace().collect::<Vec<_>>().join(" "))
        .collect()
}

#[test]
fn the_packages_messages_are_the_wires() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("ros2/tendril_msgs/msg");
    for (file, info) in [("FbgPeaks.msg", FbgPeaks::TYPE), ("ControlTick.msg", ControlTick::TYPE)] {
        let text = std::fs::read_to_string(root.join(file)).unwrap();
        assert_eq!(fields(&text), fields(info.definition), "{file}");
        let TypeInfo { name, .. } = info;
        assert_eq!(name, format!("tendril_msgs/msg/{}", file.trim_end_matches(".msg")));
    }
}
