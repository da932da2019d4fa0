//! Configuration of the FBG forward model: scenario sections `[sensor]` and `[interrogator]`.
//! `Default` is the paper's sensor and its HYPERION si255 interrogator, so both may be omitted.

use serde::{Deserialize, Serialize};
use tendril_config::{Checker, Validate};

/// The sensor: strain response, hysteresis, range and thermal behaviour of the two gratings.
///
/// Strain response (the "backbone", hysteresis-free) of FBG1 in pm for an effective force `n` in N:
/// `Δλ = k1·n + k2·n² + k3·n³`. The three coefficients are *tuned* (not in the paper): solved so
/// that the paper's least-squares quadratic fit, applied to the simulated 4-cycle calibration run
/// (`scenarios/bench-force-calibration.toml`), returns the paper's `144.99 N² + 527.62 N − 91.42`.
/// A slightly negative cubic term (the curve straightens near the top as the uvula approaches the
/// floor) is what gives a quadratic fit its negative intercept although the curve starts at zero.
/// With the hysteresis below, the loading branch then ends at ≈ 5480 pm at 4.69 N: the paper's
/// 0 → 5482.78 pm span. Re-solve with `sensor_bench::solve_strain_coefficients` after changing the
/// hysteresis or the calibration bench (a unit test checks these values are its solution).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SensorConfig {
    /// Linear strain coefficient `k1` [pm/N]; tuned (see the type docs).
    pub strain_k1_pm_per_n: f64,
    /// Quadratic strain coefficient `k2` [pm/N²]; tuned.
    pub strain_k2_pm_per_n2: f64,
    /// Cubic strain coefficient `k3` [pm/N³]; tuned (negative: the response straightens near the top).
    pub strain_k3_pm_per_n3: f64,
    /// Measuring range \[N\]: past it the uvula bottoms out (1 mm gap) and the strain stops growing;
    /// paper Sec. IV-B: 4.69 N.
    pub range_n: f64,
    /// Prandtl-Ishlinskii play widths \[N\] of the TPU/epoxy hysteresis (one-sided plays, see
    /// `control::hysteresis`). Tuned: the widest, 2.0 N = 4.69 − 2.69 N, puts the widest gap of a
    /// 0 → 4.69 → 0 N loop at ≈ 2.68 N (paper Fig. 4b); the narrower ones round the loop's lower half.
    pub hysteresis_widths_n: Vec<f64>,
    /// Play weights [-], one per width. Tuned so the maximum hysteresis of the simulated calibration
    /// run is the paper's 4.83 % of full scale.
    pub hysteresis_weights: Vec<f64>,
    /// FBG1 temperature sensitivity `K_T1` [pm/°C] (grating bonded in the TPU casing); paper: 24.29.
    pub kt1_pm_per_c: f64,
    /// FBG2 temperature sensitivity `K_T2` [pm/°C] (strain-free, in the tube); paper: 10.31.
    pub kt2_pm_per_c: f64,
    /// First-order thermal time constant of FBG1 \[s\]: it sits inside the 12 × 12 × 4 mm TPU casing
    /// (2 mm half-thickness, TPU diffusivity ≈ 1e-7 m²/s: L²/(π²α) ≈ 4-16 s). Tuned with the FBG2
    /// constant: their 5 s mismatch leaves the paper's ≈ 0.01 N compensated residual while heating.
    pub thermal_lag1_s: f64,
    /// First-order thermal time constant of FBG2 \[s\]: thin polymer tube, faster. Tuned (see above).
    pub thermal_lag2_s: f64,
    /// FBG1 unstrained Bragg wavelength at the reference temperature \[nm\]; paper: 1540.
    pub lambda1_nm: f64,
    /// FBG2 Bragg wavelength at the reference temperature \[nm\]; paper: 1550.
    pub lambda2_nm: f64,
    /// Temperature at which the nominal wavelengths hold [°C]; the lab's 25 °C (paper Sec. IV-B).
    pub reference_temperature_c: f64,
}

