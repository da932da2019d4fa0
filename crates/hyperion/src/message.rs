//! Command framing on TCP 51971 (and the 8-byte header of streamed frames on 51972).
//!
//! Request: `u8 options, u8 0, u16 command length, u32 argument length`, command, argument.
//! Response: `u8 status, u8 type, u16 message length, u32 content length`, message, content.
//! Little-endian (Luna's `hyperion.py` packs with native order on x86).

use super::HyperionError;
use tendril_codec::Decoded;

/// Header length of requests and responses.
pub const HEADER_LEN: usize = 8;
/// Largest request argument accepted (bytes): arguments are short ASCII lists.
pub const MAX_ARGUMENT_LEN: usize = 64 * 1024;
/// Largest response content accepted (bytes): a 16-channel spectrum fits.
pub const MAX_CONTENT_LEN: usize = 16 * 1024 * 1024;

/// A command request.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Request {
    /// Request option flags (0 for the commands used here).
    pub options: u8,
    /// Command, starting with `#` (e.g. `#GetPeaks`).
    pub command: String,
    /// Space-separated ASCII arguments (may be empty).
    pub argument: String,
}

impl Request {
    /// A request with no options.
    pub fn new(command: &str, argument: &str) -> Self {
        Self { options: 0, command: command.to_string(), argument: argument.to_string() }
    }

    /// Wire bytes.
    pub fn encode(&self) -> Result<Vec<u8>, HyperionError> {
        let command_len = u16::try_from(self.command.len()).map_err(|_| HyperionError::TooLong(self.command.len()))?;
        if self.argument.len() > MAX_ARGUMENT_LEN {
            return Err(HyperionError::TooLong(self.argument.len()));
        }
        let mut out = Vec::with_capacity(HEADER_LEN + self.command.len() + self.argument.len());
        out.push(self.options);
        out.push(0);
        out.extend_from_slice(&command_len.to_le_bytes());
        out.extend_from_slice(&(self.argument.len() as u32).to_le_bytes());
        out.extend_from_slice(self.command.as_bytes());
        out.extend_from_slice(self.argument.as_bytes());
        Ok(out)
    }

    /// Takes one request off the front of `buf`.
    pub fn decode(buf: &[u8]) -> Decoded<Request, HyperionError> {
        if buf.len() < HEADER_LEN {
            return Decoded::NeedMore;
        }
        let command_len = usize::from(u16::from_le_bytes([buf[2], buf[3]]));
        let argument_len = u32::from_le_bytes([buf[4], buf[5], buf[6], buf[7]]) as usize;
        if argument_len > MAX_ARGUMENT_LEN {
            // Unbounded lengths would make the server buffer without limit: drop the connection.
            return Decoded::Invalid { error: HyperionError::TooLong(argument_len), consumed: buf.len() };
        }
        let total = HEADER_LEN + command_len + argument_len;
        if buf.len() < total {
            return Decoded::NeedMore;
        }
        let ascii = |b: &[u8]| -> Result<String, HyperionError> {
            if b.is_ascii() { Ok(String::from_utf8_lossy(b).into_owned()) } else { Err(HyperionError::NotAscii) }
        };
        let parsed = ascii(&buf[HEADER_LEN..HEADER_LEN + command_len])
            .and_then(|command| Ok((command, ascii(&buf[HEADER_LEN + command_len..total])?)));
        match parsed {
            Ok((command, argument)) => {
                Decoded::Frame { packet: Request { options: buf[0], command, argument }, consumed: total }
            }
            Err(error) => Decoded::Invalid { error, consumed: total },
        }
    }
}

/// A command response (also the framing of each streamed peak frame).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Response {
    /// 0 for success; anything else is an error whose text is `message`.
    pub status: u8,
    /// Response type byte (0 here; its meaning is not documented in the public API).
    pub kind: u8,
    /// Human-readable ASCII message.
    pub message: String,
    /// Binary content.
    pub content: Vec<u8>,
}

impl Response {
    /// A success response.
    pub fn ok(message: &str, content: Vec<u8>) -> Self {
        Self { status: 0, kind: 0, message: message.to_string(), content }
    }

    /// An error response: status 1 and the message, no content (the API reads no content on error).
    pub fn error(message: &str) -> Self {
        Self { status: 1, kind: 0, message: message.to_string(), content: Vec::new() }
    }

