//! [`FbgSensor`]: the sample-by-sample forward model.

use super::config::{InterrogatorConfig, InterrogatorMode, SensorConfig};
use super::spectral::SpectralInterrogator;
use super::thermal::ThermalLag;
use crate::hysteresis::{PiModel, PiState};
use crate::signals::Wavelengths;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

/// The simulated sensor and interrogator. Deterministic for a given seed.
#[derive(Debug, Clone)]
pub struct FbgSensor {
    cfg: SensorConfig,
    noise_pm: f64,
    quantization_pm: f64,
    hysteresis: PiModel,
    hysteresis_state: PiState,
    lag1: ThermalLag,
    lag2: ThermalLag,
    spectral: Option<SpectralInterrogator>,
    rng: ChaCha8Rng,
}

impl FbgSensor {
    /// A sensor at rest (no load, thermal state set by the first sample). The configurations are
    /// expected to be validated (scenario loading does it).
    pub fn new(sensor: &SensorConfig, interrogator: &InterrogatorConfig, seed: u64) -> FbgSensor {
        FbgSensor {
            cfg: sensor.clone(),
            noise_pm: interrogator.noise_pm,
            quantization_pm: interrogator.quantization_pm,
            hysteresis: PiModel::lagging(&sensor.hysteresis_widths_n, &sensor.hysteresis_weights),
            hysteresis_state: PiState::default(),
            lag1: ThermalLag::new(sensor.thermal_lag1_s),
            lag2: ThermalLag::new(sensor.thermal_lag2_s),
            spectral: match interrogator.mode {
                InterrogatorMode::Analytic => None,
                InterrogatorMode::Spectral => Some(SpectralInterrogator::new(&interrogator.spectral)),
            },
            rng: ChaCha8Rng::seed_from_u64(seed),
        }
    }

    /// The true (noise-free) Bragg wavelengths \[nm\] for force `force_n` \[N\] and temperature
    /// `temperature_c` [°C], advancing hysteresis and thermal states by `dt_s` \[s\].
    #[inline]
    pub fn bragg(&mut self, force_n: f64, temperature_c: f64, dt_s: f64) -> Wavelengths {
        // A contact force is never negative; past the range the uvula rests on the floor.
        let n = force_n.max(0.0).min(self.cfg.range_n);
        let n_eff = self.hysteresis.output(&mut self.hysteresis_state, n);
        let t1 = self.lag1.step(temperature_c, dt_s);
        let t2 = self.lag2.step(temperature_c, dt_s);
        let t_ref = self.cfg.reference_temperature_c;
        let d1_pm = self.cfg.backbone_pm(n_eff) + self.cfg.kt1_pm_per_c * (t1 - t_ref);
        let d2_pm = self.cfg.kt2_pm_per_c * (t2 - t_ref);
        Wavelengths { fbg1_nm: self.cfg.lambda1_nm + d1_pm * 1e-3, fbg2_nm: self.cfg.lambda2_nm + d2_pm * 1e-3 }
    }

    /// One interrogator sample: the reported peak wavelengths \[nm\] for the true force \[N\] and
    /// temperature [°C] at the sensor; `dt_s` \[s\] is the time since the previous sample.
    #[inline]
    pub fn sample(&mut self, force_n: f64, temperature_c: f64, dt_s: f64) -> Wavelengths {
        let b = self.bragg(force_n, temperature_c, dt_s);
        let (p1, p2) = match &mut self.spectral {
            Some(s) => s.detect(b.fbg1_nm, b.fbg2_nm, &mut self.rng),
            None => {
                let z1: f64 = self.rng.sample(StandardNormal);
                let z2: f64 = self.rng.sample(StandardNormal);
                (b.fbg1_nm + z1 * self.noise_pm * 1e-3, b.fbg2_nm + z2 * self.noise_pm * 1e-3)
            }
        };
        Wavelengths { fbg1_nm: self.quantize(p1), fbg2_nm: self.quantize(p2) }
    }

    /// `nm` on the interrogator's reporting step (`quantization_pm`), as [`FbgSensor::sample`]
    /// reports it.
    #[inline]
    pub fn quantize(&self, nm: f64) -> f64 {
        if self.quantization_pm > 0.0 {
            let q = self.quantization_pm * 1e-3;
            (nm / q).round() * q
        } else {
            nm
        }
    }

