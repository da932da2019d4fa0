#![doc = include_str!("../README.md")]
#![warn(missing_docs)]

pub mod cdr;
pub mod graph;
mod message;
pub mod names;
mod std_types;
mod tendril_types;

pub use cdr::{CdrError, CdrReader, CdrWriter};
pub use message::{Message, SCHEMA_SEPARATOR, TypeInfo, from_body, from_payload, to_body, to_payload};
pub use std_types::{Clock, Header, JointState, StringMsg, Time, Vector3, Wrench, WrenchStamped};
pub use tendril_types::{ControlTick, FbgPeaks};

#[cfg(test)]
mod tests;
