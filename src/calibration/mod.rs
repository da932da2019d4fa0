//! The paper's calibration procedures (Sec. IV), on simulated or recorded bench data.
//!
//! Everything works on a [`BenchRecord`] (time, load-cell force, both wavelengths, thermometer),
//! whether it comes from `sensor_bench` (simulation) or from a CSV recorded on a real bench.

mod cycles;
mod fit;
mod force;
mod record;
pub mod report;
mod temperature;

pub use cycles::{Branch, Cycle, max_branch_gap, segment, smooth};
pub use fit::{FitError, PolyFit, least_squares, poly_fit};
pub use force::{
    COMPENSATION_PLAY_WIDTHS_N, Comparison, ForceFit, HYSTERESIS_BIN_N, TARE_WINDOW_S, compare, fit_hysteresis_model,
    force_calibration, track_all,
};
pub use record::{BenchRecord, BenchRow, CSV_HEADER, CsvError};
pub use temperature::{CompensationResult, TemperatureFit, compensation_test, temperature_calibration};

/// Why a calibration procedure could not run on a record.
#[derive(Debug, thiserror::Error)]
pub enum CalibrationError {
    /// The record has no rows.
    #[error("the record is empty")]
    Empty,
    /// Too few rows with a load-cell force.
    #[error("the record has too few load-cell readings (column load_cell_n)")]
    NoLoadCell,
    /// Too few rows with a thermometer reading.
    #[error("the record has too few temperature readings with a varying temperature (column temperature_c)")]
    NoTemperature,
    /// No load/unload cycle was found.
    #[error("no load/unload cycle found in the load-cell force")]
    NoCycles,
    /// The fitted curve does not increase (eq. (8) needs a ≥ 0, b > 0).
    #[error("the fitted curve a = {a:.2} pm/N², b = {b:.2} pm/N does not increase with force")]
    NotIncreasing {
        /// Fitted a [pm/N²].
        a: f64,
        /// Fitted b [pm/N].
        b: f64,
    },
    /// No sample in the settled window of the compensation test.
    #[error("no sample at or after the settle time {settle_s} s")]
    NoSettledData {
        /// The settle time \[s\].
        settle_s: f64,
    },
    /// A fit failed.
    #[error(transparent)]
    Fit(#[from] FitError),
    /// An estimate failed.
    #[error("estimate: {0}")]
    Estimate(#[from] crate::control::estimate::EstimateError),
}
