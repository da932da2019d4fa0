#![doc = include_str!("../README.md")]
#![warn(missing_docs)]

pub mod arrival;
mod bus;
pub mod config;
pub mod controller;
pub mod dashboard;
mod handle;
pub mod io;
pub mod jitter;
pub mod lockstep;
mod net;
pub mod primary;
pub mod program;
pub mod robot_messages;
pub mod robot_state;
pub mod ros2;
mod ros2_clock;
mod ros2_commands;
pub mod sensor_node;
mod setpoint;
pub mod sockets;
pub mod state;
mod twin;

pub use config::{IDLE_TIMEOUT, ServeConfig, UrAddrs};
pub use controller::{UrController, VirtualUrSetup};
pub use handle::{ServeHandle, start};
pub use jitter::{Jitter, JitterModel, JitterProfile};
pub use ros2::{Ros2Bridge, Ros2Serving};
pub use ros2_commands::{MotorDrives, MotorTarget, RosCommand, VELOCITY_HOLD_S, parse_command};
pub use state::{DeviceState, ProgramState, TwinStatus};
