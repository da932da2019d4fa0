//! The true force and water temperature of each experiment as functions of time.

use super::config::{ForceCycles, TapedHeating, WaterBath};

/// What the bench applies at the sensor over time.
pub trait Profile {
    /// Duration of the experiment \[s\].
    fn duration_s(&self) -> f64;
    /// True normal force \[N\] and water/lab temperature [°C] at time `t` \[s\].
    fn at(&self, t: f64) -> (f64, f64);
}

impl Profile for ForceCycles {
    fn duration_s(&self) -> f64 {
        self.cycles as f64 * (self.load_time_s + self.unload_time_s) + 2.0 * self.rest_s
    }

    fn at(&self, t: f64) -> (f64, f64) {
        let period = self.load_time_s + self.unload_time_s;
        let local = t - self.rest_s;
        let k = (local / period).floor();
        let phase = local - k * period;
        let force = if local < 0.0 || k >= self.cycles as f64 {
            0.0
        } else if phase < self.load_time_s {
            self.peak_force_n * phase / self.load_time_s
        } else {
            self.peak_force_n * (1.0 - (phase - self.load_time_s) / self.unload_time_s)
        };
        (force.clamp(0.0, self.peak_force_n), self.temperature_c)
    }
}

impl Profile for WaterBath {
    fn duration_s(&self) -> f64 {
        2.0 * self.hold_s + self.ramp_s
    }

    fn at(&self, t: f64) -> (f64, f64) {
        let frac = ((t - self.hold_s) / self.ramp_s).clamp(0.0, 1.0);
        (0.0, self.start_c + (self.end_c - self.start_c) * frac)
    }
}

impl Profile for TapedHeating {
    fn duration_s(&self) -> f64 {
        self.duration_s
    }

    fn at(&self, t: f64) -> (f64, f64) {
        let frac = ((t - self.heating_start_s) / (self.heating_end_s - self.heating_start_s)).clamp(0.0, 1.0);
        let temperature = self.start_c + (self.end_c - self.start_c) * frac;
        if t < self.tape_on_s {
            return (0.0, temperature);
        }
        // The tape's residual force relaxes exponentially (TPU and adhesive creep) to its final value.
        let tape = self.tape_final_n
            + (self.tape_initial_n - self.tape_final_n) * (-(t - self.tape_on_s) / self.relax_tau_s).exp();
        let phase = (t - self.press_time_s) / self.press_width_s + 0.5;
        let press =
            if (0.0..=1.0).contains(&phase) { self.press_peak_n * (std::f64::consts::PI * phase).sin() } else { 0.0 };
        (tape + press, temperature)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cycles_ramp_to_the_peak_and_rest_between() {
        let c = ForceCycles {
            cycles: 2,
            peak_force_n: 4.0,
            load_time_s: 2.0,
            unload_time_s: 2.0,
            rest_s: 1.0,
            temperature_c: 23.0,
        };
        assert_eq!(c.duration_s(), 10.0);
        assert_eq!(c.at(0.5).0, 0.0);
        assert!((c.at(2.0).0 - 2.0).abs() < 1e-12);
        assert!((c.at(3.0).0 - 4.0).abs() < 1e-12);
        assert!((c.at(4.0).0 - 2.0).abs() < 1e-12);
        assert!((c.at(5.0).0 - 0.0).abs() < 1e-12);
        assert!((c.at(7.0).0 - 4.0).abs() < 1e-12);
        assert_eq!(c.at(9.5).0, 0.0);
    }
}