    /// The sensor configuration.
    pub fn config(&self) -> &SensorConfig {
        &self.cfg
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quiet() -> InterrogatorConfig {
        InterrogatorConfig { noise_pm: 0.0, quantization_pm: 0.0, ..InterrogatorConfig::default() }
    }

    #[test]
    fn zero_shift_at_zero_force_and_reference_temperature() {
        let mut s = FbgSensor::new(&SensorConfig::default(), &quiet(), 1);
        let w = s.sample(0.0, 25.0, 0.001);
        assert_eq!(w, Wavelengths { fbg1_nm: 1540.0, fbg2_nm: 1550.0 });
    }

    #[test]
    fn saturates_past_the_range() {
        let mut s = FbgSensor::new(&SensorConfig::default(), &quiet(), 1);
        for i in 0..=469 {
            s.sample(i as f64 * 0.01, 25.0, 0.001);
        }
        let at_range = s.sample(4.69, 25.0, 0.001);
        let beyond = s.sample(8.0, 25.0, 0.001);
        assert_eq!(at_range, beyond);
        let span_pm = (at_range.fbg1_nm - 1540.0) * 1000.0;
        assert!((span_pm - 5482.78).abs() < 0.03 * 5482.78, "span {span_pm} pm");
    }

    #[test]
    fn thermal_step_moves_each_grating_by_its_sensitivity_with_its_own_lag() {
        let cfg = SensorConfig::default();
        let mut s = FbgSensor::new(&cfg, &quiet(), 1);
        s.sample(0.0, 25.0, 0.01);
        let mut w = s.sample(0.0, 35.0, 0.0);
        for _ in 0..500 {
            w = s.sample(0.0, 35.0, 0.01); // 5 s = one FBG2 time constant, half an FBG1 one
        }
        let d1 = (w.fbg1_nm - 1540.0) * 1000.0 / 243.0;
        let d2 = (w.fbg2_nm - 1550.0) * 1000.0 / 103.1;
        assert!((d1 - (1.0 - (-0.5_f64).exp())).abs() < 0.01, "FBG1 fraction {d1}");
        assert!((d2 - (1.0 - (-1.0_f64).exp())).abs() < 0.01, "FBG2 fraction {d2}");
    }

    /// The loop of a noise-free 0 → 4.69 → 0 N cycle, straight from the model: widest gap between
    /// the unloading and the loading branch near the paper's 4.83 % of full scale at 2.68 N.
    #[test]
    fn hysteresis_loop_maximum_and_location() {
        let mut s = FbgSensor::new(&SensorConfig::default(), &quiet(), 1);
        let steps = 4690;
        let mut shift = |n: f64| (s.sample(n, 25.0, 0.001).fbg1_nm - 1540.0) * 1000.0;
        let load: Vec<f64> = (0..=steps).map(|i| shift(i as f64 * 0.001)).collect();
        let unload: Vec<f64> = (0..=steps).rev().map(|i| shift(i as f64 * 0.001)).collect();
        let full_scale = load[steps];
        let (at, gap) = (0..=steps)
            .map(|i| (i as f64 * 0.001, unload[steps - i] - load[i]))
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap();
        let percent = 100.0 * gap / full_scale;
        assert!((percent - 4.83).abs() < 0.5, "max hysteresis {percent} %");
        assert!((at - 2.68).abs() < 0.1, "at {at} N");
        assert!(unload[steps].abs() < 1e-9, "the loop closes at 0 N");
    }

    #[test]
    fn spectral_mode_tracks_the_analytic_peaks() {
        let spectral = InterrogatorConfig { mode: InterrogatorMode::Spectral, ..InterrogatorConfig::default() };
        let mut a = FbgSensor::new(&SensorConfig::default(), &quiet(), 1);
        let mut b = FbgSensor::new(&SensorConfig::default(), &spectral, 1);
        let mut worst: f64 = 0.0;
        for i in 0..=200 {
            let (n, t) = (i as f64 * 0.0234, 20.0 + i as f64 * 0.1);
            let (wa, wb) = (a.sample(n, t, 0.001), b.sample(n, t, 0.001));
            worst = worst.max((wa.fbg1_nm - wb.fbg1_nm).abs()).max((wa.fbg2_nm - wb.fbg2_nm).abs());
        }
        assert!(worst * 1000.0 < 15.0, "spectral peaks {} pm off", worst * 1000.0);
    }

    #[test]
    fn same_seed_same_samples() {
        let run = |seed| {
            let mut s = FbgSensor::new(&SensorConfig::default(), &InterrogatorConfig::default(), seed);
            (0..100).map(|i| s.sample(i as f64 * 0.01, 30.0, 0.001)).collect::<Vec<_>>()
        };
        assert_eq!(run(7), run(7));
        assert_ne!(run(7), run(8));
    }
}
