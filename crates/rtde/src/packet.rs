//! RTDE packets: `u16 size` (including the 3-byte header), `u8 type`, payload; big-endian.
//!
//! The same type byte carries different payloads in each direction, so there is one enum per
//! direction: [`ClientPacket`] (client to controller) and [`ServerPacket`] (controller to client).
//! Only protocol version 2 payloads are modelled (version 1 lacks the output frequency and the
//! output recipe ID).

use super::RtdeError;
use super::types::FieldType;
use tendril_codec::Decoded;

/// Header length: u16 size and u8 type.
pub const HEADER_LEN: usize = 3;

/// Package type bytes.
pub mod kind {
    /// `V`: request protocol version.
    pub const REQUEST_PROTOCOL_VERSION: u8 = b'V';
    /// `v`: controller (URControl) version.
    pub const GET_URCONTROL_VERSION: u8 = b'v';
    /// `M`: text message.
    pub const TEXT_MESSAGE: u8 = b'M';
    /// `U`: data package.
    pub const DATA_PACKAGE: u8 = b'U';
    /// `O`: set up outputs.
    pub const SETUP_OUTPUTS: u8 = b'O';
    /// `I`: set up inputs.
    pub const SETUP_INPUTS: u8 = b'I';
    /// `S`: start.
    pub const START: u8 = b'S';
    /// `P`: pause.
    pub const PAUSE: u8 = b'P';
}

/// Severity of a text message.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MessageLevel {
    /// 0.
    Exception,
    /// 1.
    Error,
    /// 2.
    Warning,
    /// 3.
    Info,
}

impl MessageLevel {
    fn byte(self) -> u8 {
        match self {
            MessageLevel::Exception => 0,
            MessageLevel::Error => 1,
            MessageLevel::Warning => 2,
            MessageLevel::Info => 3,
        }
    }

    fn from_byte(b: u8) -> Result<Self, RtdeError> {
        Ok(match b {
            0 => MessageLevel::Exception,
            1 => MessageLevel::Error,
            2 => MessageLevel::Warning,
            3 => MessageLevel::Info,
            other => return Err(RtdeError::BadMessageLevel(other)),
        })
    }
}

/// A text message (`M`, protocol v2 layout), in either direction.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TextMessage {
    /// The text (at most 255 bytes).
    pub message: String,
    /// Who sent it (at most 255 bytes).
    pub source: String,
    /// Severity.
    pub level: MessageLevel,
}

/// The controller version (`v` reply).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ControllerVersion {
    /// Major (5 on e-Series).
    pub major: u32,
    /// Minor.
    pub minor: u32,
    /// Bugfix.
    pub bugfix: u32,
    /// Build.
    pub build: u32,
}

/// A packet from the client to the controller.
#[derive(Debug, Clone, PartialEq)]
pub enum ClientPacket {
    /// `V`: ask for a protocol version.
    RequestProtocolVersion {
        /// Requested version (2).
        version: u16,
    },
    /// `v`: ask for the controller version.
    GetControllerVersion,
    /// `M`: a message to the controller's log.
    Text(TextMessage),
    /// `O`: output recipe.
    SetupOutputs {
        /// Requested rate, Hz.
        frequency_hz: f64,
        /// Field names (a trailing comma on the wire is tolerated).
        names: Vec<String>,
    },
    /// `I`: input recipe.
    SetupInputs {
        /// Field names.
        names: Vec<String>,
    },
    /// `S`: start streaming.
    Start,
    /// `P`: pause streaming.
    Pause,
    /// `U`: input data for a recipe; decode `data` with the recipe's types.
    Data {
        /// Input recipe ID.
        recipe_id: u8,
        /// Field bytes in recipe order.
        data: Vec<u8>,
    },
}

/// A packet from the controller to the client.
#[derive(Debug, Clone, PartialEq)]
pub enum ServerPacket {
    /// `V`: whether the requested version is accepted.
    ProtocolVersion {
        /// Accepted.
        accepted: bool,
    },
    /// `v`: controller version.
    ControllerVersion(ControllerVersion),
    /// `M`: a message from the controller.
    Text(TextMessage),
    /// `O`: output recipe ID and field types.
    SetupOutputs {
        /// Recipe ID (0 when the recipe is invalid).
        recipe_id: u8,
        /// One entry per requested name.
        types: Vec<FieldType>,
    },
    /// `I`: input recipe ID and field types.
    SetupInputs {
        /// Recipe ID (0 when the recipe is invalid).
        recipe_id: u8,
        /// One entry per requested name.
        types: Vec<FieldType>,
    },
    /// `S`: start accepted.
    Start {
        /// Accepted.
        accepted: bool,
    },
    /// `P`: pause accepted.
    Pause {
        /// Accepted.
        accepted: bool,
    },
    /// `U`: output data for a recipe.
    Data {
        /// Output recipe ID.
        recipe_id: u8,
        /// Field bytes in recipe order.
        data: Vec<u8>,
    },
}

