//! First contact in the guarded close, robust to the interrogator's noise.
//!
//! The close ends when the force estimate has risen `task.wrap_contact_n` above its unloaded
//! reading. At the paper's 3 pm of peak noise one reading is enough: at zero force the estimate
//! scatters by σ ≈ 13 mN (the calibration curve is at its flattest there), and 0.1 N is 8σ. At
//! 10 pm (σ ≈ 43 mN) a single reading crosses 0.1 N about once in a hundred ticks and at 30 pm
//! (σ ≈ 0.13 N) every few ticks, so the close stopped with nothing touching (measured: at 4.7 s
//! and 3.3 s, true force 0, where 3 pm closed at 5.5 s on contact).
//!
//! So the detector learns the estimate's noise σ while the task is at home (finger retracted,
//! untouched: the same samples the tare averages) and compares the mean of the last `k` readings
//! with a threshold:
//!
//! ```text
//! k         = clamp(ceil((Z σ / rise)²), 1, MAX_WINDOW_TICKS)
//! threshold = max(rise, Z σ / √k)          rise = task.wrap_contact_n
//! ```
//!
//! The averaged noise then stays [`Z`] = 5 of its standard deviations below the threshold (a
//! false trigger once in 3.5 million windows, about 300 windows in a close), and at the paper's
//! noise `k` = 1 and the threshold is `rise`: the single reading of before, unchanged.

use std::collections::VecDeque;

/// Standard deviations of the averaged noise between it and the threshold. 5: a Gaussian
/// exceeds it with probability 2.9e-7, so a 3 s close at 100 Hz false-triggers about once in
/// 3500 closes; 4 would be once in 100.
pub const Z: f64 = 5.0;

/// Longest averaging window \[ticks\]. 25 ticks is 0.25 s at 100 Hz, in which the close (15 °/s)
/// winds 3.75° more tendon; beyond it the threshold is raised instead (30 pm: 0.13 N).
pub const MAX_WINDOW_TICKS: usize = 25;

/// Decides when the guarded close has touched the object (see the module docs).
#[derive(Debug, Clone)]
pub struct ContactDetector {
    rise_n: f64,
    /// The unloaded readings' statistics.
    unloaded: RunningStats,
    window: VecDeque<f64>,
}

/// Welford's running count, mean and sum of squared deviations: the noise of readings learnt one
/// at a time (non-finite ones left out).
#[derive(Debug, Clone, Default)]
pub struct RunningStats {
    count: u64,
    mean: f64,
    m2: f64,
}

impl RunningStats {
    /// Adds one reading; a non-finite one is left out (it would poison the rest).
    pub fn add(&mut self, x: f64) {
        if !x.is_finite() {
            return;
        }
        self.count += 1;
        let delta = x - self.mean;
        self.mean += delta / self.count as f64;
        self.m2 += delta * (x - self.mean);
    }

    /// How many readings were added.
    pub fn count(&self) -> u64 {
        self.count
    }

    /// Their mean (0 before the first).
    pub fn mean(&self) -> f64 {
        self.mean
    }

    /// Their sample standard deviation (0 before two of them).
    pub fn sd(&self) -> f64 {
        if self.count < 2 { 0.0 } else { (self.m2 / (self.count - 1) as f64).sqrt() }
    }
}

impl ContactDetector {
    /// A detector for a rise of `rise_n` \[N\] above the unloaded reading, nothing learnt yet.
    pub fn new(rise_n: f64) -> Self {
        ContactDetector { rise_n, unloaded: RunningStats::default(), window: VecDeque::new() }
    }

    /// Learns from one estimate taken with nothing on the sensor \[N\].
    pub fn observe_unloaded(&mut self, force_n: f64) {
        self.unloaded.add(force_n);
    }

    /// Standard deviation of the unloaded readings \[N\] (0 before two of them).
    pub fn noise_n(&self) -> f64 {
        self.unloaded.sd()
    }

