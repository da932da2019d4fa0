#![doc = include_str!("../README.md")]
#![warn(missing_docs)]

mod bar_axes;
mod chart;
mod error;
mod path;

pub mod controller_runs;
pub mod controllers;
pub mod controllers_summary;
pub mod convergence;
pub mod fit;
pub mod gain_map;
pub mod grid;
pub mod input;
pub mod jitter;
pub mod panels;
pub mod placement;
pub mod produce;
pub mod speed_accuracy;
pub mod stability;
pub mod style;
pub mod sweep;
pub mod trace;

pub use chart::{Chart, DrawResult, save};
pub use error::PlotError;
pub use path::plot_path;
