#![doc = include_str!("../README.md")]
#![warn(missing_docs)]

pub mod kinematics;
pub mod pose;
pub mod safety;

pub use kinematics::{HOME, forward, inverse_near};
