#![doc = include_str!("../README.md")]
#![warn(missing_docs)]

pub mod client;
pub mod dashboard;
mod data_type;
mod error;
pub mod fields;
pub mod packet;
pub mod primary;
pub mod recipe;
pub mod server;
pub mod state;
pub mod types;

pub use client::{ClientEvent, ClientSession};
pub use error::RtdeError;
pub use packet::{ClientPacket, ControllerVersion, MessageLevel, ServerPacket, TextMessage};
pub use recipe::Recipe;
pub use server::{ServerConfig, ServerSession, SharedInputs};
pub use state::{RobotInputs, RobotOutputs};
pub use types::{FieldType, RtdeType, RtdeValue};

#[cfg(test)]
mod tests;
