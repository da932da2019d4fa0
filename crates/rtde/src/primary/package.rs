//! A package on the wire: `i32 size` (the whole package), `u8 message type`, its body.

use super::error::PrimaryError;
use super::message::Message;
use super::state::SubPackage;
use tendril_codec::Decoded;

/// Message type of a robot state (sub-packages follow).
pub const ROBOT_STATE: u8 = 16;
/// Message type of a robot message.
pub const ROBOT_MESSAGE: u8 = 20;
/// Header of a package: `i32` size, `u8` type.
pub const HEADER_LEN: usize = 5;
/// Largest package a decoder accepts \[bytes\]: a UR5e's robot state is 1386 bytes; anything past
/// 64 KiB is a broken stream, not a package.
pub const MAX_PACKAGE_LEN: usize = 1 << 16;

/// A package from the controller.
#[derive(Debug, Clone, PartialEq)]
pub enum Package {
    /// A robot state: its sub-packages in order.
    State(Vec<SubPackage>),
    /// A robot message.
    Message(Message),
    /// Another message type (UR's internal ones): the type byte and the body.
    Other {
        /// Message type.
        kind: u8,
        /// The body after the header.
        body: Vec<u8>,
    },
}

impl Package {
    /// The package on the wire.
    pub fn encode(&self) -> Result<Vec<u8>, PrimaryError> {
        let (kind, body) = match self {
            Package::State(subs) => (ROBOT_STATE, subs.iter().flat_map(SubPackage::encode).collect()),
            Package::Message(m) => (ROBOT_MESSAGE, m.encode_body()?),
            Package::Other { kind, body } => (*kind, body.clone()),
        };
        let size = body.len() + HEADER_LEN;
        if size > MAX_PACKAGE_LEN {
            return Err(PrimaryError::BadSize(size as i64));
        }
        let mut out = Vec::with_capacity(size);
        out.extend_from_slice(&(size as i32).to_be_bytes());
        out.push(kind);
        out.extend_from_slice(&body);
        Ok(out)
    }

    /// Takes one package off the front of `buf` (a client's side: tests, tools).
    pub fn decode(buf: &[u8]) -> Decoded<Package, PrimaryError> {
        if buf.len() < HEADER_LEN {
            return Decoded::NeedMore;
        }
        let size = i32::from_be_bytes(buf[..4].try_into().expect("4 bytes"));
        let Some(size) = usize::try_from(size).ok().filter(|s| (HEADER_LEN..=MAX_PACKAGE_LEN).contains(s)) else {
            return Decoded::Invalid { error: PrimaryError::BadSize(i64::from(size)), consumed: 1 };
        };
        if buf.len() < size {
            return Decoded::NeedMore;
        }
        let (kind, body) = (buf[4], &buf[HEADER_LEN..size]);
        let parsed = match kind {
            ROBOT_STATE => decode_state(body).map(Package::State),
            ROBOT_MESSAGE => Message::decode_body(body).map(Package::Message),
            other => Ok(Package::Other { kind: other, body: body.to_vec() }),
        };
        match parsed {
            Ok(packet) => Decoded::Frame { packet, consumed: size },
            Err(error) => Decoded::Invalid { error, consumed: size },
        }
    }
}

fn decode_state(mut body: &[u8]) -> Result<Vec<SubPackage>, PrimaryError> {
    let mut subs = Vec::new();
    while !body.is_empty() {
        if body.len() < HEADER_LEN {
            return Err(PrimaryError::Truncated { needed: HEADER_LEN, available: body.len() });
        }
        let size = u32::from_be_bytes(body[..4].try_into().expect("4 bytes")) as usize;
        if size < HEADER_LEN || size > body.len() {
            return Err(PrimaryError::BadSize(size as i64));
        }
        subs.push(SubPackage::decode(body[4], &body[HEADER_LEN..size])?);
        body = &body[size..];
    }
    Ok(subs)
}
