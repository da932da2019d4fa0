//! The si255's TCP ports.

/// TCP port for commands.
pub const COMMAND_PORT: u16 = 51971;
/// TCP port of the peak stream.
pub const PEAK_STREAM_PORT: u16 = 51972;
