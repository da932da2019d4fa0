//! Force calibration (quadratic fit, RMSE, sensitivity), hysteresis, the load-cell comparison and
//! the fit of a hysteresis model for software compensation (paper Sec. IV-B).

use super::CalibrationError;
use super::cycles::{self, Branch};
use super::fit::{FitError, least_squares, poly_fit};
use super::record::BenchRecord;
use crate::estimate::{ForceCalibration, ForceEstimator};
use crate::hysteresis::{PiModel, one_sided_play};
use nalgebra::DMatrix;

/// The procedures take their tare over the first this many seconds of a record (unloaded).
pub const TARE_WINDOW_S: f64 = 0.5;
/// Force bins for the hysteresis study \[N\].
pub const HYSTERESIS_BIN_N: f64 = 0.1;
/// Play widths \[N\] of the hysteresis model fitted for software compensation: spread over the
/// range so the fitted weights can shape any lens-like loop (docs/facts.md#prandtl-ishlinskii-hysteresis: 3-5 plays).
pub const COMPENSATION_PLAY_WIDTHS_N: [f64; 5] = [0.25, 0.5, 1.0, 1.5, 2.0];

/// Result of the force calibration on a load/unload record.
#[derive(Debug, Clone, PartialEq)]
pub struct ForceFit {
    /// Fitted `a` [pm/N²] of `Δλ1 = a·N² + b·N + c`.
    pub a_pm_per_n2: f64,
    /// Fitted `b` [pm/N].
    pub b_pm_per_n: f64,
    /// Fitted `c` \[pm\].
    pub c_pm: f64,
    /// R² of the fit [-].
    pub r2: f64,
    /// RMSE of the fit \[pm\].
    pub rmse_pm: f64,
    /// RMSE of the force read back through eq. (8) against the load cell \[N\].
    pub rmse_n: f64,
    /// Mean peak shift over mean peak force of the cycles [pm/N] (the paper's 5482.78 pm / 4.69 N).
    pub sensitivity_pm_per_n: f64,
    /// Mean peak FBG1 shift of the cycles \[pm\] (full scale).
    pub span_pm: f64,
    /// Mean peak load-cell force of the cycles \[N\] (the range exercised).
    pub peak_force_n: f64,
    /// Number of load/unload cycles found.
    pub cycles: usize,
    /// Largest hysteresis, as % of full scale (`span_pm`) [%].
    pub hysteresis_percent: f64,
    /// Force where the largest hysteresis occurs \[N\].
    pub hysteresis_at_n: f64,
}

impl ForceFit {
    /// The estimator calibration from this fit, with temperature ratio `r` [-].
    pub fn calibration(&self, r: f64) -> ForceCalibration {
        ForceCalibration {
            a_pm_per_n2: self.a_pm_per_n2,
            b_pm_per_n: self.b_pm_per_n,
            c_pm: self.c_pm,
            r,
            range_n: self.peak_force_n,
            hysteresis: None,
        }
    }
}

/// Load-cell samples of a record: (index, force) pairs, tare, smoothed force and branches.
struct LoadData {
    idx: Vec<usize>,
    force: Vec<f64>,
    smoothed: Vec<f64>,
    branches: Vec<Branch>,
    cycles: Vec<cycles::Cycle>,
    delta1_pm: Vec<f64>,
}

fn load_data(record: &BenchRecord) -> Result<LoadData, CalibrationError> {
    let tare = record.tare(TARE_WINDOW_S).ok_or(CalibrationError::Empty)?;
    let (mut idx, mut force, mut times, mut delta1_pm) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for (i, r) in record.rows.iter().enumerate() {
        if let Some(f) = r.load_cell_n {
            idx.push(i);
            force.push(f);
            times.push(r.time_s);
            delta1_pm.push((r.fbg1_nm - tare.fbg1_nm) * 1000.0);
        }
    }
    if force.len() < 10 {
        return Err(CalibrationError::NoLoadCell);
    }
    let smoothed = cycles::smooth(&force, cycles::half_window(&times));
    let (cycles, branches) = cycles::segment(&smoothed);
    if cycles.is_empty() {
        return Err(CalibrationError::NoCycles);
    }
    Ok(LoadData { idx, force, smoothed, branches, cycles, delta1_pm })
}

