//! # tendril: a digital twin of an FBG-sensed grow-and-twine gripping cell
//!
//! Data flows one way around the loop, and the modules follow it:
//!
//! ```text
//!  cell (sim or real)                          |  control (shared)
//!  cell::physics  -> contact force             |
//!  cell::fbg      -> wavelengths (interrogator)|-> control::estimate (eq. 8) -> force
//!                                              |   control::pid, control::task -> commands
//!  cell::physics  <- actuator commands  <------|
//!                  hardware: the trait at the seam
//! ```
//!
//! - [`scenario`]: TOML scenarios, `--set` overrides and validation errors naming the key.
//! - [`cell`]: where forces and wavelengths come from (MuJoCo scene + FBG forward model).
//! - [`control`]: what runs the same on the twin and on the real cell.
//! - [`calibration`]: the paper's calibration procedures, for simulated or recorded bench data.
//! - [`reproduce`]: the paper's figures next to the twin's.
//! - [`fit`]: calibrating the twin to recorded runs (`tendril fit`) and tuning the controller on it
//!   (`tendril tune`).
//! - [`render`]: videos of finished runs (`tendril render`), from the MuJoCo states a run records.
//! - [`view`]: the twin live in MuJoCo's interactive viewer (`tendril view`).
//! - [`mujoco_log`]: MuJoCo's warnings into our log and summaries (no `MUJOCO_LOG.TXT`).
//! - [`interrupt`]: SIGINT, SIGTERM and SIGHUP as one clean stop.
//! - [`signals`]: the data types that cross the seam (wavelengths, ...).
//! - [`ur5e`]: the arm's kinematics (UR's DH table), which the cell and the control side share.

#![warn(missing_docs)]

pub mod calibration;
pub mod cell;
pub mod cli;
pub mod control;
pub mod fit;
pub mod hardware;
pub mod interrupt;
pub mod mujoco_log;
pub mod plot;
pub mod render;
pub mod reproduce;
pub mod run;
pub mod scenario;
pub mod sensor_bench;
pub mod signals;
pub mod study;
pub mod sweep;
pub mod ur5e;
pub mod view;
