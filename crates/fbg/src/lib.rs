#![doc = include_str!("../README.md")]
#![warn(missing_docs)]

pub mod array;
pub mod array_spectrum;
pub mod bench;
pub mod calibration;
mod config;
pub mod estimate;
pub mod hysteresis;
mod sensor;
pub mod signals;
mod spectral;
mod thermal;

pub use config::{InterrogatorConfig, InterrogatorMode, SensorConfig, SpectralConfig};
pub use sensor::FbgSensor;
pub use spectral::{SpectralInterrogator, centroid, line_spectrum};
pub use thermal::ThermalLag;