/// The paper's force calibration on a load/unload record with a load cell: quadratic least squares
/// of the FBG1 shift on the load-cell force, the force RMSE through eq. (8), the sensitivity and the
/// hysteresis study (largest gap between unloading and loading branches, % of full scale).
pub fn force_calibration(record: &BenchRecord) -> Result<ForceFit, CalibrationError> {
    let d = load_data(record)?;
    let fit = poly_fit(&d.force, &d.delta1_pm, 2)?;
    let (c, b, a) = (fit.coefficients[0], fit.coefficients[1], fit.coefficients[2]);
    let cal = ForceCalibration { a_pm_per_n2: a, b_pm_per_n: b, c_pm: c, ..ForceCalibration::default() };
    if !(a >= 0.0 && b > 0.0) {
        return Err(CalibrationError::NotIncreasing { a, b });
    }
    let mut est = ForceEstimator::new(cal);
    est.tare(record.tare(TARE_WINDOW_S).ok_or(CalibrationError::Empty)?);
    // The bench runs at constant temperature and the paper converts Δλ1 alone: the uncompensated value.
    let mut sq = 0.0;
    for (&i, &f) in d.idx.iter().zip(&d.force) {
        let r = &record.rows[i];
        let e = est.estimate(crate::signals::Wavelengths { fbg1_nm: r.fbg1_nm, fbg2_nm: r.fbg2_nm })?;
        sq += (e.uncompensated_n - f).powi(2);
    }
    let rmse_n = (sq / d.force.len() as f64).sqrt();
    let smoothed_delta = cycles::smooth(&d.delta1_pm, cycles::half_window(&times_of(record, &d.idx)));
    let (mut peak_pm, mut peak_n) = (0.0, 0.0);
    for cy in &d.cycles {
        peak_pm += smoothed_delta[cy.start..cy.end].iter().copied().fold(f64::NEG_INFINITY, f64::max);
        peak_n += d.smoothed[cy.peak];
    }
    let n = d.cycles.len() as f64;
    let (span_pm, peak_force_n) = (peak_pm / n, peak_n / n);
    let (gap, at) = cycles::max_branch_gap(&d.smoothed, &d.delta1_pm, &d.branches, HYSTERESIS_BIN_N)
        .ok_or(CalibrationError::NoCycles)?;
    Ok(ForceFit {
        a_pm_per_n2: a,
        b_pm_per_n: b,
        c_pm: c,
        r2: fit.r2,
        rmse_pm: fit.rmse,
        rmse_n,
        sensitivity_pm_per_n: span_pm / peak_force_n,
        span_pm,
        peak_force_n,
        cycles: d.cycles.len(),
        hysteresis_percent: 100.0 * gap / span_pm,
        hysteresis_at_n: at,
    })
}

fn times_of(record: &BenchRecord, idx: &[usize]) -> Vec<f64> {
    idx.iter().map(|&i| record.rows[i].time_s).collect()
}

/// The sensor's force readings against the load cell.
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    /// RMSE of the estimate against the load cell \[N\].
    pub rmse_n: f64,
    /// RMSE as % of the calibration's range [%] (the paper's "percentage error").
    pub percent_of_range: f64,
    /// Largest gap between the unloading and the loading branch of the estimate, % of range [%].
    pub hysteresis_percent: f64,
    /// Force where that gap occurs \[N\].
    pub hysteresis_at_n: f64,
}

/// Reads a load/unload record through the estimator with `cal` (with its hysteresis compensation,
/// if any: [`ForceEstimator::track`]) and compares with the load cell.
pub fn compare(record: &BenchRecord, cal: &ForceCalibration) -> Result<Comparison, CalibrationError> {
    let d = load_data(record)?;
    let estimates = track_all(record, cal)?;
    let est: Vec<f64> = d.idx.iter().map(|&i| estimates[i]).collect();
    let rmse_n = (est.iter().zip(&d.force).map(|(e, f)| (e - f).powi(2)).sum::<f64>() / est.len() as f64).sqrt();
    let (gap, at) =
        cycles::max_branch_gap(&d.smoothed, &est, &d.branches, HYSTERESIS_BIN_N).ok_or(CalibrationError::NoCycles)?;
    Ok(Comparison {
        rmse_n,
        percent_of_range: 100.0 * rmse_n / cal.range_n,
        hysteresis_percent: 100.0 * gap / cal.range_n,
        hysteresis_at_n: at,
    })
}

/// The tracked (temperature- and, if configured, hysteresis-compensated) force of every row \[N\].
pub fn track_all(record: &BenchRecord, cal: &ForceCalibration) -> Result<Vec<f64>, CalibrationError> {
    let mut est = ForceEstimator::new(cal.clone());
    est.tare(record.tare(TARE_WINDOW_S).ok_or(CalibrationError::Empty)?);
    record
        .rows
        .iter()
        .map(|r| Ok(est.track(crate::signals::Wavelengths { fbg1_nm: r.fbg1_nm, fbg2_nm: r.fbg2_nm })?.force_n))
        .collect()
}

