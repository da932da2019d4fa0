//! [`Node`]: a DDS participant that ROS 2 sees as a node: its topics under ROS 2's names and types
//! (`/joint_states` is the DDS topic `rt/joint_states` of type
//! `sensor_msgs::msg::dds_::JointState_`), its quality of service as configured, and the graph
//! information (`ros_discovery_info`) that makes it show in `ros2 node list`.

use super::config::{QosProfile, Ros2Config};
use super::error::Ros2Error;
use super::raw::{Raw, RawAdapter};
use rustdds::bytes::Bytes;
use rustdds::no_key::{DataReader, DataWriter};
use rustdds::policy::{Durability, History, Reliability};
use rustdds::{DomainParticipant, DomainParticipantBuilder, QosPolicies, QosPolicyBuilder, RTPSEntity, TopicKind};
use std::marker::PhantomData;
use std::net::{IpAddr, Ipv4Addr};
use tendril_ros2msg::graph::{Gid, GidFormat, NodeEntitiesInfo, ParticipantEntitiesInfo};
use tendril_ros2msg::{CdrWriter, Message, from_payload, names, to_body};

/// How long a reliable write may wait for room in a full history before it fails \[s\]: 0.1 s.
/// With keep-last histories a write replaces the oldest sample instead of waiting, so this
/// bounds only the rare case of a reader that holds every sample.
const MAX_BLOCKING_S: f64 = 0.1;

/// `profile` as RustDDS's policies: reliable or best effort, volatile, keep last `depth`.
pub fn qos(profile: QosProfile) -> QosPolicies {
    let reliability = if profile.reliable {
        Reliability::Reliable { max_blocking_time: rustdds::Duration::from_frac_seconds(MAX_BLOCKING_S) }
    } else {
        Reliability::BestEffort
    };
    QosPolicyBuilder::new()
        .reliability(reliability)
        .durability(Durability::Volatile)
        .history(History::KeepLast { depth: profile.depth as i32 })
        .build()
}

/// A ROS 2 node over its own DDS participant.
pub struct Node {
    participant: DomainParticipant,
    publisher: rustdds::Publisher,
    subscriber: rustdds::Subscriber,
    domain: u16,
    namespace: String,
    name: String,
    gid_format: GidFormat,
    graph: DataWriter<Raw, RawAdapter>,
    readers: Vec<Gid>,
    writers: Vec<Gid>,
}

fn gid(guid: rustdds::GUID) -> Gid {
    Gid(guid.to_bytes())
}

impl Node {
    /// A node named `name` in the configuration's namespace and domain: on loopback only when
    /// `localhost_only` (discovery then reaches this machine's participants through their
    /// well-known unicast ports, as ROS 2's localhost-only mode does).
    pub fn new(config: &Ros2Config, name: &str) -> Result<Node, Ros2Error> {
        let domain = config.domain_id;
        let dds = |what: &str| {
            let what = what.to_string();
            move |e: rustdds::dds::result::CreateError| Ros2Error::Dds { domain, what, cause: format!("{e:?}") }
        };
        names::node_name(name)?;
        let namespace = names::namespace(&config.namespace)?.to_string();
        let mut builder = DomainParticipantBuilder::new(domain).same_host_loopback(true);
        if config.localhost_only {
            builder = builder.with_only_networks([IpAddr::V4(Ipv4Addr::LOCALHOST)]);
        }
        let participant = builder.build().map_err(dds("participant"))?;
        let default = qos(QosProfile::DEFAULT);
        let publisher = participant.create_publisher(&default).map_err(dds("publisher"))?;
        let subscriber = participant.create_subscriber(&default).map_err(dds("subscriber"))?;
        // The graph's topic: reliable, transient local, keep last 1 (rmw_dds_common's QoS), so a
        // tool that starts later still reads the latest.
        let graph_qos = QosPolicyBuilder::new()
            .reliability(Reliability::Reliable {
                max_blocking_time: rustdds::Duration::from_frac_seconds(MAX_BLOCKING_S),
            })
            .durability(Durability::TransientLocal)
            .history(History::KeepLast { depth: 1 })
            .build();
        let topic = participant
            .create_topic(
                "ros_discovery_info".into(),
                ParticipantEntitiesInfo::INFO.dds_name(),
                &graph_qos,
                TopicKind::NoKey,
            )
            .map_err(dds("topic ros_discovery_info"))?;
        let graph = publisher
            .create_datawriter_no_key::<Raw, RawAdapter>(&topic, Some(graph_qos))
            .map_err(dds("writer ros_discovery_info"))?;
        let mut node = Node {
            participant,
            publisher,
            subscriber,
            domain,
            namespace,
            name: name.into(),
            gid_format: config.distro.gid_format(),
            graph,
            readers: Vec::new(),
            writers: Vec::new(),
        };
        node.announce();
        Ok(node)
    }

    /// The DDS domain.
    pub fn domain(&self) -> u16 {
        self.domain
    }

