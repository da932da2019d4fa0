//! The paper's calibration procedures (Sec. IV), on simulated or recorded bench data.
//!
//! Everything works on a [`BenchRecord`] (time, load-cell force, both wavelengths, thermometer),
//! whether it comes from `sensor_bench` (simulation) or from a CSV recorded on a real bench.

mod cycles;
mod error;
mod fit;
mod force;
mod record;
pub mod report;
mod temperature;

pub use cycles::{Branch, Cycle, max_branch_gap, segment, smooth};
pub use error::CalibrationError;
pub use fit::{FitError, PolyFit, least_squares, poly_fit};
pub use force::{
    COMPENSATION_PLAY_WIDTHS_N, Comparison, ForceFit, HYSTERESIS_BIN_N, TARE_WINDOW_S, compare, fit_hysteresis_model,
    force_calibration, track_all,
};
pub use record::{BenchRecord, BenchRow, CSV_HEADER, CsvError};
pub use temperature::{CompensationResult, TemperatureFit, compensation_test, temperature_calibration};