/// Fits the PI hysteresis model used for software compensation: the eq. (8) estimate (with `cal`,
/// no compensation) regressed on the load-cell force through one-sided plays of
/// [`COMPENSATION_PLAY_WIDTHS_N`], `N̂ = p0·N + Σ wᵢ·playᵢ[N] + offset`, by least squares with
/// negative weights dropped one at a time (a small active-set NNLS). The plays run on the smoothed
/// load-cell force: raw noise would keep the narrow plays chattering.
pub fn fit_hysteresis_model(record: &BenchRecord, cal: &ForceCalibration) -> Result<PiModel, CalibrationError> {
    let d = load_data(record)?;
    let plain = ForceCalibration { hysteresis: None, ..cal.clone() };
    let estimates = track_all(record, &plain)?;
    let y: Vec<f64> = d.idx.iter().map(|&i| estimates[i]).collect();
    let x: Vec<f64> = d.smoothed.iter().map(|f| f.max(0.0)).collect();
    let mut plays: Vec<Vec<f64>> = Vec::new();
    for &w in &COMPENSATION_PLAY_WIDTHS_N {
        let mut h = 0.0;
        plays.push(
            x.iter()
                .map(|&xi| {
                    h = one_sided_play(h, xi, w);
                    h
                })
                .collect(),
        );
    }
    let mut active: Vec<usize> = (0..COMPENSATION_PLAY_WIDTHS_N.len()).collect();
    loop {
        let k = active.len() + 2;
        let design = DMatrix::from_fn(x.len(), k, |i, j| match j {
            0 => x[i],
            1 => 1.0,
            j => plays[active[j - 2]][i],
        });
        let coef = least_squares(&design, &y)?;
        let worst = (2..k).min_by(|&a, &b| coef[a].total_cmp(&coef[b]));
        match worst {
            Some(j) if coef[j] < 0.0 => {
                active.remove(j - 2);
            }
            _ => {
                if coef[0].is_nan() || coef[0] <= 0.0 {
                    return Err(CalibrationError::Fit(FitError::Singular));
                }
                return Ok(PiModel {
                    linear_gain: coef[0],
                    widths: active.iter().map(|&a| COMPENSATION_PLAY_WIDTHS_N[a]).collect(),
                    weights: coef[2..].to_vec(),
                    offset: coef[1],
                });
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibration::BenchRow;

    /// Three triangle cycles to 4 N on a known quadratic, with an optional loop on unloading.
    fn record(loop_pm: f64) -> BenchRecord {
        let rows = (0..=3100)
            .map(|i| {
                let t = i as f64 * 0.01;
                let phase = ((t - 1.0) / 10.0).rem_euclid(1.0);
                let active = t >= 1.0;
                let f = if !active {
                    0.0
                } else if phase < 0.5 {
                    8.0 * phase
                } else {
                    8.0 * (1.0 - phase)
                };
                let extra = if active && phase >= 0.5 { loop_pm * (std::f64::consts::PI * f / 4.0).sin() } else { 0.0 };
                let d = 100.0 * f * f + 500.0 * f + extra;
                BenchRow {
                    time_s: t,
                    load_cell_n: Some(f),
                    fbg1_nm: 1540.0 + d / 1e3,
                    fbg2_nm: 1550.0,
                    temperature_c: None,
                }
            })
            .collect();
        BenchRecord { rows }
    }

    #[test]
    fn recovers_a_known_curve_without_hysteresis() {
        let f = force_calibration(&record(0.0)).unwrap();
        assert_eq!(f.cycles, 3);
        assert!((f.a_pm_per_n2 - 100.0).abs() < 1e-6 && (f.b_pm_per_n - 500.0).abs() < 1e-6 && f.c_pm.abs() < 1e-6);
        assert!(f.rmse_pm < 1e-6 && f.rmse_n < 1e-6);
        assert!((f.sensitivity_pm_per_n - 900.0).abs() < 15.0, "{}", f.sensitivity_pm_per_n);
        // Not exactly 0: the branches sample each bin at different forces.
        assert!(f.hysteresis_percent.abs() < 0.1, "{} at {}", f.hysteresis_percent, f.hysteresis_at_n);
    }

    #[test]
    fn finds_a_known_loop() {
        let f = force_calibration(&record(180.0)).unwrap();
        // 180 pm of 3600 pm full scale = 5 %, widest at 2 N.
        assert!((f.hysteresis_percent - 5.0).abs() < 0.3, "{}", f.hysteresis_percent);
        assert!((f.hysteresis_at_n - 2.0).abs() < 0.2, "{}", f.hysteresis_at_n);
    }
}