    /// How many readings the decision averages.
    pub fn window_ticks(&self) -> usize {
        let k = (Z * self.noise_n() / self.rise_n).powi(2).ceil();
        if k.is_finite() { (k as usize).clamp(1, MAX_WINDOW_TICKS) } else { MAX_WINDOW_TICKS }
    }

    /// The rise the averaged readings must reach \[N\].
    pub fn threshold_n(&self) -> f64 {
        self.rise_n.max(Z * self.noise_n() / (self.window_ticks() as f64).sqrt())
    }

    /// Forgets the readings of an earlier close, for a new one (a long grasp's re-wrap).
    pub fn restart(&mut self) {
        self.window.clear();
    }

    /// Takes this tick's rise of the estimate above the unloaded reading \[N\]; true once the mean
    /// of the last [`Self::window_ticks`] rises reaches [`Self::threshold_n`].
    pub fn touched(&mut self, rise_n: f64) -> bool {
        let k = self.window_ticks();
        self.window.push_back(rise_n);
        while self.window.len() > k {
            self.window.pop_front();
        }
        self.window.len() == k && self.window.iter().sum::<f64>() / k as f64 >= self.threshold_n()
    }
}

/// A deterministic N(0, σ²) stream (Box-Muller on a small LCG), so the detectors' tests need no RNG
/// crate.
#[cfg(test)]
pub(crate) fn gaussian(sigma: f64, n: usize, seed: u64) -> Vec<f64> {
    let mut s = seed;
    let mut uniform = move || {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((s >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    };
    (0..n).map(|_| sigma * (-2.0 * uniform().ln()).sqrt() * (std::f64::consts::TAU * uniform()).cos()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn learnt(sigma: f64) -> ContactDetector {
        let mut d = ContactDetector::new(0.1);
        for f in gaussian(sigma, 300, 7) {
            d.observe_unloaded(0.17 + f);
        }
        d
    }

    #[test]
    fn at_the_papers_noise_one_reading_decides_as_before() {
        let mut d = learnt(0.013);
        assert_eq!(d.window_ticks(), 1, "σ = {}", d.noise_n());
        assert_eq!(d.threshold_n(), 0.1);
        assert!(!d.touched(0.099));
        assert!(d.touched(0.1));
    }

    #[test]
    fn noisier_readings_are_averaged_and_the_threshold_rises_past_the_longest_window() {
        let d10 = learnt(0.043);
        assert!((4..=6).contains(&d10.window_ticks()), "{}", d10.window_ticks());
        assert_eq!(d10.threshold_n(), 0.1);
        let d30 = learnt(0.13);
        assert_eq!(d30.window_ticks(), MAX_WINDOW_TICKS);
        assert!((d30.threshold_n() - Z * d30.noise_n() / 5.0).abs() < 1e-12);
        assert!(d30.threshold_n() > 0.12 && d30.threshold_n() < 0.14, "{}", d30.threshold_n());
    }

    #[test]
    fn noise_alone_never_triggers_and_a_real_rise_does() {
        for sigma in [0.013, 0.043, 0.13] {
            let mut d = learnt(sigma);
            // 3000 ticks (ten 3 s closes) of noise around the unloaded reading: no contact.
            for (i, f) in gaussian(sigma, 3000, 99).into_iter().enumerate() {
                assert!(!d.touched(f), "σ = {sigma}: false contact at tick {i}");
            }
            // Contact: the estimate steps up by 0.3 N (the pad meeting the object) and stays.
            let ticks = gaussian(sigma, 100, 5).into_iter().position(|f| d.touched(0.3 + f));
            let k = d.window_ticks();
            assert!(ticks.is_some_and(|t| t < k + 5), "σ = {sigma}: detected after {ticks:?} ticks (window {k})");
        }
    }

    #[test]
    fn without_a_home_phase_it_is_the_single_reading_rule() {
        let mut d = ContactDetector::new(0.1);
        assert_eq!((d.noise_n(), d.window_ticks(), d.threshold_n()), (0.0, 1, 0.1));
        d.observe_unloaded(f64::NAN);
        assert_eq!(d.noise_n(), 0.0);
        assert!(d.touched(0.2));
    }
}
