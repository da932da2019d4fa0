//! Bench scenario files: the sensor, the interrogator, the bench instruments and one experiment.

use crate::{InterrogatorConfig, SensorConfig};
use serde::{Deserialize, Serialize};
use tendril_config::{Checker, Validate};

/// A bench scenario (`scenarios/bench-*.toml`): exactly one of the experiment sections
/// `[force_cycles]`, `[water_bath]`, `[taped_heating]` must be present.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BenchScenario {
    /// Seed of every random draw (interrogator and load-cell noise) [-]; any `u64` (above
    /// `i64::MAX` as a decimal string, see [`tendril_config::seed`]).
    #[serde(
        deserialize_with = "tendril_config::seed::deserialize",
        serialize_with = "tendril_config::seed::serialize"
    )]
    pub seed: u64,
    /// The sensor (defaults: the paper's).
    #[serde(default)]
    pub sensor: SensorConfig,
    /// The interrogator (defaults: the paper's HYPERION si255).
    #[serde(default)]
    pub interrogator: InterrogatorConfig,
    /// The load cell under the sensor.
    #[serde(default)]
    pub load_cell: LoadCellConfig,
    /// How the bench logs samples.
    #[serde(default)]
    pub recorder: RecorderConfig,
    /// Calibration to read this run with (validation and compensation runs). Absent: the one the
    /// calibration scenarios fit (`tendril reproduce sensor`).
    pub estimator: Option<crate::estimate::ForceCalibration>,
    /// Load/unload cycles by the linear actuator (force calibration and validation).
    pub force_cycles: Option<ForceCycles>,
    /// Free sensor in a heated water bath (temperature calibration).
    pub water_bath: Option<WaterBath>,
    /// Sensor taped to the glass while the water heats (compensation test).
    pub taped_heating: Option<TapedHeating>,
}

impl BenchScenario {
    fn experiments(&self) -> usize {
        self.force_cycles.is_some() as usize
            + self.water_bath.is_some() as usize
            + self.taped_heating.is_some() as usize
    }
}

/// Longest stage of a bench experiment \[s\]: a day. The paper's longest is the water bath's
/// holds of minutes; the simulated bench draws every interrogator sample, so a stage of 1e9 s would
/// run for days.
pub const MAX_STAGE_S: f64 = 86_400.0;

impl Validate for BenchScenario {
    fn validate(&self, at: &mut Checker) {
        at.section("sensor", &self.sensor);
        at.section("interrogator", &self.interrogator);
        at.section("load_cell", &self.load_cell);
        at.section("recorder", &self.recorder);
        if let Some(e) = &self.estimator {
            at.section("estimator", e);
        }
        at.require("(top level)", self.experiments() == 1, || {
            format!(
                "needs exactly one experiment section ([force_cycles], [water_bath] or [taped_heating]), found {}",
                self.experiments()
            )
        });
        let range = self.sensor.range_n;
        if let Some(e) = &self.force_cycles {
            at.section("force_cycles", e);
            at.require("force_cycles.peak_force_n", e.peak_force_n <= range, || {
                format!("{} N is past the sensor range sensor.range_n = {range} N", e.peak_force_n)
            });
        }
        if let Some(e) = &self.water_bath {
            at.section("water_bath", e);
        }
        if let Some(e) = &self.taped_heating {
            at.section("taped_heating", e);
            for (key, v) in [("press_peak_n", e.press_peak_n), ("tape_initial_n", e.tape_initial_n)] {
                at.require(&format!("taped_heating.{key}"), v + e.tape_final_n.max(0.0) <= range, || {
                    format!(
                        "the force profile reaches {} N, past the sensor range sensor.range_n = {range} N",
                        v + e.tape_final_n
                    )
                });
            }
        }
    }
}

/// The load cell (Futek LTH300) read by the bench's data acquisition (Arduino Uno).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LoadCellConfig {
    /// Standard deviation of the force noise \[N\]. Not published (the LTH300's capacity and the
    /// amplifier are not given; an Uno's 10-bit ADC over a 50 lb cell is 0.22 N per count). Tuned:
    /// 0.095 N makes the calibration's force RMSE the paper's 0.12 N.
    pub noise_n: f64,
    /// Reported force step \[N\] (0 = none).
    pub quantization_n: f64,
}

impl Default for LoadCellConfig {
    fn default() -> Self {
        LoadCellConfig { noise_n: 0.095, quantization_n: 0.0 }
    }
}

impl Validate for LoadCellConfig {
    fn validate(&self, at: &mut Checker) {
        at.non_negative("noise_n", self.noise_n);
        at.non_negative("quantization_n", self.quantization_n);
    }
}

/// The bench logger: one record row per period, holding the interrogator samples averaged over it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RecorderConfig {
    /// Rows per second \[Hz\]. 100 Hz: a choice (the paper does not state its logging rate).
    pub rate_hz: f64,
    /// Average the interrogator samples within each period (boxcar) instead of keeping the last.
    pub average: bool,
    /// Thermometer resolution [°C]; the IKA hot plate's probe shows 0.1 °C.
    pub thermometer_resolution_c: f64,
}

impl Default for RecorderConfig {
    fn default() -> Self {
        RecorderConfig { rate_hz: 100.0, average: true, thermometer_resolution_c: 0.1 }
    }
}

