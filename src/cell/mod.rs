//! The cell: where contact forces and wavelengths come from (simulation now, real drivers later).
//!
//! - [`physics`]: the MuJoCo scene (contact forces, object, finger, arm).
//! - [`fbg`]: the FBG forward model and interrogator (wavelengths from force and temperature).
//! - [`sim`]: both behind [`crate::hardware::Cell`]: the twin.
//! - [`real`]: the real devices' protocols.
//! - [`wrist`]: the arm's wrist force sensor on the twin (the load the tool carries).
//! - [`disturbance`]: what the twin can inflict on a run (a push on the object, a sensor dropout).
pub mod disturbance;
pub mod fbg;
pub mod physics;
pub mod real;
pub mod sim;
pub mod wrist;
