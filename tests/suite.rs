//! The integration tests that run on simulated time: one test binary, each file a module.
//!
//! One binary instead of one per file: the ~40 files each linked the whole workspace on their own,
//! most of a fresh `cargo xtask test`'s build after the libraries, and each binary's last test
//! left a core idle. `cargo test --test suite backend_rapier::` runs one file's tests. The
//! real-time tests are in `real_time.rs`, and `mujoco_warnings.rs`, which changes the working
//! directory, has a binary of its own.

mod common;

mod adaptive_map;
mod array_peaks;
mod backend_rapier;
mod bounded_inputs;
mod chart_controllers;
mod chart_placement;
mod cli_robust;
mod cli_run;
mod controller_seam;
mod controllers;
mod convergence;
mod cycle;
mod disturbances;
mod docs_links;
mod fit;
mod fit_targets;
mod fuzz;
mod gripper_reproduce;
mod guarded_close;
mod guide_pruning;
mod long_hold;
mod object_files;
mod physics_metamorphic;
mod physics_validation;
mod plot;
mod produce;
mod protocol_props;
mod readme_tour;
#[cfg(feature = "video")]
mod render;
mod results_durability;
mod ros2_msgs_package;
mod run_reproducible;
mod scenario_keys;
mod scene_export;
mod section_v_unchanged;
mod sensor_array;
mod sensor_bad_input;
mod sensor_hysteresis_compensation;
mod sensor_reproduce;
mod sensor_roundtrip;
mod slip_detection;
#[cfg(feature = "viewer")]
mod view;
