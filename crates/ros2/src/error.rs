//! What can go wrong on the ROS 2 side.

/// A ROS 2 failure, naming the topic where there is one.
#[derive(Debug, thiserror::Error)]
pub enum Ros2Error {
    /// The DDS participant or an endpoint could not be created (a port in use, no network).
    #[error("ROS 2 (DDS domain {domain}): {what}: {cause}")]
    Dds {
        /// The domain.
        domain: u16,
        /// What was being created.
        what: String,
        /// RustDDS's reason.
        cause: String,
    },
    /// A message on `topic` could not be decoded as its type.
    #[error("topic {topic}: malformed {type_name}: {cause}")]
    Malformed {
        /// The topic.
        topic: String,
        /// The type expected.
        type_name: &'static str,
        /// What is wrong.
        cause: tendril_ros2msg::CdrError,
    },
    /// A publish failed.
    #[error("topic {topic}: cannot publish: {cause}")]
    Publish {
        /// The topic.
        topic: String,
        /// RustDDS's reason.
        cause: String,
    },
    /// A name in the configuration is not a ROS 2 name.
    #[error(transparent)]
    Name(#[from] tendril_ros2msg::names::NameError),
}
