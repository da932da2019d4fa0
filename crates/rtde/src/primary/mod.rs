//! The primary and secondary client interfaces (TCP 30001 and 30002), controller to client,
//! sans-IO: every package is `i32 size` (the whole package), `u8 message type`, then its body,
//! big-endian. The controller sends a version message when a client connects, then a robot state
//! message ([`state`]) ten times a second; the primary interface also sends robot messages
//! ([`message`]: text, key messages when a program starts or stops, runtime exceptions, ...).
//! The other direction is URScript text, which `tendril-urscript`'s `stream` splits.
//!
//! Layouts: Universal Robots, "Client Interfaces" (the e-Series / PolyScope 5 pages), and what UR's
//! C++ client library (`Universal_Robots_Client_Library`, `src/primary/`) parses; sizes checked
//! against a UR5e's robot state from URSim 5.8 (see [`state`]).

mod checksum;
mod error;
pub mod message;
mod package;
pub mod state;
mod wire;

pub use error::PrimaryError;
pub use message::{Message, RobotMessage, Version};
pub use package::{HEADER_LEN, MAX_PACKAGE_LEN, Package, ROBOT_MESSAGE, ROBOT_STATE};
pub use state::SubPackage;

#[cfg(test)]
mod tests;
