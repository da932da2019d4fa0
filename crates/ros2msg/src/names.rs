//! ROS 2 names: what a topic or node name may be, how a relative one is resolved in a
//! namespace, and how ROS 2's middleware names topics in DDS (`/joint_states` is the DDS topic
//! `rt/joint_states`).

/// Why a name is not a valid ROS 2 name.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("`{name}` is not a valid ROS 2 {what}: {reason}")]
pub struct NameError {
    /// The name given.
    pub name: String,
    /// "topic name", "namespace", "node name".
    pub what: &'static str,
    /// Why not.
    pub reason: &'static str,
}

/// Longest DDS topic name tendril makes \[bytes\]: ROS 2 refuses topic names whose DDS form is
/// longer than 255 characters (rmw's `RMW_TOPIC_MAX_NAME_LENGTH`, 256 with the NUL).
pub const MAX_DDS_TOPIC_LEN: usize = 255;

fn token_ok(t: &str) -> bool {
    let mut chars = t.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// Checks a namespace (`/`, `/lab`, `/lab/cell_1`) and returns it.
pub fn namespace(ns: &str) -> Result<&str, NameError> {
    let err = |reason| NameError { name: ns.into(), what: "namespace", reason };
    if !ns.starts_with('/') {
        return Err(err("a namespace starts with `/`"));
    }
    if ns == "/" {
        return Ok(ns);
    }
    if ns.ends_with('/') {
        return Err(err("a namespace other than `/` does not end with `/`"));
    }
    if !ns[1..].split('/').all(token_ok) {
        return Err(err("each part is letters, digits and `_`, not starting with a digit"));
    }
    Ok(ns)
}

/// Checks a node name (`tendril`).
pub fn node_name(name: &str) -> Result<&str, NameError> {
    if token_ok(name) {
        Ok(name)
    } else {
        Err(NameError {
            name: name.into(),
            what: "node name",
            reason: "letters, digits and `_`, not starting with a digit",
        })
    }
}

/// `topic` fully qualified in namespace `ns`: an absolute name (`/joint_states`) as it is, a
/// relative one (`joint_states`) under `ns`. Refused: empty parts, characters outside letters,
/// digits and `_`, parts starting with a digit, `~` and `{}` substitutions, a DDS name over
/// [`MAX_DDS_TOPIC_LEN`].
pub fn resolve_topic(topic: &str, ns: &str) -> Result<String, NameError> {
    let err = |reason| NameError { name: topic.into(), what: "topic name", reason };
    let ns = namespace(ns)?;
    let full = if topic.starts_with('/') {
        topic.to_string()
    } else if ns == "/" {
        format!("/{topic}")
    } else {
        format!("{ns}/{topic}")
    };
    if topic.is_empty() || topic == "/" {
        return Err(err("empty"));
    }
    if topic.contains(['~', '{', '}']) {
        return Err(err("`~` and `{}` substitutions are not supported here: write the name out"));
    }
    if full.ends_with('/') {
        return Err(err("ends with `/`"));
    }
    if !full[1..].split('/').all(token_ok) {
        return Err(err("each part is letters, digits and `_`, not starting with a digit"));
    }
    if dds_topic(&full).len() > MAX_DDS_TOPIC_LEN {
        return Err(err("longer than ROS 2 allows (255 characters in DDS)"));
    }
    Ok(full)
}

/// The DDS topic of a fully qualified ROS 2 topic: `rt` in front (ROS 2's prefix for topics).
pub fn dds_topic(full: &str) -> String {
    format!("rt{full}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_resolve_as_ros_2_resolves_them() {
        assert_eq!(resolve_topic("/joint_states", "/lab").unwrap(), "/joint_states");
        assert_eq!(resolve_topic("joint_states", "/lab").unwrap(), "/lab/joint_states");
        assert_eq!(resolve_topic("fbg/pad0/wrench", "/").unwrap(), "/fbg/pad0/wrench");
        assert_eq!(dds_topic("/joint_states"), "rt/joint_states");
        for bad in ["", "/", "/a//b", "/a/", "/0abc", "/a-b", "~/x", "/{node}/x", "/a b"] {
            let e = resolve_topic(bad, "/").unwrap_err();
            assert!(e.to_string().starts_with(&format!("`{bad}` is not a valid ROS 2 topic name")), "{e}");
        }
        assert!(resolve_topic(&format!("/{}", "a".repeat(260)), "/").is_err());
        assert!(namespace("lab").is_err() && namespace("/lab/").is_err() && namespace("/").is_ok());
        assert!(node_name("tendril").is_ok() && node_name("9lives").is_err() && node_name("a/b").is_err());
    }
}
