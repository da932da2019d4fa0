#![doc = include_str!("../README.md")]
#![warn(missing_docs)]

mod array_estimates;
pub mod array_summary;
mod backend_defaults;
pub mod bag;
pub mod clock;
pub mod compare;
pub mod detector;
pub mod drop_watch;
pub mod execute;
pub mod metrics;
pub mod object_table;
pub mod output;
mod paths;
pub mod plan;
mod produce_defaults;
pub mod produce_summary;
pub mod real;
pub mod report;
pub mod ros2;
pub mod runner;
mod samples;
pub mod scenario;
pub mod session;
pub mod summary;
pub mod trace;
