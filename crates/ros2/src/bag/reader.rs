//! [`read_bag`]: every message of a rosbag2 bag, MCAP or sqlite3 storage, in time order.

use super::BagError;
use std::path::{Path, PathBuf};

/// One recorded message.
#[derive(Debug, Clone, PartialEq)]
pub struct BagMessage {
    /// Its topic.
    pub topic: String,
    /// Its type (`sensor_msgs/msg/JointState`).
    pub type_name: String,
    /// When it was recorded \[ns\].
    pub time_ns: u64,
    /// The serialized message (encapsulation header and CDR body).
    pub payload: Vec<u8>,
}

/// The storage files of `path`: a bag's folder (its `.mcap` or `.db3` files, in name order), or
/// one such file.
fn storage_files(path: &Path) -> Result<Vec<PathBuf>, BagError> {
    if path.is_file() {
        return Ok(vec![path.into()]);
    }
    if !path.is_dir() {
        return Err(BagError::new(path, "no such bag (a rosbag2 folder, or one of its .mcap or .db3 files)"));
    }
    let mut files: Vec<PathBuf> = std::fs::read_dir(path)
        .map_err(|e| BagError::new(path, format!("cannot read: {e}")))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| matches!(p.extension().and_then(|e| e.to_str()), Some("mcap" | "db3")))
        .collect();
    files.sort();
    if files.is_empty() {
        return Err(BagError::new(path, "holds no .mcap or .db3 file: not a rosbag2 bag"));
    }
    Ok(files)
}

/// Every message of the bag at `path`, in time order, with `topics` only when given.
pub fn read_bag(path: &Path, topics: Option<&[&str]>) -> Result<Vec<BagMessage>, BagError> {
    let mut out = Vec::new();
    for file in storage_files(path)? {
        match file.extension().and_then(|e| e.to_str()) {
            Some("db3") => read_sqlite(&file, topics, &mut out)?,
            Some("mcap") => read_mcap(&file, topics, &mut out)?,
            _ => return Err(BagError::new(&file, "neither .mcap nor .db3: not a rosbag2 storage file")),
        }
    }
    out.sort_by_key(|m| m.time_ns);
    Ok(out)
}

fn wanted(topics: Option<&[&str]>, topic: &str) -> bool {
    topics.is_none_or(|t| t.contains(&topic))
}

fn read_mcap(file: &Path, topics: Option<&[&str]>, out: &mut Vec<BagMessage>) -> Result<(), BagError> {
    let bytes = std::fs::read(file).map_err(|e| BagError::new(file, format!("cannot read: {e}")))?;
    let stream =
        mcap::MessageStream::new(&bytes).map_err(|e| BagError::new(file, format!("not a readable MCAP file: {e}")))?;
    for message in stream {
        let m = message.map_err(|e| BagError::new(file, format!("truncated or corrupt MCAP file: {e}")))?;
        if !wanted(topics, &m.channel.topic) {
            continue;
        }
        let type_name = m.channel.schema.as_ref().map_or_else(String::new, |s| s.name.clone());
        out.push(BagMessage {
            topic: m.channel.topic.clone(),
            type_name,
            time_ns: m.log_time,
            payload: m.data.into_owned(),
        });
    }
    Ok(())
}

fn read_sqlite(file: &Path, topics: Option<&[&str]>, out: &mut Vec<BagMessage>) -> Result<(), BagError> {
    let err = |e: rusqlite::Error| BagError::new(file, format!("not a readable rosbag2 sqlite3 file: {e}"));
    let db = rusqlite::Connection::open_with_flags(file, rusqlite::OpenFlags::SQLITE_OPEN_READ_ONLY).map_err(err)?;
    let mut query = db
        .prepare(
            "SELECT topics.name, topics.type, messages.timestamp, messages.data \
             FROM messages JOIN topics ON messages.topic_id = topics.id ORDER BY messages.timestamp",
        )
        .map_err(err)?;
    let rows = query
        .query_map([], |r| {
            Ok(BagMessage {
                topic: r.get(0)?,
                type_name: r.get(1)?,
                time_ns: r.get::<_, i64>(2)? as u64,
                payload: r.get(3)?,
            })
        })
        .map_err(err)?;
    for row in rows {
        let m = row.map_err(err)?;
        if wanted(topics, &m.topic) {
            out.push(m);
        }
    }
    Ok(())
}
