//! Eq. 8 for each further pad of a sensor array: its own tare and its own estimate, every tick,
//! as pad 0's (`crate::session`).
//!
//! Every pad is the same build as the paper's (casing, uvula, gratings' sensitivities), so the
//! bench calibration of `[estimator]` is each pad's calibration unless `[[array.calibrations]]`
//! gives each its own (a lab's bench run on each pad); what differs between pads anyway, their
//! unloaded wavelengths, is what the tare at home takes out.

use super::samples::{InvalidSamples, TareAverager};
use tendril_fbg::array::{ArrayPeaks, PerPad};
use tendril_fbg::estimate::{ForceCalibration, ForceEstimator};

/// One further pad's estimator, tare and hold.
#[derive(Debug)]
struct PadEstimator {
    estimator: ForceEstimator,
    tare: TareAverager,
    invalid: InvalidSamples,
    /// The estimate of the tare itself \[N\]: what the pad reads unloaded (eq. 8's intercept).
    unloaded_n: f64,
}

/// The further pads' estimators (none without an array).
#[derive(Debug, Default)]
pub(crate) struct ArrayEstimates {
    pads: Vec<PadEstimator>,
}

impl ArrayEstimates {
    /// Estimators for the pads `peaks` carries, pad k with `own[k-1]` or else `calibration`, made
    /// at the first reading (the cell says how many pads it reads).
    fn ensure(&mut self, peaks: &ArrayPeaks, calibration: &ForceCalibration, own: &[ForceCalibration]) {
        if self.pads.len() != peaks.len() {
            self.pads = (0..peaks.len())
                .map(|k| PadEstimator {
                    estimator: ForceEstimator::new(own.get(k).unwrap_or(calibration).clone()),
                    tare: TareAverager::default(),
                    invalid: InvalidSamples::default(),
                    unloaded_n: 0.0,
                })
                .collect();
        }
    }

    /// Adds a sample at home, finger untouched, to each pad's tare (a non-finite one is left out).
    pub(crate) fn tare(&mut self, peaks: &ArrayPeaks, calibration: &ForceCalibration, own: &[ForceCalibration]) {
        self.ensure(peaks, calibration, own);
        for (pad, w) in self.pads.iter_mut().zip(peaks.as_slice()) {
            if w.fbg1_nm.is_finite() && w.fbg2_nm.is_finite() {
                pad.tare.add(*w);
            }
            let mean = pad.tare.mean();
            pad.estimator.tare(mean);
            pad.unloaded_n = pad.estimator.estimate(mean).map_or(0.0, |e| e.force_n);
        }
    }

    /// Each pad's force estimate \[N\] this tick: from `peaks`, or the last valid one when the
    /// sample is not new (`held`) or invalid, up to the same limit of invalid samples in a row as
    /// pad 0's; past it, why the run must stop.
    pub(crate) fn estimate(
        &mut self,
        peaks: &ArrayPeaks,
        held: bool,
        calibration: &ForceCalibration,
        own: &[ForceCalibration],
    ) -> Result<PerPad<f64>, String> {
        self.ensure(peaks, calibration, own);
        let mut out = PerPad::filled(self.pads.len(), f64::NAN);
        for (k, (pad, w)) in self.pads.iter_mut().zip(peaks.as_slice()).enumerate() {
            let estimate = match (held, pad.invalid.last_valid) {
                (true, Some(e)) => e,
                _ => pad.invalid.check(pad.estimator.track(*w)).map_err(|cause| format!("pad {}: {cause}", k + 1))?,
            };
            out.as_mut_slice()[k] = estimate.force_n;
        }
        Ok(out)
    }

    /// Each further pad's unloaded reading \[N\] (0 before the tare).
    pub(crate) fn unloaded_n(&self, k: usize) -> f64 {
        self.pads.get(k).map_or(0.0, |p| p.unloaded_n)
    }

    /// Invalid samples over the run, all further pads together.
    pub(crate) fn invalid_total(&self) -> u64 {
        self.pads.iter().map(|p| p.invalid.total).sum()
    }
}
