#![doc = include_str!("../README.md")]
#![warn(missing_docs)]

mod phase;
mod seam;

pub mod gripper;
pub mod interrupt;

pub use phase::{MAX_PHASE_S, Phase};
pub use seam::*;
pub use tendril_fbg::signals::Wavelengths;
