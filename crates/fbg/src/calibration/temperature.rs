//! Temperature calibration (water bath: linear fits of both shifts on temperature) and the
//! compensation test (constant force while heating: eq. (8) with and without `r·Δλ2`).

use super::CalibrationError;
use super::fit::poly_fit;
use super::force::{TARE_WINDOW_S, track_all};
use super::record::BenchRecord;
use crate::estimate::{ForceCalibration, ForceEstimator};
use crate::signals::Wavelengths;

/// Result of the temperature calibration.
#[derive(Debug, Clone, PartialEq)]
pub struct TemperatureFit {
    /// FBG1 temperature sensitivity `K_T1` [pm/°C].
    pub kt1_pm_per_c: f64,
    /// R² of the FBG1 fit [-].
    pub r2_1: f64,
    /// FBG2 temperature sensitivity `K_T2` [pm/°C].
    pub kt2_pm_per_c: f64,
    /// R² of the FBG2 fit [-].
    pub r2_2: f64,
    /// `r = K_T1/K_T2` [-].
    pub r: f64,
}

/// Linear fits of both wavelength shifts \[pm\] on the thermometer reading [°C] (no load).
pub fn temperature_calibration(record: &BenchRecord) -> Result<TemperatureFit, CalibrationError> {
    let (mut t, mut d1, mut d2) = (Vec::new(), Vec::new(), Vec::new());
    for r in &record.rows {
        if let Some(temp) = r.temperature_c {
            t.push(temp);
            d1.push(r.fbg1_nm * 1000.0);
            d2.push(r.fbg2_nm * 1000.0);
        }
    }
    if t.len() < 10 {
        return Err(CalibrationError::NoTemperature);
    }
    // Shift relative to the first sample: same slope, better conditioned than absolute pm.
    let (o1, o2) = (d1[0], d2[0]);
    let d1: Vec<f64> = d1.iter().map(|v| v - o1).collect();
    let d2: Vec<f64> = d2.iter().map(|v| v - o2).collect();
    let f1 = poly_fit(&t, &d1, 1)?;
    let f2 = poly_fit(&t, &d2, 1)?;
    let (kt1, kt2) = (f1.coefficients[1], f2.coefficients[1]);
    if kt2.is_nan() || kt2 == 0.0 {
        return Err(CalibrationError::NoTemperature);
    }
    Ok(TemperatureFit { kt1_pm_per_c: kt1, r2_1: f1.r2, kt2_pm_per_c: kt2, r2_2: f2.r2, r: kt1 / kt2 })
}

/// Result of the compensation test.
#[derive(Debug, Clone, PartialEq)]
pub struct CompensationResult {
    /// The settled compensated reading the errors are measured from \[N\] (the paper's "0.1 N").
    pub reference_n: f64,
    /// RMSE of the compensated reading about the reference after settling \[N\].
    pub compensated_rmse_n: f64,
    /// RMSE of the uncompensated reading about the reference after settling \[N\].
    pub uncompensated_rmse_n: f64,
    /// Largest uncompensated error after settling \[N\].
    pub max_uncompensated_error_n: f64,
    /// FBG2 shift over the last `window_s` of the test from the tare \[pm\]; divided by `K_T2` it is
    /// the temperature change the paper reads from the strain-free grating (11 °C).
    pub fbg2_shift_pm: f64,
}

