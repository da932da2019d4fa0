//! Force estimation from the two FBG wavelengths: the paper's equation (8), with temperature
//! compensation through `r = K_T1/K_T2` against a tare taken at start, and optional software
//! hysteresis compensation (the inverse of a Prandtl-Ishlinskii model).
//!
//! Shared by the twin and the real cell: it only sees [`Wavelengths`].
//!
//! ```text
//! Δλ1, Δλ2 = wavelengths − tare                     (pm)
//! s        = Δλ1 − r·Δλ2                            (strain part of Δλ1, eq. 5 with ΔT1 = ΔT2)
//! N        = (−b + sqrt(b² − 4a(c − s))) / 2a       (eq. 8, with the calibration a, b, c)
//! ```

use crate::hysteresis::{PiModel, PiState};
use crate::signals::Wavelengths;
use serde::{Deserialize, Serialize};
use tendril_config::{Checker, Validate};

/// Readings above this fraction of the range are flagged over-range. The sensor saturates when the
/// uvula bottoms out; on the loading branch the saturated reading maps through the paper's curve to
/// about 4.63 N (hysteresis keeps it below 4.69 N), so a reading above 95 % of the range cannot be
/// told from saturation.
pub const OVER_RANGE_FRACTION: f64 = 0.95;

/// Calibration of eq. (8): `Δλ1_strain [pm] = a·N² + b·N + c`, the temperature ratio and the range.
/// `Default` is the paper's sensor (Sec. IV-B). Scenario section `[estimator]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ForceCalibration {
    /// Quadratic coefficient `a` [pm/N²]; paper: 144.99.
    pub a_pm_per_n2: f64,
    /// Linear coefficient `b` [pm/N]; paper: 527.62.
    pub b_pm_per_n: f64,
    /// Intercept `c` \[pm\]; paper: −91.42.
    pub c_pm: f64,
    /// Temperature sensitivity ratio `r = K_T1/K_T2` [-]; paper: 24.29/10.31 = 2.356.
    pub r: f64,
    /// Measuring range \[N\]; paper: 4.69.
    pub range_n: f64,
    /// Optional software hysteresis compensation: a PI model mapping the true force to the eq. (8)
    /// estimate (fitted by `calibration::fit_hysteresis_model`); `None` (the paper) disables it.
    pub hysteresis: Option<PiModel>,
}

impl Default for ForceCalibration {
    fn default() -> Self {
        ForceCalibration {
            a_pm_per_n2: 144.99,
            b_pm_per_n: 527.62,
            c_pm: -91.42,
            r: 24.29 / 10.31,
            range_n: 4.69,
            hysteresis: None,
        }
    }
}

impl Validate for ForceCalibration {
    fn validate(&self, at: &mut Checker) {
        // Eq. (8) takes the + root, the increasing branch, which needs a ≥ 0 and b > 0.
        at.non_negative("a_pm_per_n2", self.a_pm_per_n2);
        at.positive("b_pm_per_n", self.b_pm_per_n);
        at.finite("c_pm", self.c_pm);
        at.positive("r", self.r);
        // 100 N: twenty times the paper's 4.69 N; a soft 12 × 12 mm pad tears long before.
        at.in_range("range_n", self.range_n, 1e-3, 100.0);
        if let Some(h) = &self.hysteresis {
            at.section("hysteresis", h);
        }
    }
}

/// One force estimate.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Estimate {
    /// Temperature-compensated force, eq. (8) \[N\] (hysteresis-compensated too when enabled and the
    /// estimate came from [`ForceEstimator::track`]). May be slightly negative near zero force: the
    /// fitted curve's intercept is not zero, and the value is reported as computed.
    pub force_n: f64,
    /// Eq. (8) without the `r·Δλ2` term \[N\]: the paper's "without compensation". Where its
    /// discriminant is negative it is the curve's vertex `−b/2a` (never NaN).
    pub uncompensated_n: f64,
    /// The reading is at or above [`OVER_RANGE_FRACTION`] of the range: the sensor may be saturated.
    pub over_range: bool,
    /// FBG1 shift from the tare \[pm\].
    pub delta1_pm: f64,
    /// FBG2 shift from the tare \[pm\].
    pub delta2_pm: f64,
}

/// Why no estimate could be made.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum EstimateError {
    /// [`ForceEstimator::tare`] was never called.
    #[error("no tare: call tare() with an unloaded reading first")]
    NotTared,
    /// A wavelength is NaN or infinite.
    #[error("non-finite wavelength ({fbg1_nm} nm, {fbg2_nm} nm)")]
    NonFinite {
        /// FBG1 reading \[nm\].
        fbg1_nm: f64,
        /// FBG2 reading \[nm\].
        fbg2_nm: f64,
    },
    /// `b² − 4a(c − s) < 0`: the compensated shift lies below the fitted curve's minimum.
    #[error("invalid discriminant: compensated shift {shift_pm:.1} pm is below the calibration curve's minimum")]
    InvalidDiscriminant {
        /// The compensated strain shift `Δλ1 − r·Δλ2` \[pm\].
        shift_pm: f64,
    },
}

/// Eq. (8) estimator with a tare; see the module docs.
#[derive(Debug, Clone)]
pub struct ForceEstimator {
    cal: ForceCalibration,
    tare: Option<Wavelengths>,
    hysteresis_state: PiState,
}

impl ForceEstimator {
    /// An estimator for `cal`, not yet tared.
    pub fn new(cal: ForceCalibration) -> ForceEstimator {
        ForceEstimator { cal, tare: None, hysteresis_state: PiState::default() }
    }

    /// The calibration in use.
    pub fn calibration(&self) -> &ForceCalibration {
        &self.cal
    }

