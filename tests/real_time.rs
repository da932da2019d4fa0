//! The integration tests that run the virtual devices in real time, behind live sockets and a
//! pty: one test binary, each file a module, apart from `suite.rs` so that they never share the
//! machine with the simulated-time tests; inside it they take turns (`common::one_at_a_time`).
//! `cargo test --test real_time real_path::` runs one file's tests.

mod common;

mod python_clients;
mod real_path;
mod real_path_controllers;
mod ros2;
mod serve_run_e2e;
mod virtual_dashboard;
mod virtual_hyperion;
mod virtual_ur;
mod virtual_ur_driver;