    /// Wire bytes.
    pub fn encode(&self) -> Result<Vec<u8>, HyperionError> {
        let message_len = u16::try_from(self.message.len()).map_err(|_| HyperionError::TooLong(self.message.len()))?;
        if self.content.len() > MAX_CONTENT_LEN {
            return Err(HyperionError::TooLong(self.content.len()));
        }
        let mut out = Vec::with_capacity(HEADER_LEN + self.message.len() + self.content.len());
        out.push(self.status);
        out.push(self.kind);
        out.extend_from_slice(&message_len.to_le_bytes());
        out.extend_from_slice(&(self.content.len() as u32).to_le_bytes());
        out.extend_from_slice(self.message.as_bytes());
        out.extend_from_slice(&self.content);
        Ok(out)
    }

    /// Takes one response off the front of `buf`.
    pub fn decode(buf: &[u8]) -> Decoded<Response, HyperionError> {
        if buf.len() < HEADER_LEN {
            return Decoded::NeedMore;
        }
        let message_len = usize::from(u16::from_le_bytes([buf[2], buf[3]]));
        let content_len = u32::from_le_bytes([buf[4], buf[5], buf[6], buf[7]]) as usize;
        if content_len > MAX_CONTENT_LEN {
            return Decoded::Invalid { error: HyperionError::TooLong(content_len), consumed: buf.len() };
        }
        let total = HEADER_LEN + message_len + content_len;
        if buf.len() < total {
            return Decoded::NeedMore;
        }
        let message = String::from_utf8_lossy(&buf[HEADER_LEN..HEADER_LEN + message_len]).into_owned();
        let packet =
            Response { status: buf[0], kind: buf[1], message, content: buf[HEADER_LEN + message_len..total].to_vec() };
        Decoded::Frame { packet, consumed: total }
    }

    /// The content, or the instrument's error message.
    pub fn into_result(self) -> Result<Vec<u8>, HyperionError> {
        if self.status == 0 {
            Ok(self.content)
        } else {
            Err(HyperionError::Instrument { status: self.status, message: self.message })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn request_layout_is_byte_exact() {
        let wire = Request::new("#GetDutChannelCount", "").encode().unwrap();
        let mut expected = vec![0, 0, 19, 0, 0, 0, 0, 0];
        expected.extend_from_slice(b"#GetDutChannelCount");
        assert_eq!(wire, expected);
        let with_arg = Request::new("#SetLaserScanSpeed", "1000").encode().unwrap();
        assert_eq!(&with_arg[..8], &[0, 0, 18, 0, 4, 0, 0, 0]);
        assert_eq!(&with_arg[8 + 18..], b"1000");
    }

    #[test]
    fn response_layout_and_round_trip() {
        let r = Response::ok("4 channels", 4u32.to_le_bytes().to_vec());
        let wire = r.encode().unwrap();
        assert_eq!(&wire[..8], &[0, 0, 10, 0, 4, 0, 0, 0]);
        assert_eq!(Response::decode(&wire), Decoded::Frame { packet: r.clone(), consumed: wire.len() });
        for end in 0..wire.len() {
            assert_eq!(Response::decode(&wire[..end]), Decoded::NeedMore);
        }
        assert_eq!(r.into_result().unwrap(), 4u32.to_le_bytes().to_vec());
        let e = Response::error("Unknown command").into_result().unwrap_err();
        assert!(matches!(e, HyperionError::Instrument { status: 1, .. }));
    }

    #[test]
    fn request_round_trip_and_limits() {
        let r = Request::new("#GetPeaks", "");
        let wire = r.encode().unwrap();
        assert_eq!(Request::decode(&wire), Decoded::Frame { packet: r, consumed: wire.len() });
        let huge = [0, 0, 0, 0, 0xFF, 0xFF, 0xFF, 0x7F];
        assert!(matches!(Request::decode(&huge), Decoded::Invalid { .. }));
        let mut not_ascii = vec![0, 0, 2, 0, 0, 0, 0, 0];
        not_ascii.extend_from_slice(&[b'#', 0xC3]);
        assert!(matches!(
            Request::decode(&not_ascii),
            Decoded::Invalid { error: HyperionError::NotAscii, consumed: 10 }
        ));
    }
}
