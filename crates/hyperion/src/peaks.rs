//! Peak data: the content of `#GetPeaks` and of each frame streamed on TCP 51972.
//!
//! Layout (docs/facts.md#hyperion-peak-data-layout, from Luna's `hyperion.py`): a 24-byte header `u16 length,
//! u8 buffer_available, u8 version, u32 reserved, u64 serial_number, u32 timestamp_s,
//! u32 timestamp_ns`, then one i16 peak count per channel up to `length` bytes, then the f64
//! peak wavelengths (nm) of all channels in channel order. Little-endian.

use super::HyperionError;
use super::message::Response;
use tendril_codec::Decoded;

/// Fixed part of the peak header, in bytes.
pub const PEAK_HEADER_LEN: usize = 24;

/// Peak header fields other than the lengths.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PeakHeader {
    /// Acquisition buffer fill (%).
    pub buffer_available: u8,
    /// Format version.
    pub version: u8,
    /// Reserved.
    pub reserved: u32,
    /// Scan serial number; consecutive frames differ by exactly 1.
    pub serial_number: u64,
    /// Timestamp, whole seconds.
    pub timestamp_s: u32,
    /// Timestamp, nanoseconds part.
    pub timestamp_ns: u32,
}

/// One scan's peaks.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PeakFrame {
    /// Header.
    pub header: PeakHeader,
    /// Peak wavelengths (nm) per channel; index 0 is channel 1.
    pub channels: Vec<Vec<f64>>,
}

impl PeakFrame {
    /// Peaks of channel `n` (1-based, as the instrument numbers them).
    pub fn channel(&self, n: usize) -> Option<&[f64]> {
        n.checked_sub(1).and_then(|i| self.channels.get(i)).map(Vec::as_slice)
    }

    /// Encodes to content bytes.
    pub fn encode(&self) -> Result<Vec<u8>, HyperionError> {
        let length = PEAK_HEADER_LEN + 2 * self.channels.len();
        let length16 = u16::try_from(length).map_err(|_| HyperionError::TooLong(length))?;
        let h = &self.header;
        let total_peaks: usize = self.channels.iter().map(Vec::len).sum();
        let mut out = Vec::with_capacity(length + 8 * total_peaks);
        out.extend_from_slice(&length16.to_le_bytes());
        out.push(h.buffer_available);
        out.push(h.version);
        out.extend_from_slice(&h.reserved.to_le_bytes());
        out.extend_from_slice(&h.serial_number.to_le_bytes());
        out.extend_from_slice(&h.timestamp_s.to_le_bytes());
        out.extend_from_slice(&h.timestamp_ns.to_le_bytes());
        for peaks in &self.channels {
            let count = i16::try_from(peaks.len()).map_err(|_| HyperionError::TooLong(peaks.len()))?;
            out.extend_from_slice(&count.to_le_bytes());
        }
        for peak in self.channels.iter().flatten() {
            out.extend_from_slice(&peak.to_le_bytes());
        }
        Ok(out)
    }

    /// Decodes content bytes (exactly one frame).
    pub fn decode(content: &[u8]) -> Result<PeakFrame, HyperionError> {
        let bad = |reason: &'static str| HyperionError::BadPeakData { reason, len: content.len() };
        if content.len() < PEAK_HEADER_LEN {
            return Err(bad("shorter than the 24-byte header"));
        }
        let u32_at = |i: usize| u32::from_le_bytes([content[i], content[i + 1], content[i + 2], content[i + 3]]);
        let length = usize::from(u16::from_le_bytes([content[0], content[1]]));
        if length < PEAK_HEADER_LEN || !(length - PEAK_HEADER_LEN).is_multiple_of(2) || length > content.len() {
            return Err(bad("header length field inconsistent"));
        }
        let mut serial = [0u8; 8];
        serial.copy_from_slice(&content[8..16]);
        let header = PeakHeader {
            buffer_available: content[2],
            version: content[3],
            reserved: u32_at(4),
            serial_number: u64::from_le_bytes(serial),
            timestamp_s: u32_at(16),
            timestamp_ns: u32_at(20),
        };
        let counts: Vec<usize> = content[PEAK_HEADER_LEN..length]
            .chunks_exact(2)
            .map(|c| usize::try_from(i16::from_le_bytes([c[0], c[1]])).map_err(|_| bad("negative peak count")))
            .collect::<Result<_, _>>()?;
        let peak_bytes = &content[length..];
        if peak_bytes.len() != 8 * counts.iter().sum::<usize>() {
            return Err(bad("peak count does not match the data"));
        }
        let mut values = peak_bytes.chunks_exact(8).map(|c| {
            let mut b = [0u8; 8];
            b.copy_from_slice(c);
            f64::from_le_bytes(b)
        });
        let channels = counts.iter().map(|&n| values.by_ref().take(n).collect()).collect();
        Ok(PeakFrame { header, channels })
    }
}

