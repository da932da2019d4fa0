//! What a run does with each interrogator sample before it reaches the controller: the tare's
//! running mean, and holding the last valid estimate over invalid samples (for pad 0 and each
//! further pad of a sensor array alike).

use super::report::MAX_CONSECUTIVE_INVALID_SAMPLES;
use tendril_cell::Wavelengths;
use tendril_fbg::estimate::{Estimate, EstimateError};

/// Skips invalid estimates, holding the last valid one, until too many come in a row.
#[derive(Debug, Default)]
pub(crate) struct InvalidSamples {
    pub(crate) last_valid: Option<Estimate>,
    consecutive: u32,
    pub(crate) total: u64,
}

impl InvalidSamples {
    /// The estimate to use this tick, or why the run must stop: no tare, or
    /// [`MAX_CONSECUTIVE_INVALID_SAMPLES`] invalid samples in a row (or one before any valid).
    pub(crate) fn check(&mut self, estimate: Result<Estimate, EstimateError>) -> Result<Estimate, String> {
        match estimate {
            Ok(e) => {
                self.consecutive = 0;
                self.last_valid = Some(e);
                Ok(e)
            }
            Err(e @ EstimateError::NotTared) => Err(e.to_string()),
            Err(e) => {
                self.consecutive += 1;
                self.total += 1;
                match self.last_valid {
                    Some(held) if self.consecutive < MAX_CONSECUTIVE_INVALID_SAMPLES => Ok(held),
                    Some(_) => Err(format!("{} consecutive invalid samples, the last: {e}", self.consecutive)),
                    None => Err(format!("no valid sample yet: {e}")),
                }
            }
        }
    }
}

/// Running mean of wavelength samples, for the tare.
#[derive(Debug, Default)]
pub(crate) struct TareAverager {
    sum1: f64,
    sum2: f64,
    n: u32,
}

impl TareAverager {
    pub(crate) fn add(&mut self, w: Wavelengths) {
        self.sum1 += w.fbg1_nm;
        self.sum2 += w.fbg2_nm;
        self.n += 1;
    }

    pub(crate) fn mean(&self) -> Wavelengths {
        let n = f64::from(self.n.max(1));
        Wavelengths { fbg1_nm: self.sum1 / n, fbg2_nm: self.sum2 / n }
    }
}
