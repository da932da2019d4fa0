//! The ROS 2 graph's own topic, `ros_discovery_info` (`rmw_dds_common/msg/ParticipantEntitiesInfo`):
//! which nodes a DDS participant holds and which readers and writers each node owns. ROS 2's tools
//! (`ros2 node list`, `ros2 topic info -v`, rqt) learn a participant's nodes from it; topics work
//! without it.

use crate::cdr::{CdrError, CdrReader, CdrWriter};
use crate::message::TypeInfo;

/// How long a graph identifier (`rmw_dds_common/msg/Gid`) is on the wire: 24 bytes up to Humble,
/// 16 from Iron on (ros2/rmw_dds_common changed `char[24]` to `char[16]` in January 2023). A
/// participant whose length differs from the tools' is not shown by them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GidFormat {
    /// `char[24] data`: Foxy, Galactic, Humble.
    Humble,
    /// `char[16] data`: Iron, Jazzy and later.
    Iron,
}

impl GidFormat {
    /// Bytes on the wire.
    pub fn len(self) -> usize {
        match self {
            GidFormat::Humble => 24,
            GidFormat::Iron => 16,
        }
    }

    /// Always false: a Gid has bytes.
    pub fn is_empty(self) -> bool {
        false
    }
}

/// A DDS entity's GUID (16 bytes: prefix and entity id) as a graph identifier.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Gid(pub [u8; 16]);

fn encode_gid(g: &Gid, format: GidFormat, w: &mut CdrWriter) {
    w.bytes(&g.0);
    w.bytes(&[0; 8][..format.len() - 16]);
}

fn decode_gid(format: GidFormat, r: &mut CdrReader<'_>) -> Result<Gid, CdrError> {
    let g = Gid(r.bytes::<16>("gid.data")?);
    if format == GidFormat::Humble {
        r.bytes::<8>("gid.data")?;
    }
    Ok(g)
}

/// One node of a participant: its name and the entities it owns.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct NodeEntitiesInfo {
    /// Namespace (`/` at least).
    pub node_namespace: String,
    /// Name.
    pub node_name: String,
    /// Its readers (subscriptions).
    pub reader_gid_seq: Vec<Gid>,
    /// Its writers (publishers).
    pub writer_gid_seq: Vec<Gid>,
}

/// `rmw_dds_common/msg/ParticipantEntitiesInfo`, in the Gid format of the ROS 2 distribution.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ParticipantEntitiesInfo {
    /// The Gid length the tools expect.
    pub format: GidFormat,
    /// The participant's Gid.
    pub gid: Gid,
    /// Its nodes.
    pub node_entities_info_seq: Vec<NodeEntitiesInfo>,
}

const GID_INFO: TypeInfo = TypeInfo { name: "rmw_dds_common/msg/Gid", definition: "char[24] data\n", nested: &[] };
const NODE_INFO: TypeInfo = TypeInfo {
    name: "rmw_dds_common/msg/NodeEntitiesInfo",
    definition: "string<=256 node_namespace\nstring<=256 node_name\nGid[] reader_gid_seq\nGid[] writer_gid_seq\n",
    nested: &[GID_INFO],
};

impl ParticipantEntitiesInfo {
    /// Its type (the DDS type name is the same in every distribution; the Gid's length is not).
    pub const INFO: TypeInfo = TypeInfo {
        name: "rmw_dds_common/msg/ParticipantEntitiesInfo",
        definition: "Gid gid\nNodeEntitiesInfo[] node_entities_info_seq\n",
        nested: &[GID_INFO, NODE_INFO],
    };

    /// Its CDR body.
    pub fn encode(&self, w: &mut CdrWriter) {
        let f = self.format;
        encode_gid(&self.gid, f, w);
        w.u32(self.node_entities_info_seq.len() as u32);
        for n in &self.node_entities_info_seq {
            w.string(&n.node_namespace);
            w.string(&n.node_name);
            for seq in [&n.reader_gid_seq, &n.writer_gid_seq] {
                w.u32(seq.len() as u32);
                for g in seq {
                    encode_gid(g, f, w);
                }
            }
        }
    }

    /// Reads a CDR body written in `format`.
    pub fn decode(format: GidFormat, r: &mut CdrReader<'_>) -> Result<ParticipantEntitiesInfo, CdrError> {
        let gid = decode_gid(format, r)?;
        let nodes = r.u32("node_entities_info_seq")? as usize;
        if nodes > r.remaining() {
            return Err(CdrError::BadLength { field: "node_entities_info_seq", offset: 0, len: nodes });
        }
        let mut node_entities_info_seq = Vec::with_capacity(nodes);
        for _ in 0..nodes {
            let node_namespace = r.string("node_namespace")?;
            let node_name = r.string("node_name")?;
            let mut seqs = [Vec::new(), Vec::new()];
            for seq in &mut seqs {
                let n = r.u32("gid_seq")? as usize;
                if n * format.len() > r.remaining() {
                    return Err(CdrError::BadLength { field: "gid_seq", offset: 0, len: n });
                }
                for _ in 0..n {
                    seq.push(decode_gid(format, r)?);
                }
            }
            let [reader_gid_seq, writer_gid_seq] = seqs;
            node_entities_info_seq.push(NodeEntitiesInfo { node_namespace, node_name, reader_gid_seq, writer_gid_seq });
        }
        Ok(ParticipantEntitiesInfo { format, gid, node_entities_info_seq })
    }
}
