#![doc = include_str!("../README.md")]
#![warn(missing_docs)]

pub mod bag;
pub mod cell;
pub mod config;
mod error;
pub mod node;
mod raw;
pub mod state;
pub mod watch;

pub use cell::{Ros2Cell, Ros2CellConfig};
pub use config::{ClockMode, Distro, QosProfile, Ros2Config};
pub use error::Ros2Error;
pub use node::{Node, Pub, Sub};
