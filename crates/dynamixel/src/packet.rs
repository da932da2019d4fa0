//! Packet framing: `FF FF FD 00 | ID | LEN_L LEN_H | INST | body | CRC_L CRC_H`, with
//! LEN = stuffed body + 3 (instruction and CRC), CRC-16 over everything before it.

use super::crc::crc16;
use super::stuffing::{stuff, unstuff};
use super::{DxlError, MAX_PACKET_LEN};
use tendril_codec::Decoded;

/// The four header bytes that start every packet.
pub const HEADER: [u8; 4] = [0xFF, 0xFF, 0xFD, 0x00];
/// Instruction byte of a status (reply) packet.
pub const STATUS_INSTRUCTION: u8 = 0x55;
/// The broadcast ID: every device executes the instruction; replies only where the protocol says.
pub const BROADCAST_ID: u8 = 0xFE;

/// One packet as framed on the wire, after unstuffing and CRC check: instruction or status.
///
/// For a status packet, `instruction` is [`STATUS_INSTRUCTION`] and `body[0]` is the error byte.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RawPacket {
    /// Device ID (0..=252), or [`BROADCAST_ID`].
    pub id: u8,
    /// Instruction byte (0x55 for a status packet).
    pub instruction: u8,
    /// Unstuffed bytes between instruction and CRC.
    pub body: Vec<u8>,
}

impl RawPacket {
    /// Encodes to wire bytes: header, stuffed body, length and CRC.
    ///
    /// Fails when the stuffed packet would exceed [`MAX_PACKET_LEN`].
    pub fn encode(&self) -> Result<Vec<u8>, DxlError> {
        let body = stuff(&self.body);
        let total = HEADER.len() + 4 + body.len() + 2;
        if total > MAX_PACKET_LEN {
            return Err(DxlError::TooLong { len: total, max: MAX_PACKET_LEN });
        }
        let len = (body.len() + 3) as u16;
        let mut out = Vec::with_capacity(total);
        out.extend_from_slice(&HEADER);
        out.push(self.id);
        out.extend_from_slice(&len.to_le_bytes());
        out.push(self.instruction);
        out.extend_from_slice(&body);
        let crc = crc16(&out);
        out.extend_from_slice(&crc.to_le_bytes());
        Ok(out)
    }

    /// Takes one packet off the front of `buf`.
    ///
    /// Garbage before a header, a bad length and a bad CRC give [`Decoded::Invalid`] with the number
    /// of bytes to drop, so a caller that keeps dropping them resynchronises on the next header.
    pub fn decode(buf: &[u8]) -> Decoded<RawPacket, DxlError> {
        let Some(start) = find_header(buf) else {
            // Keep a trailing partial header (up to 3 bytes): the rest of it may still arrive.
            let keep = partial_header_suffix(buf);
            return match buf.len() - keep {
                0 => Decoded::NeedMore,
                garbage => Decoded::Invalid { error: DxlError::Garbage { skipped: garbage }, consumed: garbage },
            };
        };
        if start > 0 {
            return Decoded::Invalid { error: DxlError::Garbage { skipped: start }, consumed: start };
        }
        if buf.len() < 7 {
            return Decoded::NeedMore;
        }
        let len = usize::from(u16::from_le_bytes([buf[5], buf[6]]));
        let total = 7 + len;
        if len < 3 || total > MAX_PACKET_LEN {
            return Decoded::Invalid { error: DxlError::BadLength { len }, consumed: 1 };
        }
        if buf.len() < total {
            return Decoded::NeedMore;
        }
        let expected = crc16(&buf[..total - 2]);
        let received = u16::from_le_bytes([buf[total - 2], buf[total - 1]]);
        if expected != received {
            let error = DxlError::BadCrc { expected, received, id: buf[4], instruction: buf[7] };
            return Decoded::Invalid { error, consumed: 1 };
        }
        let packet = RawPacket { id: buf[4], instruction: buf[7], body: unstuff(&buf[8..total - 2]) };
        Decoded::Frame { packet, consumed: total }
    }
}

/// Position of the first complete header in `buf`.
fn find_header(buf: &[u8]) -> Option<usize> {
    buf.windows(HEADER.len()).position(|w| w == HEADER)
}

/// Length of the longest suffix of `buf` that is a proper prefix of the header.
fn partial_header_suffix(buf: &[u8]) -> usize {
    (1..HEADER.len()).rev().find(|&n| buf.len() >= n && buf[buf.len() - n..] == HEADER[..n]).unwrap_or(0)
}

/// Incremental decoder for a byte stream (a serial port): push bytes as they arrive, pull packets.
#[derive(Debug, Default, Clone)]
pub struct StreamDecoder {
    buf: Vec<u8>,
}

impl StreamDecoder {
    /// An empty decoder.
    pub fn new() -> Self {
        Self::default()
    }

    /// Appends received bytes.
    pub fn push(&mut self, bytes: &[u8]) {
        self.buf.extend_from_slice(bytes);
    }

    /// Bytes held, waiting for the rest of a packet.
    pub fn buffered(&self) -> usize {
        self.buf.len()
    }

    /// The next packet, an error for bytes it dropped while resynchronising, or `None` when more
    /// bytes are needed. Call until `None`.
    pub fn next_packet(&mut self) -> Option<Result<RawPacket, DxlError>> {
        match RawPacket::decode(&self.buf) {
            Decoded::NeedMore => None,
            Decoded::Frame { packet, consumed } => {
                self.buf.drain(..consumed);
                Some(Ok(packet))
            }
            Decoded::Invalid { error, consumed } => {
                self.buf.drain(..consumed);
                Some(Err(error))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const PING: [u8; 10] = [0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x03, 0x00, 0x01, 0x19, 0x4E];

    #[test]
    fn ping_example_round_trip() {
        let packet = RawPacket { id: 1, instruction: 0x01, body: vec![] };
        assert_eq!(packet.encode().unwrap(), PING.to_vec());
        assert_eq!(RawPacket::decode(&PING), Decoded::Frame { packet, consumed: 10 });
    }

    #[test]
    fn partial_packet_needs_more() {
        for end in 0..PING.len() {
            assert_eq!(RawPacket::decode(&PING[..end]), Decoded::NeedMore, "prefix of {end} bytes");
        }
    }

    #[test]
    fn stream_resyncs_after_garbage_and_bad_crc() {
        let mut bad = PING;
        bad[8] ^= 0x01;
        let mut stream = StreamDecoder::new();
        stream.push(&[0x00, 0xFF, 0x12]);
        stream.push(&bad);
        stream.push(&PING);
        let mut packets = 0;
        let mut crc_errors = 0;
        while let Some(item) = stream.next_packet() {
            match item {
                Ok(p) => {
                    assert_eq!(p.id, 1);
                    packets += 1;
                }
                Err(DxlError::BadCrc { .. }) => crc_errors += 1,
                Err(_) => {}
            }
        }
        assert_eq!((packets, crc_errors), (1, 1));
        assert_eq!(stream.buffered(), 0);
    }

    #[test]
    fn stuffed_body_is_unstuffed_and_length_counts_stuffing() {
        let packet = RawPacket { id: 3, instruction: 0x03, body: vec![0x74, 0x00, 0xFF, 0xFF, 0xFD, 0x00] };
        let wire = packet.encode().unwrap();
        assert_eq!(u16::from_le_bytes([wire[5], wire[6]]), 7 + 3);
        assert_eq!(RawPacket::decode(&wire), Decoded::Frame { packet, consumed: wire.len() });
    }
}
