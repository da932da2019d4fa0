//! OMG CDR (XCDR version 1, "plain CDR"), the encoding of every ROS 2 message on the wire and in
//! a rosbag2 bag: primitives aligned to their own size relative to the start of the message body,
//! strings as a `u32` length that counts the closing NUL, sequences as a `u32` count and their
//! elements. The body follows a four-byte encapsulation header (`00 01 00 00`: little-endian CDR)
//! in a bag and in an RTPS `DATA` submessage.

/// The encapsulation header of a little-endian CDR body (representation `CDR_LE`, options 0).
pub const CDR_LE_HEADER: [u8; 4] = [0x00, 0x01, 0x00, 0x00];

/// Longest sequence or string a decoder accepts \[elements\]: a message on a configured topic
/// is a few hundred bytes, and a corrupt length must fail fast instead of asking for gigabytes.
/// The count is also checked against the bytes left, so this bound only matters for sequences of
/// zero-sized elements; it is the bound a reader states.
pub const MAX_SEQUENCE_LEN: usize = 1 << 20;

/// Why bytes could not be decoded as a message.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum CdrError {
    /// The body ended inside a field.
    #[error("truncated: {field} needs {needed} byte(s) at offset {offset}, {left} left")]
    Truncated {
        /// The field being read.
        field: &'static str,
        /// Its offset in the body.
        offset: usize,
        /// Bytes it needs.
        needed: usize,
        /// Bytes left.
        left: usize,
    },
    /// A string that is not NUL-terminated UTF-8.
    #[error("{field}: not a NUL-terminated UTF-8 string at offset {offset}")]
    BadString {
        /// The field being read.
        field: &'static str,
        /// Its offset in the body.
        offset: usize,
    },
    /// A sequence or string length beyond what the bytes left could hold.
    #[error("{field}: length {len} at offset {offset} is more than the message holds")]
    BadLength {
        /// The field being read.
        field: &'static str,
        /// Its offset in the body.
        offset: usize,
        /// The length read.
        len: usize,
    },
    /// A boolean byte other than 0 or 1.
    #[error("{field}: {value} at offset {offset} is not a boolean (0 or 1)")]
    BadBool {
        /// The field being read.
        field: &'static str,
        /// Its offset in the body.
        offset: usize,
        /// The byte read.
        value: u8,
    },
    /// An encapsulation header this decoder does not read.
    #[error("encapsulation {0:02x?}: not plain CDR (expected 00 00 big-endian or 00 01 little-endian)")]
    Encapsulation([u8; 2]),
}

/// Writes a CDR body, little-endian.
#[derive(Debug, Default, Clone)]
pub struct CdrWriter {
    buf: Vec<u8>,
}

impl CdrWriter {
    /// An empty body.
    pub fn new() -> CdrWriter {
        CdrWriter::default()
    }

    /// The body written.
    pub fn into_bytes(self) -> Vec<u8> {
        self.buf
    }

    fn align(&mut self, n: usize) {
        let pad = (n - self.buf.len() % n) % n;
        self.buf.resize(self.buf.len() + pad, 0);
    }

    /// A `bool` (one byte, 0 or 1).
    pub fn bool(&mut self, v: bool) {
        self.buf.push(u8::from(v));
    }

    /// An `uint8`.
    pub fn u8(&mut self, v: u8) {
        self.buf.push(v);
    }

