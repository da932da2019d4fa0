//! A slip cue from a sensor array: the load moving along the finger.
//!
//! A single pad sees a slip only once its own load falls (`crate::slip`). An object that slides
//! along the wrap while the wrap still carries it moves its load from pad to pad first: the pads'
//! *shares* of the array's load change while their total may not. The cue compares each tick's
//! shares with their slow average (a first-order filter of time constant `tau_s`) and raises an
//! alarm when the fraction of the load that moved, half the summed share differences (0: the same
//! distribution, 1: the load wholly on other pads), passes `transfer`. The slow average follows
//! the distribution's drift as the lift brings the object's weight on; a knock or a slide moves it
//! within a few ticks. The cue raises nothing in the first `tau_s` of a watch: the average is not
//! yet a distribution to compare with, and the lift-off, when the weight comes onto the wrap,
//! shuffles the load between pads in every run (measured: up to 0.6 of it in the first 0.2 s of
//! a shampoo's lift that went on to hold).

/// What the cue has seen and raised.
#[derive(Debug, Clone, PartialEq)]
pub struct ArrayCue {
    transfer: f64,
    tau_s: f64,
    min_load_n: f64,
    slow: Vec<f64>,
    last_s: Option<f64>,
    watch_start_s: f64,
    in_episode: bool,
    alarms_s: Vec<f64>,
}

impl ArrayCue {
    /// A cue alarming when `transfer` (0-1) of the load has moved between pads against the shares'
    /// slow average over `tau_s` \[s\], watching only while the pads carry at least `min_load_n`
    /// \[N\] together (below it there is no distribution to follow: the single-pad detectors see a
    /// load that is lost).
    pub fn new(transfer: f64, tau_s: f64, min_load_n: f64) -> ArrayCue {
        ArrayCue {
            transfer,
            tau_s,
            min_load_n,
            slow: Vec::new(),
            last_s: None,
            watch_start_s: 0.0,
            in_episode: false,
            alarms_s: Vec::new(),
        }
    }

    /// One tick at `time_s` with each pad's load `loads_n` (estimate minus the pad's unloaded
    /// reading, \[N\]); `watching` while the arm carries the object. Returns whether an alarm
    /// episode starts this tick.
    pub fn update(&mut self, time_s: f64, loads_n: &[f64], watching: bool) -> bool {
        let total: f64 = loads_n.iter().map(|l| l.max(0.0)).sum();
        // A NaN total (a pad without an estimate) watches nothing, as too little load does.
        let loaded = total >= self.min_load_n;
        if !watching || loads_n.len() < 2 || !loaded {
            self.slow.clear();
            self.last_s = None;
            self.in_episode = false;
            return false;
        }
        let shares = loads_n.iter().map(|l| l.max(0.0) / total);
        if self.slow.len() != loads_n.len() {
            self.slow = shares.collect();
            self.last_s = Some(time_s);
            self.watch_start_s = time_s;
            return false;
        }
        let dt = time_s - self.last_s.unwrap_or(time_s);
        self.last_s = Some(time_s);
        let alpha = if self.tau_s > 0.0 { (dt / self.tau_s).clamp(0.0, 1.0) } else { 1.0 };
        let mut moved = 0.0;
        for (slow, share) in self.slow.iter_mut().zip(shares) {
            moved += 0.5 * (share - *slow).abs();
            *slow += alpha * (share - *slow);
        }
        let armed = time_s - self.watch_start_s >= self.tau_s;
        let starts = armed && !self.in_episode && moved > self.transfer;
        if starts {
            self.alarms_s.push(time_s);
        }
        // An episode ends once the distribution has settled to half the threshold.
        self.in_episode = if self.in_episode { moved > 0.5 * self.transfer } else { starts };
        starts
    }

    /// The start of each alarm episode \[s\].
    pub fn alarms_s(&self) -> &[f64] {
        &self.alarms_s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_load_sliding_from_pad_to_pad_alarms_and_a_slow_drift_does_not() {
        let mut cue = ArrayCue::new(0.3, 1.0, 0.2);
        // 10 s of a slow drift: the share of pad 1 grows from 0.2 to 0.5.
        for i in 0..1000 {
            let s = 0.2 + 0.3 * i as f64 / 1000.0;
            assert!(!cue.update(i as f64 * 0.01, &[2.0 * (1.0 - s), 2.0 * s, 0.0], true), "tick {i}");
        }
        // Then the load passes onto pad 2 within 0.1 s.
        let mut fired = None;
        for i in 0..30 {
            let f = (i as f64 / 10.0).min(1.0);
            if cue.update(10.0 + i as f64 * 0.01, &[1.0 * (1.0 - f), 1.0 * (1.0 - f), 2.0 * f], true) {
                fired = Some(i);
            }
        }
        assert!(fired.is_some_and(|i| i <= 6), "{fired:?}");
        assert_eq!(cue.alarms_s().len(), 1, "one episode");
    }

    #[test]
    fn below_the_least_load_or_outside_the_carry_it_watches_nothing() {
        let mut cue = ArrayCue::new(0.3, 1.0, 0.2);
        assert!(!cue.update(0.0, &[0.05, 0.0], true));
        assert!(!cue.update(0.01, &[0.0, 0.1], true));
        assert!(!cue.update(0.02, &[1.0, 0.0], false));
        assert!(!cue.update(0.03, &[0.0, 1.0], false));
        assert!(cue.alarms_s().is_empty());
    }
}