/// Takes one streamed peak frame (8-byte response header, then peak content) off the front of
/// `buf`, as received on the peak stream port.
pub fn decode_stream_frame(buf: &[u8]) -> Decoded<PeakFrame, HyperionError> {
    match Response::decode(buf) {
        Decoded::NeedMore => Decoded::NeedMore,
        Decoded::Invalid { error, consumed } => Decoded::Invalid { error, consumed },
        Decoded::Frame { packet, consumed } => match packet.into_result().and_then(|c| PeakFrame::decode(&c)) {
            Ok(frame) => Decoded::Frame { packet: frame, consumed },
            Err(error) => Decoded::Invalid { error, consumed },
        },
    }
}

/// What a new serial number says about the stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SequenceCheck {
    /// First frame seen.
    First,
    /// Exactly the next frame.
    Next,
    /// Frames were lost.
    Gap {
        /// How many serial numbers were skipped.
        missed: u64,
    },
    /// The serial number did not increase (instrument restart or a replayed frame).
    NotIncreasing,
}

/// Tracks streamed serial numbers (consecutive frames differ by exactly 1).
#[derive(Debug, Clone, Copy, Default)]
pub struct PeakSequence {
    last: Option<u64>,
}

impl PeakSequence {
    /// Records a frame's serial number.
    pub fn observe(&mut self, serial: u64) -> SequenceCheck {
        let check = match self.last {
            None => SequenceCheck::First,
            Some(last) if serial == last.wrapping_add(1) => SequenceCheck::Next,
            Some(last) if serial > last => SequenceCheck::Gap { missed: serial - last - 1 },
            Some(_) => SequenceCheck::NotIncreasing,
        };
        self.last = Some(serial);
        check
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame() -> PeakFrame {
        PeakFrame {
            header: PeakHeader {
                buffer_available: 5,
                version: 1,
                reserved: 0,
                serial_number: 0x0102_0304_0506_0708,
                timestamp_s: 1_700_000_000,
                timestamp_ns: 250_000_000,
            },
            channels: vec![vec![1540.1, 1550.2], vec![], vec![1530.0], vec![]],
        }
    }

    #[test]
    fn layout_is_byte_exact() {
        let bytes = frame().encode().unwrap();
        assert_eq!(&bytes[..2], &32u16.to_le_bytes()); // 24 + 4 channels * 2
        assert_eq!(bytes[2..4], [5, 1]);
        assert_eq!(&bytes[8..16], &[8, 7, 6, 5, 4, 3, 2, 1]);
        assert_eq!(&bytes[24..32], &[2, 0, 0, 0, 1, 0, 0, 0]);
        assert_eq!(&bytes[32..40], &1540.1f64.to_le_bytes());
        assert_eq!(bytes.len(), 32 + 3 * 8);
        assert_eq!(PeakFrame::decode(&bytes).unwrap(), frame());
    }

    #[test]
    fn inconsistent_counts_are_errors() {
        let mut bytes = frame().encode().unwrap();
        bytes.pop();
        assert!(PeakFrame::decode(&bytes).is_err());
        let mut negative = frame().encode().unwrap();
        negative[24..26].copy_from_slice(&(-1i16).to_le_bytes());
        assert!(PeakFrame::decode(&negative).is_err());
        assert!(PeakFrame::decode(&[0; 10]).is_err());
    }

    #[test]
    fn stream_frames_decode_back_to_back() {
        let one = Response::ok("", frame().encode().unwrap()).encode().unwrap();
        let mut two = one.clone();
        two.extend_from_slice(&one[..10]);
        let Decoded::Frame { packet, consumed } = decode_stream_frame(&two) else { panic!("no frame") };
        assert_eq!((packet, consumed), (frame(), one.len()));
        assert_eq!(decode_stream_frame(&two[consumed..]), Decoded::NeedMore);
    }

    #[test]
    fn sequence_detects_gaps() {
        let mut s = PeakSequence::default();
        assert_eq!(s.observe(10), SequenceCheck::First);
        assert_eq!(s.observe(11), SequenceCheck::Next);
        assert_eq!(s.observe(14), SequenceCheck::Gap { missed: 2 });
        assert_eq!(s.observe(14), SequenceCheck::NotIncreasing);
    }
}