impl Default for SensorConfig {
    fn default() -> Self {
        SensorConfig {
            strain_k1_pm_per_n: 310.03,
            strain_k2_pm_per_n2: 284.20,
            strain_k3_pm_per_n3: -18.514,
            range_n: 4.69,
            hysteresis_widths_n: vec![0.6, 1.3, 2.0],
            hysteresis_weights: vec![0.0345, 0.0345, 0.0575],
            kt1_pm_per_c: 24.29,
            kt2_pm_per_c: 10.31,
            thermal_lag1_s: 10.0,
            thermal_lag2_s: 5.0,
            lambda1_nm: 1540.0,
            lambda2_nm: 1550.0,
            reference_temperature_c: 25.0,
        }
    }
}

impl SensorConfig {
    /// The backbone strain shift \[pm\] at effective force `n` \[N\].
    #[inline]
    pub fn backbone_pm(&self, n: f64) -> f64 {
        n * (self.strain_k1_pm_per_n + n * (self.strain_k2_pm_per_n2 + n * self.strain_k3_pm_per_n3))
    }
}

impl Validate for SensorConfig {
    fn validate(&self, at: &mut Checker) {
        at.positive("range_n", self.range_n);
        at.finite("strain_k1_pm_per_n", self.strain_k1_pm_per_n);
        at.finite("strain_k2_pm_per_n2", self.strain_k2_pm_per_n2);
        at.finite("strain_k3_pm_per_n3", self.strain_k3_pm_per_n3);
        // The response must rise over the whole range, or a force could not be read back.
        let rising = (0..=100).all(|i| {
            let n = self.range_n * i as f64 / 100.0;
            self.strain_k1_pm_per_n + 2.0 * self.strain_k2_pm_per_n2 * n + 3.0 * self.strain_k3_pm_per_n3 * n * n > 0.0
        });
        at.require("strain_k1_pm_per_n", !self.range_n.is_finite() || rising, || {
            "the strain response k1·N + k2·N² + k3·N³ must increase over 0..range_n".into()
        });
        let model = crate::hysteresis::PiModel::lagging(&self.hysteresis_widths_n, &self.hysteresis_weights);
        at.require("hysteresis_widths_n", self.hysteresis_widths_n.len() <= crate::hysteresis::MAX_PLAYS, || {
            format!("at most {} plays", crate::hysteresis::MAX_PLAYS)
        });
        at.require("hysteresis_weights", self.hysteresis_weights.len() == self.hysteresis_widths_n.len(), || {
            "needs one weight per width".into()
        });
        for (i, d) in self.hysteresis_widths_n.iter().enumerate() {
            at.non_negative(&format!("hysteresis_widths_n[{i}]"), *d);
        }
        for (i, w) in self.hysteresis_weights.iter().enumerate() {
            at.non_negative(&format!("hysteresis_weights[{i}]"), *w);
        }
        at.require("hysteresis_weights", model.linear_gain > 0.0, || "the weights must sum to less than 1".into());
        at.finite("kt1_pm_per_c", self.kt1_pm_per_c);
        at.finite("kt2_pm_per_c", self.kt2_pm_per_c);
        at.non_negative("thermal_lag1_s", self.thermal_lag1_s);
        at.non_negative("thermal_lag2_s", self.thermal_lag2_s);
        at.in_range("lambda1_nm", self.lambda1_nm, 1000.0, 2000.0);
        at.in_range("lambda2_nm", self.lambda2_nm, 1000.0, 2000.0);
        at.finite("reference_temperature_c", self.reference_temperature_c);
    }
}

/// How the interrogator turns the gratings' state into peak wavelengths.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum InterrogatorMode {
    /// Peak = true Bragg wavelength + Gaussian noise, quantized (cheap; the default).
    #[default]
    Analytic,
    /// Sampled reflection spectra and a centroid peak detector (carries peak-detection error).
    Spectral,
}

/// The interrogator (Luna HYPERION si255 in the paper). Scenario section `[interrogator]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct InterrogatorConfig {
    /// Sample rate \[Hz\]; the si255 runs at 1 kHz (docs/facts.md#hyperion-scan-rate).
    pub sample_rate_hz: f64,
    /// Standard deviation of the peak-wavelength noise in analytic mode \[pm\]; paper: "≈ 3 pm".
    pub noise_pm: f64,
    /// Reported wavelength step \[pm\]; paper: 1 pm resolution.
    pub quantization_pm: f64,
    /// `"analytic"` or `"spectral"`.
    pub mode: InterrogatorMode,
    /// Spectral-mode settings (used only when `mode = "spectral"`).
    pub spectral: SpectralConfig,
}

