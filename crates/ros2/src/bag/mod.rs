//! rosbag2 bags: [`BagWriter`] records topics into a bag with MCAP storage (`metadata.yaml` and
//! one `.mcap` file, as `ros2 bag record -s mcap` writes them), and [`read_bag`] reads a bag
//! with MCAP or sqlite3 storage (Humble's default), without a ROS installation.

mod metadata;
mod reader;
mod recorder;
mod writer;

pub use reader::{BagMessage, read_bag};
pub use recorder::{CellRecorder, time_ns};
pub use writer::{BagSummary, BagWriter, TopicId};

/// Why a bag could not be written or read; names the file.
#[derive(Debug, thiserror::Error)]
#[error("{}: {reason}", path.display())]
pub struct BagError {
    /// The bag's folder or file at fault.
    pub path: std::path::PathBuf,
    /// What is wrong.
    pub reason: String,
}

impl BagError {
    pub(crate) fn new(path: &std::path::Path, reason: impl std::fmt::Display) -> BagError {
        BagError { path: path.into(), reason: reason.to_string() }
    }
}
