//! The virtual cell's Sensor node: every pad's force estimate (eq. 8) from its peaks, as the
//! paper's Sensor node publishes the force for the rest of the graph.

use tendril_fbg::array::ArrayPeaks;
use tendril_fbg::estimate::{ForceCalibration, ForceEstimator};
use tendril_fbg::signals::Wavelengths;

/// How long the sensor node averages the peaks for its tare from the twin's start \[s\]: 0.5 s.
/// The twin starts at home, finger retracted and untouched, as the control side's tare at home
/// assumes (a stated choice: the paper does not say how its Sensor node tares); 50 samples at the
/// default 100 Hz publish rate average the interrogator's 3 pm noise down to 0.4 pm, 0.4 mN.
pub const TARE_S: f64 = 0.5;

struct Pad {
    estimator: ForceEstimator,
    sum: [f64; 2],
    n: u32,
}

/// Each pad's estimator, tared on the first [`TARE_S`] of samples.
pub struct SensorNode {
    pads: Vec<Pad>,
}

impl SensorNode {
    /// Pad 0 with `calibration`, the further pads with their own (`own[k]`) or `calibration`.
    pub fn new(calibration: &ForceCalibration, further_pads: usize, own: &[ForceCalibration]) -> SensorNode {
        let pad = |c: &ForceCalibration| Pad { estimator: ForceEstimator::new(c.clone()), sum: [0.0; 2], n: 0 };
        let mut pads = vec![pad(calibration)];
        pads.extend((0..further_pads).map(|k| pad(own.get(k).unwrap_or(calibration))));
        SensorNode { pads }
    }

    /// Each pad's estimate \[N\] at twin time `time_s` (NaN while taring, or for a sample without
    /// a valid estimate).
    pub fn estimate(&mut self, time_s: f64, pad0: Wavelengths, array: &ArrayPeaks) -> Vec<f64> {
        let samples = std::iter::once(&pad0).chain(array.as_slice());
        self.pads
            .iter_mut()
            .zip(samples)
            .map(|(p, w)| {
                if time_s < TARE_S {
                    if w.fbg1_nm.is_finite() && w.fbg2_nm.is_finite() {
                        p.sum[0] += w.fbg1_nm;
                        p.sum[1] += w.fbg2_nm;
                        p.n += 1;
                        let n = f64::from(p.n);
                        p.estimator.tare(Wavelengths { fbg1_nm: p.sum[0] / n, fbg2_nm: p.sum[1] / n });
                    }
                    return f64::NAN;
                }
                p.estimator.estimate(*w).map_or(f64::NAN, |e| e.force_n)
            })
            .collect()
    }
}
