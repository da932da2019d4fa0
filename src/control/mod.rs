//! Control code shared by the simulated and the real cell: it talks to the cell only through
//! [`crate::hardware::Cell`].
//!
//! - [`pid`]: the force controller (output: twine motor speed).
//! - [`trajectory`]: joint-space moves within the paper's speed and acceleration limits.

pub mod pid;
pub mod trajectory;
