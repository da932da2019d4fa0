#![doc = include_str!("../README.md")]
#![warn(missing_docs)]

pub mod array_windows;
pub mod device;
mod error;
pub mod fbg_map;
pub mod message;
pub mod pad_windows;
pub mod peaks;
mod ports;
pub mod spectrum;
pub mod stream;

pub use array_windows::WindowFault;
pub use device::{InterrogatorConfig, VirtualInterrogator};
pub use error::HyperionError;
pub use fbg_map::{FbgMapError, FbgWindows};
pub use message::{Request, Response};
pub use pad_windows::{PadWindowList, PadWindows};
pub use peaks::{PeakFrame, PeakHeader, PeakSequence, SequenceCheck, decode_stream_frame};
pub use ports::{COMMAND_PORT, PEAK_STREAM_PORT};
