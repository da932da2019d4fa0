//! [`BagWriter`]: a rosbag2 bag with MCAP storage, written as the messages come.

use super::BagError;
use super::metadata::{TopicMeta, metadata_yaml, offered_qos};
use crate::config::{Distro, QosProfile};
use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use tendril_ros2msg::{Message, to_payload};

/// Bytes of messages collected into one MCAP chunk before it is written \[bytes\]: 64 KiB, about
/// 0.6 s of a run's topics at 100 Hz, so a process killed outright loses about as much of the bag
/// as of `trace.csv` (whose buffer holds 0.7 s); Foxglove seeks by these chunks' indexes.
pub const CHUNK_BYTES: u64 = 64 * 1024;

/// A topic added to a bag.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TopicId(usize);

struct Topic {
    name: String,
    type_name: &'static str,
    qos: QosProfile,
    channel: u16,
    count: u64,
}

/// What a finished bag holds.
#[derive(Debug, Clone, PartialEq)]
pub struct BagSummary {
    /// The bag's folder.
    pub dir: PathBuf,
    /// Messages written.
    pub messages: u64,
    /// Topics, with their message counts.
    pub topics: Vec<(String, u64)>,
}

/// A rosbag2 bag being written: `DIR/metadata.yaml` (at [`BagWriter::finish`]) and
/// `DIR/<name>_0.mcap` (as the messages come, profile `ros2`, schemas `ros2msg`, messages CDR).
pub struct BagWriter {
    dir: PathBuf,
    file: String,
    distro: Distro,
    mcap: mcap::Writer<BufWriter<File>>,
    topics: Vec<Topic>,
    span_ns: Option<(u64, u64)>,
    sequence: u32,
}

impl BagWriter {
    /// Creates the bag's folder `dir` (its parent must exist) for `distro`'s rosbag2. A folder
    /// that exists is refused, so nothing is overwritten.
    pub fn create(dir: &Path, distro: Distro) -> Result<BagWriter, BagError> {
        if dir.exists() {
            return Err(BagError::new(
                dir,
                "exists: a bag is never written over (move it away or choose another folder)",
            ));
        }
        std::fs::create_dir(dir).map_err(|e| BagError::new(dir, format!("cannot create: {e}")))?;
        let base = dir.file_name().map_or_else(|| "bag".into(), |n| n.to_string_lossy().into_owned());
        let file = format!("{base}_0.mcap");
        let path = dir.join(&file);
        let out = File::create(&path).map_err(|e| BagError::new(&path, format!("cannot create: {e}")))?;
        let mcap = mcap::WriteOptions::new()
            .profile("ros2")
            .library(concat!("tendril ", env!("CARGO_PKG_VERSION")))
            .compression(None)
            .chunk_size(Some(CHUNK_BYTES))
            .create(BufWriter::new(out))
            .map_err(|e| BagError::new(&path, format!("cannot start the MCAP file: {e}")))?;
        Ok(BagWriter { dir: dir.into(), file, distro, mcap, topics: Vec::new(), span_ns: None, sequence: 0 })
    }

    fn mcap_error(&self, e: impl std::fmt::Display) -> BagError {
        BagError::new(&self.dir.join(&self.file), e)
    }

    /// Adds a topic of type `M`, offered with `qos` (what a player republishes it with).
    pub fn add_topic<M: Message>(&mut self, topic: &str, qos: QosProfile) -> Result<TopicId, BagError> {
        if let Some(i) = self.topics.iter().position(|t| t.name == topic) {
            if self.topics[i].type_name != M::TYPE.name {
                return Err(self.mcap_error(format!(
                    "topic {topic} is already recorded as {}, not {}",
                    self.topics[i].type_name,
                    M::TYPE.name
                )));
            }
            return Ok(TopicId(i));
        }
        let schema = self
            .mcap
            .add_schema(M::TYPE.name, "ros2msg", M::TYPE.schema().as_bytes())
            .map_err(|e| self.mcap_error(e))?;
        let metadata = BTreeMap::from([("offered_qos_profiles".to_string(), offered_qos(qos))]);
        let channel = self.mcap.add_channel(schema, topic, "cdr", &metadata).map_err(|e| self.mcap_error(e))?;
        self.topics.push(Topic { name: topic.into(), type_name: M::TYPE.name, qos, channel, count: 0 });
        Ok(TopicId(self.topics.len() - 1))
    }

    /// Writes `message` on `topic` at `time_ns` \[ns\] (its receive and publish time).
    pub fn write<M: Message>(&mut self, topic: TopicId, time_ns: u64, message: &M) -> Result<(), BagError> {
        self.write_payload(topic, time_ns, &to_payload(message))
    }

    /// Writes a serialized message (encapsulation header and CDR body) on `topic` at `time_ns`.
    pub fn write_payload(&mut self, topic: TopicId, time_ns: u64, payload: &[u8]) -> Result<(), BagError> {
        let t = &mut self.topics[topic.0];
        let header = mcap::records::MessageHeader {
            channel_id: t.channel,
            sequence: self.sequence,
            log_time: time_ns,
            publish_time: time_ns,
        };
        t.count += 1;
        self.sequence = self.sequence.wrapping_add(1);
        self.span_ns = Some(self.span_ns.map_or((time_ns, time_ns), |(a, b)| (a.min(time_ns), b.max(time_ns))));
        self.mcap.write_to_known_channel(&header, payload).map_err(|e| self.mcap_error(e))
    }

    /// Ends the MCAP file (its summary and indexes) and writes `metadata.yaml`.
    pub fn finish(mut self) -> Result<BagSummary, BagError> {
        self.mcap.finish().map_err(|e| self.mcap_error(e))?;
        let (start, end) = self.span_ns.unwrap_or((0, 0));
        let topics: Vec<TopicMeta<'_>> = self
            .topics
            .iter()
            .map(|t| TopicMeta { name: &t.name, type_name: t.type_name, qos: t.qos, count: t.count })
            .collect();
        let yaml = metadata_yaml(self.distro, &self.file, start, end - start, &topics);
        let path = self.dir.join("metadata.yaml");
        tendril_config::write_atomically(&path, yaml.as_bytes())
            .map_err(|(file, e)| BagError::new(&file, format!("cannot write: {e}")))?;
        Ok(BagSummary {
            dir: self.dir.clone(),
            messages: self.topics.iter().map(|t| t.count).sum(),
            topics: self.topics.iter().map(|t| (t.name.clone(), t.count)).collect(),
        })
    }
}
