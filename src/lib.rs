//! # tendril: a digital twin of an FBG-sensed grow-and-twine gripping cell
//!
//! The application crate on top of the workspace: the `tendril` command line and what only it
//! does (render and view runs, sweeps, studies, fitting and tuning, reproducing the paper). The
//! twin, the sensor model, the control loop, the drivers and the protocols are crates of their
//! own under `crates/`, one per layer; docs/architecture.md draws them and their rules.
//!
//! - [`cli`]: the subcommands.
//! - [`render`]: videos of finished runs (`tendril render`), from the MuJoCo states a run records.
//! - [`view`]: the twin live in MuJoCo's interactive viewer (`tendril view`).
//! - [`sweep`]: many runs over a grid of keys, durable and resumable (`tendril sweep`).
//! - [`study`]: studies over many runs, charted (`tendril chart`).
//! - [`fit`]: calibrating the twin to recorded runs (`tendril fit`) and tuning the controller on it
//!   (`tendril tune`).
//! - [`keys`]: the scenario key reference (`tendril keys`), generated from the code.
//! - [`reproduce`]: the paper's figures next to the twin's (`tendril reproduce`).
//! - [`signals`]: SIGINT, SIGTERM and SIGHUP as one clean stop.
//! - [`features`]: the optional parts (`viewer`, `video`) and how to build one that is missing.

#![warn(missing_docs)]

pub mod cli;
pub mod features;
pub mod fit;
pub mod keys;
pub mod render;
pub mod reproduce;
pub mod signals;
pub mod study;
pub mod sweep;
pub mod view;