    /// An `int32`.
    pub fn i32(&mut self, v: i32) {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    /// An `uint32`.
    pub fn u32(&mut self, v: u32) {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    /// A `float64`.
    pub fn f64(&mut self, v: f64) {
        self.align(8);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    /// A `string`: its length with the NUL, its bytes, the NUL.
    pub fn string(&mut self, s: &str) {
        self.u32(len_u32(s.len() + 1));
        self.buf.extend_from_slice(s.as_bytes());
        self.buf.push(0);
    }

    /// A `string[]`.
    pub fn strings<S: AsRef<str>>(&mut self, v: &[S]) {
        self.u32(len_u32(v.len()));
        for s in v {
            self.string(s.as_ref());
        }
    }

    /// A `float64[]`.
    pub fn f64s(&mut self, v: &[f64]) {
        self.u32(len_u32(v.len()));
        for &x in v {
            self.f64(x);
        }
    }

    /// A fixed `uint8[N]` (no count).
    pub fn bytes(&mut self, v: &[u8]) {
        self.buf.extend_from_slice(v);
    }
}

/// A length as CDR's `uint32`. Messages tendril writes hold a handful of joints and pads, so a
/// length beyond `u32` is a bug, not input.
fn len_u32(n: usize) -> u32 {
    u32::try_from(n).expect("a CDR length fits in 32 bits")
}

/// Reads a CDR body; every read checks the bytes left, so malformed input is an error, never a
/// panic or a huge allocation.
#[derive(Debug, Clone)]
pub struct CdrReader<'a> {
    body: &'a [u8],
    pos: usize,
    big_endian: bool,
}

impl<'a> CdrReader<'a> {
    /// A reader of a little-endian body (no encapsulation header).
    pub fn new(body: &'a [u8]) -> CdrReader<'a> {
        CdrReader { body, pos: 0, big_endian: false }
    }

    /// A reader of `payload`, an encapsulation header and its body (a bag's message, a `DATA`
    /// submessage's payload): plain CDR in either byte order.
    pub fn with_header(payload: &'a [u8]) -> Result<CdrReader<'a>, CdrError> {
        let Some((header, body)) = payload.split_first_chunk::<4>() else {
            return Err(CdrError::Truncated { field: "encapsulation", offset: 0, needed: 4, left: payload.len() });
        };
        let big_endian = match [header[0], header[1]] {
            [0x00, 0x00] => true,
            [0x00, 0x01] => false,
            other => return Err(CdrError::Encapsulation(other)),
        };
        Ok(CdrReader { body, pos: 0, big_endian })
    }

    /// Bytes not read yet (a body may end in up to three bytes of padding).
    pub fn remaining(&self) -> usize {
        self.body.len() - self.pos
    }

    fn take(&mut self, field: &'static str, align: usize, n: usize) -> Result<&'a [u8], CdrError> {
        let start = self.pos.div_ceil(align) * align;
        let left = self.body.len().saturating_sub(start);
        if left < n {
            return Err(CdrError::Truncated { field, offset: start, needed: n, left });
        }
        self.pos = start + n;
        Ok(&self.body[start..start + n])
    }

    fn array<const N: usize>(&mut self, field: &'static str) -> Result<[u8; N], CdrError> {
        let mut a: [u8; N] = self.take(field, N, N)?.try_into().expect("take returns N bytes");
        if self.big_endian {
            a.reverse();
        }
        Ok(a)
    }

    /// A `bool`.
    pub fn bool(&mut self, field: &'static str) -> Result<bool, CdrError> {
        let offset = self.pos;
        match self.take(field, 1, 1)?[0] {
            0 => Ok(false),
            1 => Ok(true),
            value => Err(CdrError::BadBool { field, offset, value }),
        }
    }

    /// An `uint8`.
    pub fn u8(&mut self, field: &'static str) -> Result<u8, CdrError> {
        Ok(self.take(field, 1, 1)?[0])
    }

    /// An `int32`.
    pub fn i32(&mut self, field: &'static str) -> Result<i32, CdrError> {
        self.array(field).map(i32::from_le_bytes)
    }

    /// An `uint32`.
    pub fn u32(&mut self, field: &'static str) -> Result<u32, CdrError> {
        self.array(field).map(u32::from_le_bytes)
    }

    /// A `float64`.
    pub fn f64(&mut self, field: &'static str) -> Result<f64, CdrError> {
        self.array(field).map(f64::from_le_bytes)
    }

    /// A sequence's count, checked against the bytes left (each element takes at least
    /// `min_element` bytes) and [`MAX_SEQUENCE_LEN`].
    fn count(&mut self, field: &'static str, min_element: usize) -> Result<usize, CdrError> {
        let offset = self.pos;
        let len = self.u32(field)? as usize;
        if len > MAX_SEQUENCE_LEN || len.saturating_mul(min_element) > self.remaining() {
            return Err(CdrError::BadLength { field, offset, len });
        }
        Ok(len)
    }

    /// A `string`.
    pub fn string(&mut self, field: &'static str) -> Result<String, CdrError> {
        let offset = self.pos;
        let len = self.count(field, 1)?;
        let bytes = self.take(field, 1, len)?;
        match bytes.split_last() {
            Some((0, text)) => {
                std::str::from_utf8(text).map(str::to_string).map_err(|_| CdrError::BadString { field, offset })
            }
            _ => Err(CdrError::BadString { field, offset }),
        }
    }

    /// A `string[]`.
    pub fn strings(&mut self, field: &'static str) -> Result<Vec<String>, CdrError> {
        // Each string takes at least its length word and its NUL.
        let n = self.count(field, 5)?;
        (0..n).map(|_| self.string(field)).collect()
    }

    /// A `float64[]`.
    pub fn f64s(&mut self, field: &'static str) -> Result<Vec<f64>, CdrError> {
        let n = self.count(field, 8)?;
        (0..n).map(|_| self.f64(field)).collect()
    }

    /// A fixed `uint8[N]`.
    pub fn bytes<const N: usize>(&mut self, field: &'static str) -> Result<[u8; N], CdrError> {
        Ok(self.take(field, 1, N)?.try_into().expect("take returns N bytes"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn primitives_align_to_their_size_from_the_body_start() {
        let mut w = CdrWriter::new();
        w.bool(true);
        w.u32(7);
        w.u8(9);
        w.f64(1.5);
        w.string("ab");
        let bytes = w.into_bytes();
        assert_eq!(
            bytes,
            [
                1, 0, 0, 0, // bool, pad to 4
                7, 0, 0, 0, // u32
                9, 0, 0, 0, 0, 0, 0, 0, // u8, pad to 16
                0, 0, 0, 0, 0, 0, 0xf8, 0x3f, // 1.5
                3, 0, 0, 0, b'a', b'b', 0 // "ab" with its NUL
            ]
        );
        let mut r = CdrReader::new(&bytes);
        assert!(r.bool("b").unwrap());
        assert_eq!(r.u32("u").unwrap(), 7);
        assert_eq!(r.u8("c").unwrap(), 9);
        assert_eq!(r.f64("f").unwrap(), 1.5);
        assert_eq!(r.string("s").unwrap(), "ab");
        assert_eq!(r.remaining(), 0);
    }

    #[test]
    fn malformed_bodies_are_errors_naming_the_field() {
        // A string length beyond the body.
        let e = CdrReader::new(&[200, 0, 0, 0, b'a', 0]).string("frame_id").unwrap_err();
        assert!(matches!(e, CdrError::BadLength { field: "frame_id", len: 200, .. }), "{e}");
        // A sequence count of four billion elements.
        let e = CdrReader::new(&[0xff, 0xff, 0xff, 0xff]).f64s("position").unwrap_err();
        assert!(matches!(e, CdrError::BadLength { field: "position", .. }), "{e}");
        // No NUL.
        let e = CdrReader::new(&[2, 0, 0, 0, b'a', b'b']).string("name").unwrap_err();
        assert!(matches!(e, CdrError::BadString { .. }), "{e}");
        // Ends inside a float.
        let e = CdrReader::new(&[1, 2, 3]).f64("x").unwrap_err();
        assert_eq!(e.to_string(), "truncated: x needs 8 byte(s) at offset 0, 3 left");
        assert!(matches!(CdrReader::new(&[2]).bool("b"), Err(CdrError::BadBool { value: 2, .. })));
        assert!(matches!(CdrReader::with_header(&[0, 7, 0, 0]), Err(CdrError::Encapsulation([0, 7]))));
        assert!(CdrReader::with_header(&[0, 1]).is_err());
    }

    #[test]
    fn big_endian_bodies_read_too() {
        let mut r =
            CdrReader::with_header(&[0, 0, 0, 0, 0, 0, 0, 5, 0, 0, 0, 0, 0x3f, 0xf8, 0, 0, 0, 0, 0, 0]).unwrap();
        assert_eq!(r.u32("n").unwrap(), 5);
        assert_eq!(r.f64("x").unwrap(), 1.5);
    }
}
