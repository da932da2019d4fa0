//! Luna (Micron Optics) HYPERION si255: commands on TCP 51971, peak stream on TCP 51972.
//!
//! - [`message`]: request/response framing (8-byte little-endian headers).
//! - [`peaks`]: the peak data frame, and serial-number continuity of the stream.
//! - [`device`]: [`VirtualInterrogator`], the device side `tendril serve` runs.
//! - [`fbg_map`]: peaks to FBG1/FBG2 by wavelength window.
//! - [`stream`]: the peak stream's backlog and divider.
//! - [`spectrum`]: `#GetSpectrum`, power calibration and detection setting contents.

pub mod device;
pub mod fbg_map;
pub mod message;
pub mod peaks;
pub mod spectrum;
pub mod stream;

pub use device::{InterrogatorConfig, VirtualInterrogator};
pub use fbg_map::{FbgMapError, FbgWindows};
pub use message::{Request, Response};
pub use peaks::{PeakFrame, PeakHeader, PeakSequence, SequenceCheck, decode_stream_frame};

/// TCP port for commands.
pub const COMMAND_PORT: u16 = 51971;
/// TCP port of the peak stream.
pub const PEAK_STREAM_PORT: u16 = 51972;

/// HYPERION protocol errors.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum HyperionError {
    /// A field longer than its length field or our cap.
    #[error("{0} bytes exceed the length limit")]
    TooLong(usize),
    /// Command or argument not ASCII.
    #[error("command or argument is not ASCII")]
    NotAscii,
    /// Peak content malformed.
    #[error("malformed peak data ({len} bytes): {reason}")]
    BadPeakData {
        /// What is wrong.
        reason: &'static str,
        /// Content length.
        len: usize,
    },
    /// The instrument answered with an error.
    #[error("instrument error (status {status}): {message}")]
    Instrument {
        /// Non-zero status.
        status: u8,
        /// Its message.
        message: String,
    },
    /// Virtual instrument misconfigured.
    #[error("invalid interrogator configuration: {0}")]
    BadConfig(String),
}
