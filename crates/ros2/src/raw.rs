//! The bytes RustDDS carries: a message's CDR body, encoded and decoded by `tendril-ros2msg`
//! rather than by serde, so the wire and the bags hold the same bytes and a malformed message is
//! a decode error of ours (naming the field), not a sample RustDDS silently drops.

use rustdds::RepresentationIdentifier;
use rustdds::bytes::Bytes;
use rustdds::no_key::{Decode, DefaultDecoder, DeserializerAdapter, SerializerAdapter};

/// A message's CDR body (as written), or a serialized message (encapsulation header and body, as
/// read: the header says the body's byte order).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Raw(pub Bytes);

/// Never happens: taking or giving bytes cannot fail.
#[derive(Debug, thiserror::Error)]
#[error("unreachable")]
pub struct Infallible;

/// The adapter of [`Raw`] both ways.
pub struct RawAdapter;

impl SerializerAdapter<Raw> for RawAdapter {
    type Error = Infallible;
    fn output_encoding() -> RepresentationIdentifier {
        RepresentationIdentifier::CDR_LE
    }
    fn to_bytes(value: &Raw) -> Result<Bytes, Infallible> {
        Ok(value.0.clone())
    }
}

/// Decodes by copying the body.
#[derive(Clone)]
pub struct RawDecoder;

impl<'de> Decode<'de, Raw> for RawDecoder {
    type Error = Infallible;
    fn decode_bytes(self, body: &'de [u8], encoding: RepresentationIdentifier) -> Result<Raw, Infallible> {
        let order = if encoding == RepresentationIdentifier::CDR_BE { 0x00 } else { 0x01 };
        let mut payload = Vec::with_capacity(body.len() + 4);
        payload.extend_from_slice(&[0x00, order, 0x00, 0x00]);
        payload.extend_from_slice(body);
        Ok(Raw(Bytes::from(payload)))
    }
}

impl DeserializerAdapter<Raw> for RawAdapter {
    type Error = Infallible;
    type Decoded = Raw;
    fn supported_encodings() -> &'static [RepresentationIdentifier] {
        // Plain CDR in either byte order (the body's order is the writer's).
        &[RepresentationIdentifier::CDR_LE, RepresentationIdentifier::CDR_BE]
    }
    fn transform_decoded(decoded: Raw) -> Raw {
        decoded
    }
}

impl DefaultDecoder<Raw> for RawAdapter {
    type Decoder = RawDecoder;
    const DECODER: RawDecoder = RawDecoder;
}
