#![doc = include_str!("../README.md")]
#![warn(missing_docs)]

pub mod array_cue;
pub mod config;
pub mod contact;
pub mod controller;
pub mod feedforward;
pub mod hold;
pub mod limits;
pub mod load;
pub mod pid;
pub mod settle;
pub mod slip;
pub mod slip_margin;
pub mod task;
pub mod trajectory;

pub use config::ControllerConfig;
