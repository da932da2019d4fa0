//! Sans-IO protocol codecs: no sockets, no serial ports, no clocks.
//!
//! Each protocol decodes frames incrementally from a byte buffer (see [`Decoded`]) and encodes
//! typed packets to bytes. The IO layer owns the buffers and the timing; these modules only
//! turn bytes into packets and packets into replies, so they are tested byte for byte.
//!
//! - [`rtde`]: UR Real-Time Data Exchange (TCP 30004), client and server sessions.
//! - [`dashboard`]: the UR Dashboard Server's commands and replies (TCP 29999).
//! - [`dynamixel`]: Dynamixel Protocol 2.0 packets and a virtual MX-106 bus.
//! - [`hyperion`]: Luna HYPERION si255 commands, peak frames and FBG1/FBG2 mapping.

pub mod dashboard;
pub mod dynamixel;
pub mod hyperion;
pub mod rtde;

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
