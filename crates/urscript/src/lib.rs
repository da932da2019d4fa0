#![doc = include_str!("../README.md")]
#![warn(missing_docs)]

pub mod ast;
pub mod builtins;
pub mod call;
pub mod compile;
pub mod controller;
mod error;
mod follow;
pub mod interp;
pub mod lexer;
pub mod motion;
pub mod parser;
pub mod setup;
mod sockets;
pub mod stream;
pub mod value;
mod watchdog;

pub use controller::{Controller, DigitalOut, SocketState};
pub use error::ScriptError;
pub use follow::{
    ENABLE_REGISTER, FOLLOW_SCRIPT, FOLLOWING_REGISTER, STAMP_REGISTER, TARGET_REGISTER, input_names,
    is_complete_program,
};
pub use interp::{Interpreter, Status};
pub use setup::Setup;
pub use watchdog::{RtdeWatchdog, WatchdogAction};

#[cfg(test)]
mod driver_tests;
#[cfg(test)]
mod tests;