impl ClientPacket {
    /// Wire bytes; fails if a field does not fit (packet over 65535 bytes, text over 255).
    pub fn encode(&self) -> Result<Vec<u8>, RtdeError> {
        let mut p = Vec::new();
        let kind = match self {
            ClientPacket::RequestProtocolVersion { version } => {
                p.extend_from_slice(&version.to_be_bytes());
                kind::REQUEST_PROTOCOL_VERSION
            }
            ClientPacket::GetControllerVersion => kind::GET_URCONTROL_VERSION,
            ClientPacket::Text(t) => {
                encode_text(t, &mut p)?;
                kind::TEXT_MESSAGE
            }
            ClientPacket::SetupOutputs { frequency_hz, names } => {
                p.extend_from_slice(&frequency_hz.to_be_bytes());
                p.extend_from_slice(join_names(names)?.as_bytes());
                kind::SETUP_OUTPUTS
            }
            ClientPacket::SetupInputs { names } => {
                p.extend_from_slice(join_names(names)?.as_bytes());
                kind::SETUP_INPUTS
            }
            ClientPacket::Start => kind::START,
            ClientPacket::Pause => kind::PAUSE,
            ClientPacket::Data { recipe_id, data } => {
                p.push(*recipe_id);
                p.extend_from_slice(data);
                kind::DATA_PACKAGE
            }
        };
        frame(kind, &p)
    }

    /// Takes one client packet off the front of `buf`.
    pub fn decode(buf: &[u8]) -> Decoded<ClientPacket, RtdeError> {
        decode_with(buf, Self::from_payload)
    }

    fn from_payload(kind: u8, p: &[u8]) -> Result<ClientPacket, RtdeError> {
        Ok(match kind {
            kind::REQUEST_PROTOCOL_VERSION => {
                ClientPacket::RequestProtocolVersion { version: u16::from_be_bytes(exact::<2>(kind, p)?) }
            }
            kind::GET_URCONTROL_VERSION => {
                exact::<0>(kind, p)?;
                ClientPacket::GetControllerVersion
            }
            kind::TEXT_MESSAGE => ClientPacket::Text(decode_text(p)?),
            kind::SETUP_OUTPUTS => {
                let freq = p.get(..8).ok_or(RtdeError::BadPayload { kind, len: p.len() })?;
                let frequency_hz =
                    f64::from_be_bytes(freq.try_into().map_err(|_| RtdeError::BadPayload { kind, len: p.len() })?);
                ClientPacket::SetupOutputs { frequency_hz, names: split_names(&p[8..])? }
            }
            kind::SETUP_INPUTS => ClientPacket::SetupInputs { names: split_names(p)? },
            kind::START => {
                exact::<0>(kind, p)?;
                ClientPacket::Start
            }
            kind::PAUSE => {
                exact::<0>(kind, p)?;
                ClientPacket::Pause
            }
            kind::DATA_PACKAGE => {
                let (&recipe_id, data) = p.split_first().ok_or(RtdeError::BadPayload { kind, len: 0 })?;
                ClientPacket::Data { recipe_id, data: data.to_vec() }
            }
            other => return Err(RtdeError::UnknownPackage(other)),
        })
    }
}

impl ServerPacket {
    /// Wire bytes; fails if a field does not fit (packet over 65535 bytes, text over 255).
    pub fn encode(&self) -> Result<Vec<u8>, RtdeError> {
        let mut p = Vec::new();
        let kind = match self {
            ServerPacket::ProtocolVersion { accepted } => {
                p.push(u8::from(*accepted));
                kind::REQUEST_PROTOCOL_VERSION
            }
            ServerPacket::ControllerVersion(v) => {
                for x in [v.major, v.minor, v.bugfix, v.build] {
                    p.extend_from_slice(&x.to_be_bytes());
                }
                kind::GET_URCONTROL_VERSION
            }
            ServerPacket::Text(t) => {
                encode_text(t, &mut p)?;
                kind::TEXT_MESSAGE
            }
            ServerPacket::SetupOutputs { recipe_id, types } | ServerPacket::SetupInputs { recipe_id, types } => {
                p.push(*recipe_id);
                let joined: Vec<&str> = types.iter().map(|t| t.name()).collect();
                p.extend_from_slice(joined.join(",").as_bytes());
                if matches!(self, ServerPacket::SetupOutputs { .. }) { kind::SETUP_OUTPUTS } else { kind::SETUP_INPUTS }
            }
            ServerPacket::Start { accepted } => {
                p.push(u8::from(*accepted));
                kind::START
            }
            ServerPacket::Pause { accepted } => {
                p.push(u8::from(*accepted));
                kind::PAUSE
            }
            ServerPacket::Data { recipe_id, data } => {
                p.push(*recipe_id);
                p.extend_from_slice(data);
                kind::DATA_PACKAGE
            }
        };
        frame(kind, &p)
    }