impl Default for InterrogatorConfig {
    fn default() -> Self {
        InterrogatorConfig {
            sample_rate_hz: 1000.0,
            noise_pm: 3.0,
            quantization_pm: 1.0,
            mode: InterrogatorMode::Analytic,
            spectral: SpectralConfig::default(),
        }
    }
}

impl Validate for InterrogatorConfig {
    fn validate(&self, at: &mut Checker) {
        // 1 Hz to 10 kHz: the HYPERION si255 runs at 1 kHz (docs/facts.md#hyperion-scan-rate), the fastest HYPERION
        // models at 5 kHz; the twin draws every sample, so 1e9 Hz makes no progress, and below
        // 1 Hz no control loop is fed.
        at.in_range("sample_rate_hz", self.sample_rate_hz, 1.0, 10_000.0);
        at.non_negative("noise_pm", self.noise_pm);
        at.non_negative("quantization_pm", self.quantization_pm);
        at.section("spectral", &self.spectral);
    }
}

/// The sampled spectrum and the peak detector of spectral mode.
///
/// Each grating reflects a Gaussian line (the common stand-in for an apodized grating: apodization
/// suppresses the side lobes, docs/facts.md#peak-detection). The interrogator samples the summed spectrum on a
/// fixed grid with additive intensity noise; each channel's peak is the centroid of the samples
/// above `threshold` × the channel maximum (Tosi 2017's centroid detector).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SpectralConfig {
    /// Full width at half maximum of each reflection line \[nm\]; paper: 0.6-0.7 nm.
    pub fwhm_nm: f64,
    /// Peak reflectivity [-]; paper: > 30 %.
    pub reflectivity: f64,
    /// First sampled wavelength \[nm\].
    pub start_nm: f64,
    /// Last sampled wavelength \[nm\].
    pub end_nm: f64,
    /// Grid step of the sampled spectrum \[pm\]. 10 pm: coarse enough for 10 k spectra/s, fine
    /// enough that the centroid's grid bias stays well under the 3 pm noise.
    pub step_pm: f64,
    /// Boundary between the FBG1 channel (below) and the FBG2 channel (above) \[nm\]: FBG1 moves up to
    /// ≈ 5.5 nm with force, FBG2 stays near 1550 nm.
    pub channel_split_nm: f64,
    /// Standard deviation of the additive intensity noise, relative to full reflection [-]. Tuned so
    /// the detected peaks jitter by ≈ 3 pm, the paper's interrogator noise.
    pub intensity_noise: f64,
    /// Detection threshold as a fraction of the channel's maximum sample [-].
    pub threshold: f64,
}

impl Default for SpectralConfig {
    fn default() -> Self {
        SpectralConfig {
            fwhm_nm: 0.65,
            reflectivity: 0.4,
            start_nm: 1536.0,
            end_nm: 1554.0,
            step_pm: 10.0,
            channel_split_nm: 1547.8,
            intensity_noise: 0.015,
            threshold: 0.5,
        }
    }
}

impl Validate for SpectralConfig {
    fn validate(&self, at: &mut Checker) {
        at.positive("fwhm_nm", self.fwhm_nm);
        at.in_range("reflectivity", self.reflectivity, 1e-6, 1.0);
        at.finite("start_nm", self.start_nm);
        at.require("end_nm", self.end_nm.is_finite() && self.end_nm > self.start_nm, || {
            format!("must be above start_nm ({}), got {}", self.start_nm, self.end_nm)
        });
        at.positive("step_pm", self.step_pm);
        let points = (self.end_nm - self.start_nm) * 1000.0 / self.step_pm;
        at.require("step_pm", !points.is_finite() || points <= 1.0e6, || {
            format!("gives {points:.0} spectrum points; at most 1e6")
        });
        at.require(
            "channel_split_nm",
            self.channel_split_nm > self.start_nm && self.channel_split_nm < self.end_nm,
            || "must lie between start_nm and end_nm".into(),
        );
        at.non_negative("intensity_noise", self.intensity_noise);
        at.in_range("threshold", self.threshold, 0.01, 0.99);
    }
}
