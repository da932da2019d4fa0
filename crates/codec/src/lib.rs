#![doc = include_str!("../README.md")]
#![warn(missing_docs)]

/// The outcome of trying to take one frame off the front of a byte buffer.
#[derive(Debug, Clone, PartialEq)]
pub enum Decoded<P, E> {
    /// The buffer holds the start of a frame (or nothing): read more bytes and try again.
    NeedMore,
    /// A whole frame: the packet, and how many bytes of the buffer it used.
    Frame {
        /// The decoded packet.
        packet: P,
        /// Bytes to drop from the front of the buffer.
        consumed: usize,
    },
    /// The bytes at the front are not a valid frame.
    Invalid {
        /// Why.
        error: E,
        /// Bytes to drop from the front of the buffer before trying again (always at least 1).
        consumed: usize,
    },
}
