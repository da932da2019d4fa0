//! First-order thermal lag of a grating behind its packaging: `τ·dT_g/dt = T − T_g`.

/// The temperature a grating sees, lagging the surroundings with time constant `tau_s`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ThermalLag {
    tau_s: f64,
    state_c: Option<f64>,
    // exp(−dt/τ) for the last dt, cached: samples come at a fixed rate.
    last_dt: f64,
    last_decay: f64,
}

impl ThermalLag {
    /// A lag with time constant `tau_s` \[s\] (0 = no lag); starts in equilibrium with the first input.
    pub fn new(tau_s: f64) -> ThermalLag {
        ThermalLag { tau_s, state_c: None, last_dt: f64::NAN, last_decay: 0.0 }
    }

    /// Advances by `dt_s` towards `surroundings_c` and returns the grating temperature [°C].
    /// The exact discrete step of the linear ODE for a piecewise-constant input, so any `dt_s` is stable.
    #[inline]
    pub fn step(&mut self, surroundings_c: f64, dt_s: f64) -> f64 {
        let t = match self.state_c {
            None => surroundings_c,
            Some(prev) => {
                if dt_s != self.last_dt {
                    self.last_dt = dt_s;
                    self.last_decay = if self.tau_s > 0.0 { (-dt_s.max(0.0) / self.tau_s).exp() } else { 0.0 };
                }
                surroundings_c + (prev - surroundings_c) * self.last_decay
            }
        };
        self.state_c = Some(t);
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn step_response_reaches_63_percent_after_one_time_constant() {
        let mut lag = ThermalLag::new(10.0);
        lag.step(25.0, 0.001);
        let mut t = 25.0;
        for _ in 0..10_000 {
            t = lag.step(35.0, 0.001);
        }
        let expected = 35.0 - 10.0 * (-1.0_f64).exp();
        assert!((t - expected).abs() < 1e-9, "{t} vs {expected}");
    }

    #[test]
    fn zero_lag_follows_the_input() {
        let mut lag = ThermalLag::new(0.0);
        lag.step(20.0, 0.01);
        assert_eq!(lag.step(30.0, 0.01), 30.0);
    }
}