    /// A publisher of `M` on `topic` (resolved in the node's namespace).
    pub fn publisher<M: Message>(&mut self, topic: &str, profile: QosProfile) -> Result<Pub<M>, Ros2Error> {
        let full = names::resolve_topic(topic, &self.namespace)?;
        let policies = qos(profile);
        let t = self.topic::<M>(&full, &policies)?;
        let writer = self
            .publisher
            .create_datawriter_no_key::<Raw, RawAdapter>(&t, Some(policies))
            .map_err(|e| self.dds_error(&format!("publisher on {full}"), e))?;
        self.writers.push(gid(writer.guid()));
        self.announce();
        Ok(Pub { writer, topic: full, _m: PhantomData })
    }

    /// A subscription to `M` on `topic` (resolved in the node's namespace).
    pub fn subscription<M: Message>(&mut self, topic: &str, profile: QosProfile) -> Result<Sub<M>, Ros2Error> {
        let full = names::resolve_topic(topic, &self.namespace)?;
        let policies = qos(profile);
        let t = self.topic::<M>(&full, &policies)?;
        let reader = self
            .subscriber
            .create_datareader_no_key::<Raw, RawAdapter>(&t, Some(policies))
            .map_err(|e| self.dds_error(&format!("subscription to {full}"), e))?;
        self.readers.push(gid(reader.guid()));
        self.announce();
        Ok(Sub { reader, topic: full, _m: PhantomData })
    }

    fn topic<M: Message>(&self, full: &str, policies: &QosPolicies) -> Result<rustdds::Topic, Ros2Error> {
        self.participant
            .create_topic(names::dds_topic(full), M::TYPE.dds_name(), policies, TopicKind::NoKey)
            .map_err(|e| self.dds_error(&format!("topic {full}"), e))
    }

    fn dds_error(&self, what: &str, e: impl std::fmt::Debug) -> Ros2Error {
        Ros2Error::Dds { domain: self.domain, what: what.into(), cause: format!("{e:?}") }
    }

    /// Publishes the node's graph information (its readers and writers): ROS 2's tools learn from
    /// it which node owns which endpoints. Called whenever an endpoint is added.
    fn announce(&mut self) {
        let info = ParticipantEntitiesInfo {
            format: self.gid_format,
            gid: gid(self.participant.guid()),
            node_entities_info_seq: vec![NodeEntitiesInfo {
                node_namespace: self.namespace.clone(),
                node_name: self.name.clone(),
                reader_gid_seq: self.readers.clone(),
                writer_gid_seq: self.writers.clone(),
            }],
        };
        let mut w = CdrWriter::new();
        info.encode(&mut w);
        // Best effort: a graph the tools cannot see leaves the topics working.
        let _ = self.graph.write(Raw(Bytes::from(w.into_bytes())), None);
    }

    /// The DDS types other participants' writers offer on `topic` (fully qualified) that are not
    /// `M`'s: why a subscription to it receives nothing.
    pub fn foreign_types<M: Message>(&self, topic: &str) -> Vec<String> {
        let (dds_topic, ours) = (names::dds_topic(topic), M::TYPE.dds_name());
        let mut types: Vec<String> = self
            .participant
            .discovered_writers()
            .into_iter()
            .filter(|w| *w.publication_topic_data.topic_name() == dds_topic)
            .map(|w| w.publication_topic_data.type_name.clone())
            .filter(|t| *t != ours)
            .collect();
        types.sort();
        types.dedup();
        types
    }
}

/// A typed publisher.
pub struct Pub<M> {
    writer: DataWriter<Raw, RawAdapter>,
    topic: String,
    _m: PhantomData<fn(&M)>,
}

impl<M: Message> Pub<M> {
    /// Publishes `m`.
    pub fn publish(&self, m: &M) -> Result<(), Ros2Error> {
        self.writer
            .write(Raw(Bytes::from(to_body(m))), None)
            .map_err(|e| Ros2Error::Publish { topic: self.topic.clone(), cause: format!("{e:?}") })
    }

    /// The topic, fully qualified.
    pub fn topic(&self) -> &str {
        &self.topic
    }
}

/// A typed subscription.
pub struct Sub<M> {
    reader: DataReader<Raw, RawAdapter>,
    topic: String,
    _m: PhantomData<fn() -> M>,
}

/// Most samples one call to [`Sub::take`] returns: a flood is read in bounded slices, the rest
/// left to the reader's keep-last history (which drops the oldest), so nothing grows without
/// limit.
pub const TAKE_AT_MOST: usize = 64;

impl<M: Message> Sub<M> {
    /// The samples received since the last call, oldest first, at most [`TAKE_AT_MOST`]: each
    /// decoded, or the reason it could not be.
    pub fn take(&mut self) -> Vec<Result<M, Ros2Error>> {
        let samples = self.reader.take(TAKE_AT_MOST, rustdds::ReadCondition::not_read()).unwrap_or_default();
        samples
            .into_iter()
            .map(|s| s.into_value())
            .map(|raw| {
                from_payload::<M>(&raw.0).map_err(|cause| Ros2Error::Malformed {
                    topic: self.topic.clone(),
                    type_name: M::TYPE.name,
                    cause,
                })
            })
            .collect()
    }

    /// The topic, fully qualified.
    pub fn topic(&self) -> &str {
        &self.topic
    }

    /// The reader, to register with a `mio` poll (it becomes readable when samples arrive).
    pub fn reader_mut(&mut self) -> &mut DataReader<Raw, RawAdapter> {
        &mut self.reader
    }
}
