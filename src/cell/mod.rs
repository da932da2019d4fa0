//! The cell: where contact forces and wavelengths come from (simulation now, real drivers later).
//!
//! - [`physics`]: the MuJoCo scene (contact forces, object, finger, arm).
//! - [`fbg`]: the FBG forward model and interrogator (wavelengths from force and temperature).
//! - [`sim`]: both behind [`crate::hardware::Cell`]: the twin.
//! - [`real`]: the real devices' protocols.
pub mod fbg;
pub mod physics;
pub mod real;
pub mod sim;
