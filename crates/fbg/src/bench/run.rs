//! Running a bench scenario: the sensor sampled at the interrogator rate, rows logged at the recorder rate.

use super::config::BenchScenario;
use super::profile::Profile;
use crate::FbgSensor;
use crate::calibration::{BenchRecord, BenchRow};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

/// Simulates the scenario's experiment and returns what the bench logs. Deterministic in the seed.
pub fn run(s: &BenchScenario) -> BenchRecord {
    let profile: &dyn Profile = match (&s.force_cycles, &s.water_bath, &s.taped_heating) {
        (Some(e), _, _) => e,
        (_, Some(e), _) => e,
        (_, _, Some(e)) => e,
        _ => return BenchRecord::default(),
    };
    let has_load_cell = s.force_cycles.is_some();
    let has_thermometer = s.water_bath.is_some();
    // Separate streams: changing the load cell must not change the interrogator's noise.
    let mut sensor = FbgSensor::new(&s.sensor, &s.interrogator, s.seed);
    let mut rng = ChaCha8Rng::seed_from_u64(s.seed ^ 0x5EED_10AD_CE11);
    let dt = 1.0 / s.interrogator.sample_rate_hz;
    let record_dt = 1.0 / s.recorder.rate_hz;
    let samples = (profile.duration_s() / dt).floor() as usize;
    let mut rows = Vec::with_capacity((profile.duration_s() / record_dt) as usize + 1);
    let (mut sum1, mut sum2, mut count) = (0.0, 0.0, 0usize);
    let mut next_record = 0.0;
    for k in 0..=samples {
        let t = k as f64 * dt;
        let (force, temperature) = profile.at(t);
        let w = sensor.sample(force, temperature, dt);
        if s.recorder.average {
            sum1 += w.fbg1_nm;
            sum2 += w.fbg2_nm;
            count += 1;
        } else {
            (sum1, sum2, count) = (w.fbg1_nm, w.fbg2_nm, 1);
        }
        if t + 1e-9 >= next_record {
            let load_cell_n = has_load_cell.then(|| {
                let z: f64 = rng.sample(StandardNormal);
                quantize(force + s.load_cell.noise_n * z, s.load_cell.quantization_n)
            });
            let temperature_c = has_thermometer.then(|| quantize(temperature, s.recorder.thermometer_resolution_c));
            rows.push(BenchRow {
                time_s: t,
                load_cell_n,
                fbg1_nm: sum1 / count as f64,
                fbg2_nm: sum2 / count as f64,
                temperature_c,
            });
            (sum1, sum2, count) = (0.0, 0.0, 0);
            next_record += record_dt;
        }
    }
    BenchRecord { rows }
}

fn quantize(v: f64, step: f64) -> f64 {
    if step > 0.0 { (v / step).round() * step } else { v }
}
