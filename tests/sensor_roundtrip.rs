//! Forward model → estimator round trip over forces × temperatures (property tests).

use proptest::prelude::*;
use tendril_fbg::estimate::{ForceCalibration, ForceEstimator};
use tendril_fbg::signals::Wavelengths;
use tendril_fbg::{FbgSensor, InterrogatorConfig, SensorConfig};

/// Mean of `n` samples at a held force and temperature (the lags settle first).
fn settle_and_average(s: &mut FbgSensor, force: f64, temp: f64, n: usize) -> Wavelengths {
    for _ in 0..200 {
        s.sample(force, temp, 1.0); // 200 s: many thermal time constants
    }
    let (mut a, mut b) = (0.0, 0.0);
    for _ in 0..n {
        let w = s.sample(force, temp, 0.001);
        a += w.fbg1_nm;
        b += w.fbg2_nm;
    }
    Wavelengths { fbg1_nm: a / n as f64, fbg2_nm: b / n as f64 }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// A hysteresis-free sensor whose strain response is exactly the estimator's quadratic (c = 0)
    /// reads back the force within the interrogator noise at any temperature: 16-sample means have
    /// σ = 3 pm·√(1 + r²)/4 ≈ 1.9 pm, ≤ 0.004 N at ≥ 527 pm/N; the bound is 6σ plus quantization.
    #[test]
    fn round_trip_within_noise(force in 0.0f64..4.4, temp in 10.0f64..50.0, tare_temp in 15.0f64..40.0, seed in 0u64..1000) {
        let sensor = SensorConfig {
            strain_k1_pm_per_n: 527.62,
            strain_k2_pm_per_n2: 144.99,
            strain_k3_pm_per_n3: 0.0,
            hysteresis_widths_n: vec![],
            hysteresis_weights: vec![],
            ..SensorConfig::default()
        };
        let cal = ForceCalibration { c_pm: 0.0, r: sensor.kt1_pm_per_c / sensor.kt2_pm_per_c, ..ForceCalibration::default() };
        let mut s = FbgSensor::new(&sensor, &InterrogatorConfig::default(), seed);
        let mut est = ForceEstimator::new(cal);
        est.tare(settle_and_average(&mut s, 0.0, tare_temp, 16));
        let e = est.estimate(settle_and_average(&mut s, force, temp, 16)).unwrap();
        prop_assert!((e.force_n - force).abs() < 0.025, "force {force} temp {temp}: read {}", e.force_n);
        prop_assert!(!e.force_n.is_nan() && !e.uncompensated_n.is_nan());
    }

    /// The paper's sensor (hysteresis, cubic backbone) read with the paper's calibration: the error
    /// stays within the calibration's own spread (fit residual + half the hysteresis loop), at any
    /// temperature, and a saturated sensor is flagged over-range.
    #[test]
    fn paper_sensor_reads_within_calibration_error(force in 0.3f64..6.0, temp in 10.0f64..50.0, seed in 0u64..1000) {
        let mut s = FbgSensor::new(&SensorConfig::default(), &InterrogatorConfig::default(), seed);
        let mut est = ForceEstimator::new(ForceCalibration::default());
        est.tare(settle_and_average(&mut s, 0.0, 25.0, 16));
        let e = est.estimate(settle_and_average(&mut s, force, temp, 16)).unwrap();
        if force <= 4.69 {
            prop_assert!((e.force_n - force).abs() < 0.35, "force {force} temp {temp}: read {}", e.force_n);
        }
        if force >= 4.69 {
            prop_assert!(e.over_range, "saturated at {force} N but not flagged: {}", e.force_n);
        }
    }
}
