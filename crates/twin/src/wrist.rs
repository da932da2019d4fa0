//! The arm's wrist force sensor on the twin (TOML `[wrist]`): the vertical load the tool carries,
//! as a UR5e reports it (RTDE `actual_TCP_force`, its z component, with the tool's own payload
//! compensated) and the control code reads it through [`tendril_cell::CellState::tool_load_n`].
//!
//! The physics gives the object's load on everything the arm carries
//! ([`super::physics::PhysicsReadout::tool_load_n`]); the sensor adds white noise, from a random
//! stream of its own so that a wrist reading never moves the interrogator's noise (a run with
//! the same seed keeps its wavelengths to the last digit). The UR's pose-dependent error (its
//! datasheet's 4 N accuracy over the workspace) is not modelled: the control code compares the
//! load with what it read a fraction of a second before, while the arm has turned a few degrees.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use serde::{Deserialize, Serialize};
use tendril_config::{Checker, Validate};

/// Added to the scenario's seed for the wrist's random stream, so that it differs from the
/// interrogator's (seeded with the seed itself) [-]: any fixed number does; this one spells
/// "wrist" in ASCII.
const STREAM: u64 = 0x77_72_69_73_74;

/// The wrist force sensor's model (TOML `[wrist]`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct WristConfig {
    /// Whether the arm has the sensor. `false` leaves the control code the pad's force alone, as
    /// in the paper (and as on an arm without a wrist force sensor).
    pub present: bool,
    /// Standard deviation of one reading's noise \[N\]. 1.75 N: the UR5e datasheet gives the
    /// built-in force/torque sensor a force precision of 3.5 N, read here as a ±2σ band of a
    /// single reading (a stated reading of the figure: the datasheet does not say how it is
    /// measured). The control code learns the noise at home, so a quieter or noisier sensor only
    /// changes how many readings it averages.
    pub noise_n: f64,
    /// Readings per second \[Hz\]: 500 Hz, the UR e-Series' RTDE rate. A control tick reads the
    /// mean of the readings since the last (five at 100 Hz: the noise over √5, 0.78 N by default),
    /// as the real cell's RTDE reader does.
    pub sample_rate_hz: f64,
}

impl Default for WristConfig {
    fn default() -> Self {
        WristConfig { present: true, noise_n: 1.75, sample_rate_hz: 500.0 }
    }
}

impl Validate for WristConfig {
    fn validate(&self, at: &mut Checker) {
        // 50 N: the UR5e sensor's force range; noise beyond it would be no reading at all.
        at.in_range("noise_n", self.noise_n, 0.0, 50.0);
        // 1 Hz to 10 kHz: slower, and a control tick would see no reading; the e-Series streams
        // at most 500 Hz, and a faster sensor changes nothing but the averaging.
        at.in_range("sample_rate_hz", self.sample_rate_hz, 1.0, 10_000.0);
    }
}

/// The wrist sensor of one run: the noise's random stream.
#[derive(Debug, Clone)]
pub struct WristSensor {
    config: WristConfig,
    rng: ChaCha8Rng,
    /// Cell time of the last reading \[s\].
    last_s: f64,
}

impl WristSensor {
    /// A sensor with `config`'s noise, its stream drawn from the run's `seed`.
    pub fn new(config: &WristConfig, seed: u64) -> WristSensor {
        WristSensor { config: *config, rng: ChaCha8Rng::seed_from_u64(seed.wrapping_add(STREAM)), last_s: 0.0 }
    }

    /// The mean of the readings of the true load `load_n` \[N\] since the last call, at cell time
    /// `time_s` \[s\] (at least one reading: the load held over the interval).
    pub fn read(&mut self, load_n: f64, time_s: f64) -> f64 {
        let readings = ((time_s - self.last_s) * self.config.sample_rate_hz).round().max(1.0);
        self.last_s = time_s;
        let z: f64 = self.rng.sample(StandardNormal);
        load_n + self.config.noise_n / readings.sqrt() * z
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tick_reads_the_mean_of_its_readings_and_repeats_with_the_seed() {
        // 100 Hz ticks of a 400 Hz sensor: four readings a tick, the noise halved.
        let config = WristConfig { noise_n: 2.0, sample_rate_hz: 400.0, ..WristConfig::default() };
        let mut a = WristSensor::new(&config, 7);
        let readings: Vec<f64> = (1..=20_000).map(|i| a.read(3.0, i as f64 * 0.01)).collect();
        let mean = readings.iter().sum::<f64>() / readings.len() as f64;
        let sd = (readings.iter().map(|r| (r - mean).powi(2)).sum::<f64>() / (readings.len() - 1) as f64).sqrt();
        assert!((mean - 3.0).abs() < 0.05, "{mean}");
        assert!((sd - 1.0).abs() < 0.03, "{sd}");
        let mut b = WristSensor::new(&config, 7);
        assert_eq!(b.read(3.0, 0.01), readings[0]);
        let mut other = WristSensor::new(&config, 8);
        assert_ne!(other.read(3.0, 0.01), readings[0]);
    }

    #[test]
    fn a_noise_outside_the_sensor_range_is_refused() {
        for bad in [-1.0, 51.0, f64::NAN] {
            let mut at = Checker::default();
            at.section("wrist", &WristConfig { noise_n: bad, ..WristConfig::default() });
            assert_eq!(at.errors().first().map(|e| e.0.as_str()), Some("wrist.noise_n"), "{bad}");
        }
    }
}
