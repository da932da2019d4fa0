//! [`CalibrationError`]: why a calibration procedure could not run on a record.

use super::fit::FitError;

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
    Estimate(#[from] crate::estimate::EstimateError),
}
