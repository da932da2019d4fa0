//! The paper's sensor bench (Sec. IV), simulated: a linear actuator loading the sensor on a load
//! cell, a heated water bath, and the taped compensation test. Each run yields a
//! [`BenchRecord`](crate::calibration::BenchRecord) that the calibration procedures read exactly as
//! they read a CSV recorded on the real bench.

mod config;
mod profile;
mod run;
mod tune;

pub use config::{BenchScenario, ForceCycles, LoadCellConfig, RecorderConfig, TapedHeating, WaterBath};
pub use profile::Profile;
pub use run::run;
pub use tune::solve_strain_coefficients;