    /// Takes one server packet off the front of `buf`.
    pub fn decode(buf: &[u8]) -> Decoded<ServerPacket, RtdeError> {
        decode_with(buf, Self::from_payload)
    }

    fn from_payload(kind: u8, p: &[u8]) -> Result<ServerPacket, RtdeError> {
        let flag = |p: &[u8]| -> Result<bool, RtdeError> { Ok(exact::<1>(kind, p)?[0] != 0) };
        Ok(match kind {
            kind::REQUEST_PROTOCOL_VERSION => ServerPacket::ProtocolVersion { accepted: flag(p)? },
            kind::GET_URCONTROL_VERSION => {
                let b = exact::<16>(kind, p)?;
                let w = |i: usize| u32::from_be_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
                ServerPacket::ControllerVersion(ControllerVersion {
                    major: w(0),
                    minor: w(4),
                    bugfix: w(8),
                    build: w(12),
                })
            }
            kind::TEXT_MESSAGE => ServerPacket::Text(decode_text(p)?),
            kind::SETUP_OUTPUTS | kind::SETUP_INPUTS => {
                let (&recipe_id, rest) = p.split_first().ok_or(RtdeError::BadPayload { kind, len: 0 })?;
                let types = split_names(rest)?.iter().map(|n| FieldType::from_name(n)).collect::<Result<_, _>>()?;
                if kind == kind::SETUP_OUTPUTS {
                    ServerPacket::SetupOutputs { recipe_id, types }
                } else {
                    ServerPacket::SetupInputs { recipe_id, types }
                }
            }
            kind::START => ServerPacket::Start { accepted: flag(p)? },
            kind::PAUSE => ServerPacket::Pause { accepted: flag(p)? },
            kind::DATA_PACKAGE => {
                let (&recipe_id, data) = p.split_first().ok_or(RtdeError::BadPayload { kind, len: 0 })?;
                ServerPacket::Data { recipe_id, data: data.to_vec() }
            }
            other => return Err(RtdeError::UnknownPackage(other)),
        })
    }
}

/// Header plus payload.
fn frame(kind: u8, payload: &[u8]) -> Result<Vec<u8>, RtdeError> {
    let size = u16::try_from(HEADER_LEN + payload.len()).map_err(|_| RtdeError::TooLong(HEADER_LEN + payload.len()))?;
    let mut out = Vec::with_capacity(usize::from(size));
    out.extend_from_slice(&size.to_be_bytes());
    out.push(kind);
    out.extend_from_slice(payload);
    Ok(out)
}

/// Frames one packet. An invalid payload inside a well-formed frame consumes the whole frame;
/// a size below 3 consumes the header (RTDE has no resync marker: the caller should close).
fn decode_with<P>(buf: &[u8], parse: impl Fn(u8, &[u8]) -> Result<P, RtdeError>) -> Decoded<P, RtdeError> {
    if buf.len() < HEADER_LEN {
        return Decoded::NeedMore;
    }
    let size = usize::from(u16::from_be_bytes([buf[0], buf[1]]));
    if size < HEADER_LEN {
        return Decoded::Invalid { error: RtdeError::BadSize(size), consumed: HEADER_LEN };
    }
    if buf.len() < size {
        return Decoded::NeedMore;
    }
    match parse(buf[2], &buf[HEADER_LEN..size]) {
        Ok(packet) => Decoded::Frame { packet, consumed: size },
        Err(error) => Decoded::Invalid { error, consumed: size },
    }
}

fn exact<const N: usize>(kind: u8, p: &[u8]) -> Result<[u8; N], RtdeError> {
    p.try_into().map_err(|_| RtdeError::BadPayload { kind, len: p.len() })
}

fn join_names(names: &[String]) -> Result<String, RtdeError> {
    if let Some(bad) = names.iter().find(|n| n.is_empty() || n.contains(',')) {
        return Err(RtdeError::BadName(bad.clone()));
    }
    Ok(names.join(","))
}

/// Splits a comma-separated list; a trailing comma (as SDU's `ur_rtde` sends) adds no entry.
fn split_names(bytes: &[u8]) -> Result<Vec<String>, RtdeError> {
    let text = std::str::from_utf8(bytes).map_err(|_| RtdeError::NotUtf8)?;
    let text = text.strip_suffix(',').unwrap_or(text);
    if text.is_empty() {
        return Ok(Vec::new());
    }
    Ok(text.split(',').map(|s| s.trim().to_string()).collect())
}

