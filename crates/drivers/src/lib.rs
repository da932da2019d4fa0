#![doc = include_str!("../README.md")]
#![warn(missing_docs)]

pub mod cell;
pub mod config;
pub mod dashboard;
pub mod dxl;
pub mod dxl_link;
pub mod interrogator;
pub mod latency;
pub mod realtime;
pub mod tcp;
pub mod ur;

pub use cell::{RealCell, RealCellConfig, Watchdog};
pub use config::HardwareConfig;