/// The compensation test: the sensor holds a constant force while the water heats. The paper has no
/// reference force here, so the errors are measured about the sensor's own settled reading: the mean
/// compensated estimate over `[settle_s, settle_s + window_s]`. RMSEs cover `t ≥ settle_s`.
/// The FBG2 shift is averaged over the last `window_s`.
pub fn compensation_test(
    record: &BenchRecord,
    cal: &ForceCalibration,
    settle_s: f64,
    window_s: f64,
) -> Result<CompensationResult, CalibrationError> {
    let compensated = track_all(record, cal)?;
    let mut est = ForceEstimator::new(cal.clone());
    let tare = record.tare(TARE_WINDOW_S).ok_or(CalibrationError::Empty)?;
    est.tare(tare);
    let mut uncompensated = Vec::with_capacity(record.rows.len());
    for r in &record.rows {
        uncompensated.push(est.estimate(Wavelengths { fbg1_nm: r.fbg1_nm, fbg2_nm: r.fbg2_nm })?.uncompensated_n);
    }
    let window: Vec<f64> = record
        .rows
        .iter()
        .zip(&compensated)
        .filter(|(r, _)| r.time_s >= settle_s && r.time_s <= settle_s + window_s)
        .map(|(_, c)| *c)
        .collect();
    if window.is_empty() {
        return Err(CalibrationError::NoSettledData { settle_s });
    }
    let reference_n = window.iter().sum::<f64>() / window.len() as f64;
    let after: Vec<usize> = (0..record.rows.len()).filter(|&i| record.rows[i].time_s >= settle_s).collect();
    let rms =
        |v: &[f64]| (after.iter().map(|&i| (v[i] - reference_n).powi(2)).sum::<f64>() / after.len() as f64).sqrt();
    let max_err = after.iter().map(|&i| (uncompensated[i] - reference_n).abs()).fold(0.0, f64::max);
    let end = record.rows.last().ok_or(CalibrationError::Empty)?.time_s;
    let tail: Vec<f64> = record.rows.iter().filter(|r| r.time_s >= end - window_s).map(|r| r.fbg2_nm).collect();
    let fbg2_end_nm = tail.iter().sum::<f64>() / tail.len() as f64;
    Ok(CompensationResult {
        reference_n,
        compensated_rmse_n: rms(&compensated),
        uncompensated_rmse_n: rms(&uncompensated),
        max_uncompensated_error_n: max_err,
        fbg2_shift_pm: (fbg2_end_nm - tare.fbg2_nm) * 1000.0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibration::BenchRow;

    fn row(t: f64, d1_pm: f64, d2_pm: f64, temp: Option<f64>) -> BenchRow {
        BenchRow {
            time_s: t,
            load_cell_n: None,
            fbg1_nm: 1540.0 + d1_pm / 1e3,
            fbg2_nm: 1550.0 + d2_pm / 1e3,
            temperature_c: temp,
        }
    }

    #[test]
    fn recovers_known_sensitivities() {
        let rows = (0..200)
            .map(|i| {
                let temp = 25.0 + i as f64 * 0.1;
                row(i as f64, 20.0 * (temp - 25.0) + 7.0, 8.0 * (temp - 25.0), Some(temp))
            })
            .collect();
        let f = temperature_calibration(&BenchRecord { rows }).unwrap();
        assert!((f.kt1_pm_per_c - 20.0).abs() < 1e-6 && (f.kt2_pm_per_c - 8.0).abs() < 1e-6);
        assert!((f.r - 2.5).abs() < 1e-6 && f.r2_1 > 0.999_999);
        let no_temp = BenchRecord { rows: (0..20).map(|i| row(i as f64, 0.0, 0.0, None)).collect() };
        assert!(matches!(temperature_calibration(&no_temp), Err(CalibrationError::NoTemperature)));
    }

    #[test]
    fn compensation_test_separates_drift_from_force() {
        // Constant 1 N on the paper's curve; 10 °C of heating after 5 s; perfect r.
        let cal = ForceCalibration::default();
        let strain = 144.99 + 527.62 - 91.42;
        let rows = (0..1000)
            .map(|i| {
                let t = i as f64 * 0.01;
                let dt = if t < 5.0 { 0.0 } else { (t - 5.0) * 2.0 };
                let force = if t < 1.0 { 0.0 } else { strain };
                row(t, force + 24.29 * dt, 10.31 * dt, None)
            })
            .collect();
        let c = compensation_test(&BenchRecord { rows }, &cal, 2.0, 1.0).unwrap();
        assert!((c.reference_n - 1.0).abs() < 1e-6, "{}", c.reference_n);
        assert!(c.compensated_rmse_n < 1e-6);
        assert!(c.uncompensated_rmse_n > 0.1 && c.max_uncompensated_error_n > 0.2);
    }
}