fn encode_text(t: &TextMessage, p: &mut Vec<u8>) -> Result<(), RtdeError> {
    for s in [&t.message, &t.source] {
        let len = u8::try_from(s.len()).map_err(|_| RtdeError::TooLong(s.len()))?;
        p.push(len);
        p.extend_from_slice(s.as_bytes());
    }
    p.push(t.level.byte());
    Ok(())
}

fn decode_text(p: &[u8]) -> Result<TextMessage, RtdeError> {
    let bad = || RtdeError::BadPayload { kind: kind::TEXT_MESSAGE, len: p.len() };
    let (message, rest) = take_string(p).ok_or_else(bad)?;
    let (source, rest) = take_string(rest).ok_or_else(bad)?;
    let level = match rest {
        [level] => MessageLevel::from_byte(*level)?,
        _ => return Err(bad()),
    };
    Ok(TextMessage { message, source, level })
}

/// A u8-length-prefixed string off the front (lossy UTF-8: messages are for humans).
fn take_string(p: &[u8]) -> Option<(String, &[u8])> {
    let (&len, rest) = p.split_first()?;
    let len = usize::from(len);
    let text = rest.get(..len)?;
    Some((String::from_utf8_lossy(text).into_owned(), &rest[len..]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::types::RtdeType;

    fn frame_of<P: std::fmt::Debug>(d: Decoded<P, RtdeError>) -> (P, usize) {
        match d {
            Decoded::Frame { packet, consumed } => (packet, consumed),
            other => panic!("not a frame: {other:?}"),
        }
    }

    #[test]
    fn version_request_and_reply_examples() {
        let request = [0x00, 0x05, 0x56, 0x00, 0x02];
        let packet = ClientPacket::RequestProtocolVersion { version: 2 };
        assert_eq!(packet.encode().unwrap(), request.to_vec());
        assert_eq!(frame_of(ClientPacket::decode(&request)), (packet, 5));
        let reply = [0x00, 0x04, 0x56, 0x01];
        let packet = ServerPacket::ProtocolVersion { accepted: true };
        assert_eq!(packet.encode().unwrap(), reply.to_vec());
        assert_eq!(frame_of(ServerPacket::decode(&reply)), (packet, 4));
    }

    #[test]
    fn input_data_package_example() {
        let wire = [0x00, 0x10, 0x55, 0x02, 0x3F, 0xF8, 0, 0, 0, 0, 0, 0, 0x00, 0x00, 0x00, 0x07];
        let mut data = 1.5f64.to_be_bytes().to_vec();
        data.extend_from_slice(&7i32.to_be_bytes());
        let packet = ClientPacket::Data { recipe_id: 2, data };
        assert_eq!(packet.encode().unwrap(), wire.to_vec());
        assert_eq!(frame_of(ClientPacket::decode(&wire)), (packet, 16));
    }

    #[test]
    fn trailing_comma_is_tolerated() {
        let mut wire = frame(kind::SETUP_INPUTS, b"input_int_register_0,input_double_register_1,").unwrap();
        let (packet, _) = frame_of(ClientPacket::decode(&wire));
        assert_eq!(
            packet,
            ClientPacket::SetupInputs { names: vec!["input_int_register_0".into(), "input_double_register_1".into()] }
        );
        wire.truncate(4);
        assert_eq!(ClientPacket::decode(&wire), Decoded::NeedMore);
    }

    #[test]
    fn every_server_packet_round_trips() {
        let packets = [
            ServerPacket::ProtocolVersion { accepted: false },
            ServerPacket::ControllerVersion(ControllerVersion { major: 5, minor: 11, bugfix: 1, build: 108 }),
            ServerPacket::Text(TextMessage {
                message: "hi".into(),
                source: "tendril".into(),
                level: MessageLevel::Warning,
            }),
            ServerPacket::SetupOutputs {
                recipe_id: 1,
                types: vec![FieldType::Known(RtdeType::Vector6d), FieldType::NotFound],
            },
            ServerPacket::SetupInputs { recipe_id: 0, types: vec![FieldType::InUse] },
            ServerPacket::Start { accepted: true },
            ServerPacket::Pause { accepted: true },
            ServerPacket::Data { recipe_id: 1, data: vec![1, 2, 3] },
        ];
        for p in packets {
            let wire = p.encode().unwrap();
            assert_eq!(frame_of(ServerPacket::decode(&wire)), (p, wire.len()));
        }
    }

    #[test]
    fn bad_frames_are_errors_not_panics() {
        assert!(matches!(ClientPacket::decode(&[0x00, 0x02, 0x56]), Decoded::Invalid { consumed: 3, .. }));
        assert!(matches!(
            ClientPacket::decode(&[0x00, 0x04, 0x7A, 0x00]),
            Decoded::Invalid { error: RtdeError::UnknownPackage(0x7A), consumed: 4 }
        ));
        assert!(matches!(ServerPacket::decode(&[0x00, 0x05, 0x53, 1, 1]), Decoded::Invalid { .. }));
    }
}