    /// Takes `w` (an unloaded reading) as the zero of both shifts and resets the hysteresis state.
    pub fn tare(&mut self, w: Wavelengths) {
        self.tare = Some(w);
        self.hysteresis_state = PiState::default();
    }

    /// The tare, if taken.
    pub fn tare_value(&self) -> Option<Wavelengths> {
        self.tare
    }

    /// Eq. (8) for one reading (stateless: no hysteresis compensation).
    #[inline]
    pub fn estimate(&self, w: Wavelengths) -> Result<Estimate, EstimateError> {
        let tare = self.tare.ok_or(EstimateError::NotTared)?;
        if !(w.fbg1_nm.is_finite() && w.fbg2_nm.is_finite()) {
            return Err(EstimateError::NonFinite { fbg1_nm: w.fbg1_nm, fbg2_nm: w.fbg2_nm });
        }
        let delta1_pm = (w.fbg1_nm - tare.fbg1_nm) * 1000.0;
        let delta2_pm = (w.fbg2_nm - tare.fbg2_nm) * 1000.0;
        let shift_pm = delta1_pm - self.cal.r * delta2_pm;
        let force_n = self.invert_curve(shift_pm).ok_or(EstimateError::InvalidDiscriminant { shift_pm })?;
        let uncompensated_n = self.invert_curve(delta1_pm).unwrap_or_else(|| self.vertex_n());
        Ok(Estimate {
            force_n,
            uncompensated_n,
            over_range: force_n >= OVER_RANGE_FRACTION * self.cal.range_n,
            delta1_pm,
            delta2_pm,
        })
    }

    /// As [`ForceEstimator::estimate`], and with hysteresis compensation when the calibration has a
    /// model: the eq. (8) force is passed through the model's inverse, whose state advances with
    /// each call (call it once per sample, in time order). Without a model it equals `estimate`.
    pub fn track(&mut self, w: Wavelengths) -> Result<Estimate, EstimateError> {
        let mut e = self.estimate(w)?;
        if let Some(model) = &self.cal.hysteresis {
            // The PI model is defined for non-negative forces (a contact force), so clamp at zero.
            e.force_n = model.invert(&mut self.hysteresis_state, e.force_n).max(0.0);
            e.over_range |= e.force_n >= OVER_RANGE_FRACTION * self.cal.range_n;
        }
        Ok(e)
    }

    /// The force for a strain shift `s` [pm] on the calibration curve, `None` if below its minimum.
    #[inline]
    fn invert_curve(&self, s: f64) -> Option<f64> {
        let ForceCalibration { a_pm_per_n2: a, b_pm_per_n: b, c_pm: c, .. } = self.cal;
        if a.abs() < 1e-12 {
            return Some((s - c) / b);
        }
        let disc = b * b - 4.0 * a * (c - s);
        if disc < 0.0 {
            return None;
        }
        // (−b + √D) / 2a written as 2(s − c) / (b + √D): the same value without cancellation.
        Some(2.0 * (s - c) / (b + disc.sqrt()))
    }

    fn vertex_n(&self) -> f64 {
        if self.cal.a_pm_per_n2.abs() < 1e-12 { 0.0 } else { -self.cal.b_pm_per_n / (2.0 * self.cal.a_pm_per_n2) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn w(d1_pm: f64, d2_pm: f64) -> Wavelengths {
        Wavelengths { fbg1_nm: 1540.0 + d1_pm / 1000.0, fbg2_nm: 1550.0 + d2_pm / 1000.0 }
    }

    fn tared() -> ForceEstimator {
        let mut e = ForceEstimator::new(ForceCalibration::default());
        e.tare(w(0.0, 0.0));
        e
    }

    #[test]
    fn paper_curve_inverts_exactly() {
        let e = tared();
        for n in [0.0, 0.5, 2.68, 4.4] {
            let s = 144.99 * n * n + 527.62 * n - 91.42;
            let got = e.estimate(w(s, 0.0)).unwrap();
            assert!((got.force_n - n).abs() < 1e-9, "{n} -> {}", got.force_n);
            assert!(!got.over_range);
        }
    }

    #[test]
    fn temperature_cancels_through_r_but_not_without_it() {
        let e = tared();
        let (kt1, kt2, dt) = (24.29, 10.31, 11.0);
        let base = 144.99 * 0.25 + 527.62 * 0.5 - 91.42;
        let got = e.estimate(w(base + kt1 * dt, kt2 * dt)).unwrap();
        assert!((got.force_n - 0.5).abs() < 1e-9);
        assert!(got.uncompensated_n > 0.85, "drifts with temperature: {}", got.uncompensated_n);
    }

    #[test]
    fn errors_instead_of_nan() {
        let untared = ForceEstimator::new(ForceCalibration::default());
        assert_eq!(untared.estimate(w(0.0, 0.0)), Err(EstimateError::NotTared));
        let e = tared();
        assert!(matches!(e.estimate(w(-2000.0, 0.0)), Err(EstimateError::InvalidDiscriminant { .. })));
        let nan = Wavelengths { fbg1_nm: f64::NAN, fbg2_nm: 1550.0 };
        assert!(matches!(e.estimate(nan), Err(EstimateError::NonFinite { .. })));
        // Compensated fine, uncompensated below the curve: the vertex, not NaN.
        let got = e.estimate(w(-1000.0, -500.0)).unwrap();
        assert!(got.uncompensated_n.is_finite());
    }

    #[test]
    fn flags_over_range() {
        let e = tared();
        let s = 144.99 * 4.6 * 4.6 + 527.62 * 4.6 - 91.42;
        assert!(e.estimate(w(s, 0.0)).unwrap().over_range);
    }
}