impl Validate for RecorderConfig {
    fn validate(&self, at: &mut Checker) {
        // Up to the fastest interrogator's 10 kHz: the recorder cannot log faster than it samples.
        at.in_range("rate_hz", self.rate_hz, 1e-3, 10_000.0);
        at.non_negative("thermometer_resolution_c", self.thermometer_resolution_c);
    }
}

/// Load/unload cycles by the linear actuator at a constant temperature: a rest (the tare), the
/// cycles back to back (`ramp up → ramp down`), a rest.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ForceCycles {
    /// Number of cycles [-].
    pub cycles: u32,
    /// Peak force of each cycle \[N\]; at most the sensor range.
    pub peak_force_n: f64,
    /// Duration of each loading ramp \[s\].
    pub load_time_s: f64,
    /// Duration of each unloading ramp \[s\].
    pub unload_time_s: f64,
    /// Unloaded time before the first cycle (the tare) and after the last \[s\].
    pub rest_s: f64,
    /// Lab temperature [°C].
    pub temperature_c: f64,
}

impl Validate for ForceCycles {
    fn validate(&self, at: &mut Checker) {
        // 1000 cycles: the paper runs 5; a thousand of the 30 s cycles is over eight hours.
        at.require("cycles", (1..=1000).contains(&self.cycles), || {
            format!("must be from 1 to 1000, got {}", self.cycles)
        });
        at.positive("peak_force_n", self.peak_force_n);
        at.in_range("load_time_s", self.load_time_s, 1e-3, MAX_STAGE_S);
        at.in_range("unload_time_s", self.unload_time_s, 1e-3, MAX_STAGE_S);
        let tare = crate::calibration::TARE_WINDOW_S;
        at.require("rest_s", self.rest_s.is_finite() && self.rest_s > tare && self.rest_s <= MAX_STAGE_S, || {
            format!("must be > {tare} s (the tare needs an unloaded start) and <= {MAX_STAGE_S} s, got {}", self.rest_s)
        });
        at.finite("temperature_c", self.temperature_c);
    }
}

/// Temperature calibration: free sensor in water heated at a constant rate between two holds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WaterBath {
    /// Starting water temperature [°C].
    pub start_c: f64,
    /// Final water temperature [°C].
    pub end_c: f64,
    /// Hold at each end \[s\].
    pub hold_s: f64,
    /// Duration of the ramp \[s\].
    pub ramp_s: f64,
}

impl Validate for WaterBath {
    fn validate(&self, at: &mut Checker) {
        at.finite("start_c", self.start_c);
        at.require("end_c", self.end_c.is_finite() && self.end_c != self.start_c, || {
            "must be finite and differ from start_c".into()
        });
        at.in_range("hold_s", self.hold_s, 1.0, MAX_STAGE_S);
        at.in_range("ramp_s", self.ramp_s, 1e-3, MAX_STAGE_S);
    }
}

/// Compensation test: the sensor, free in water, is taped to the glass (a finger presses it
/// meanwhile); the tape's residual force relaxes to a constant; the water is heated.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TapedHeating {
    /// Total duration \[s\].
    pub duration_s: f64,
    /// Water temperature at the start [°C].
    pub start_c: f64,
    /// Water temperature at the end of heating [°C].
    pub end_c: f64,
    /// Heating starts \[s\].
    pub heating_start_s: f64,
    /// Heating ends (then holds) \[s\].
    pub heating_end_s: f64,
    /// Tape applied (force starts) \[s\].
    pub tape_on_s: f64,
    /// Time of the finger's press peak \[s\].
    pub press_time_s: f64,
    /// Finger force at the peak, on top of the tape \[N\].
    pub press_peak_n: f64,
    /// Duration of the (half-sine) press \[s\].
    pub press_width_s: f64,
    /// Tape force when applied \[N\].
    pub tape_initial_n: f64,
    /// Tape force after relaxing \[N\].
    pub tape_final_n: f64,
    /// Relaxation time constant of the tape force \[s\].
    pub relax_tau_s: f64,
    /// From here on the force is taken as settled and the errors are measured \[s\].
    pub settle_s: f64,
}

impl Validate for TapedHeating {
    fn validate(&self, at: &mut Checker) {
        at.in_range("duration_s", self.duration_s, 1e-3, MAX_STAGE_S);
        at.finite("start_c", self.start_c);
        at.finite("end_c", self.end_c);
        at.non_negative("heating_start_s", self.heating_start_s);
        at.require("heating_end_s", self.heating_end_s > self.heating_start_s, || {
            "must be after heating_start_s".into()
        });
        at.require("tape_on_s", self.tape_on_s.is_finite() && self.tape_on_s >= 1.0, || {
            "must be >= 1 s (the tare needs an unloaded start)".into()
        });
        at.non_negative("press_time_s", self.press_time_s);
        at.non_negative("press_peak_n", self.press_peak_n);
        at.positive("press_width_s", self.press_width_s);
        at.non_negative("tape_initial_n", self.tape_initial_n);
        at.non_negative("tape_final_n", self.tape_final_n);
        at.positive("relax_tau_s", self.relax_tau_s);
        at.require("settle_s", self.settle_s > self.tape_on_s && self.settle_s < self.duration_s, || {
            "must lie between tape_on_s and duration_s".into()
        });
    }
}
