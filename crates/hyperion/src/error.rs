//! [`HyperionError`]: why bytes are not a valid frame or packet.

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
