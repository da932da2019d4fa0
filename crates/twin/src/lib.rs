#![doc = include_str!("../README.md")]
#![warn(missing_docs)]

pub mod disturbance;
pub mod frames;
pub mod mujoco_log;
pub mod physics;
pub mod sim;
pub mod wrist;
