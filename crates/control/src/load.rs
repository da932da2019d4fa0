//! Drop detection from the arm's wrist force sensor: the load the tool carries
//! ([`tendril_cell::CellState::tool_load_n`]), a cue beside the pad's force ([`super::slip`]).
//!
//! The pad sees a drop only when the object leaves it. Without feedback the twin's pad loses the
//! object seconds before it falls (it hangs meanwhile on the pinch between the palm and the
//! strip), and a slick object slides through a grip whose pad keeps its load. The wrist sees what
//! the hand as a whole carries: an object that leaves the hand takes its weight with it (the
//! crimper 3.4 N, the shampoo 2.2 N, the hammer 4.1 N).
//!
//! The cue learns the readings' zero and noise σ at home (arm still, nothing held: a UR's "zero
//! the force sensor"), then, while the arm carries the object:
//!
//! ```text
//! carried ← carried + (reading − carried) / LONG_WINDOW_TICKS     (from 0 when the carry begins)
//! k       = clamp(ceil((Z σ / (f carried))²), 1, LONG_WINDOW_TICKS)
//! fallen  = the mean of the last k readings ≤ (1 − f) carried
//! ```
//!
//! The carried load is an exponential mean over about `LONG_WINDOW_TICKS` readings: it follows the
//! load up as the object leaves the table, scatters by under a tenth of the noise, and lags a fall
//! that the `k`-reading mean (a few ticks) sees at once. (The largest of the long means, tried
//! first, read the shampoo 0.4-0.6 N heavy at the default noise: the maximum of thousands of noisy
//! means.)
//!
//! with `f = slip.load_fall_fraction`, and [`Z`] as for the pad's cues. The cue is *armed* once
//! the fall it looks for, `f carried`, stands `Z` SDs of the `k`-reading mean clear of the noise:
//! before that (nothing carried yet, an object too light for the sensor, or a cell without one)
//! the pad's cues keep the drop alarm ([`super::slip::SlipDetector`]).
//!
//! The carried load is learnt from the readings, so an object the hand never took up (a slick one
//! that stays on the table while the grip slides up it) shows no fall. For that the cue also
//! checks the load against the object's weight `W` once the caller says the hand should carry it
//! (the detector: once the hand has risen `slip.lift_check_m` since the carry began):
//!
//! ```text
//! k_W   = clamp(ceil((Z σ / (f W))²), 1, LONG_WINDOW_TICKS)
//! short = the mean of the last k_W readings ≤ (1 − f) W
//! ```
//!
//! armed, like the fall, once `f W` stands `Z` SDs of the `k_W`-reading mean clear of the noise.

use super::contact::{RunningStats, Z};
use std::collections::VecDeque;

/// The carried load's time constant \[ticks\], and the longest the fall's average may be: 0.5 s at
/// 100 Hz. Long enough that the carried load scatters by σ/10 (0.08 N at the default 0.78 N per
/// tick, against the shampoo's 1.1 N fall), short enough that the carry's first second arms the
/// cue.
pub const LONG_WINDOW_TICKS: usize = 50;

/// The wrist's cue (see the module docs).
#[derive(Debug, Clone)]
pub struct LoadCue {
    fall_fraction: f64,
    home: RunningStats,
    /// The last readings while carrying, less the zero learnt at home (at most [`LONG_WINDOW_TICKS`]).
    recent: VecDeque<f64>,
    /// The exponential mean of the readings since the carry began \[N\].
    carried_n: f64,
}

impl LoadCue {
    /// A cue for a fall of `fall_fraction` of the carried load, nothing learnt.
    pub fn new(fall_fraction: f64) -> LoadCue {
        LoadCue { fall_fraction, home: RunningStats::default(), recent: VecDeque::new(), carried_n: 0.0 }
    }

    /// Learns from one reading at home \[N\] (nothing held, the arm still).
    pub fn observe_home(&mut self, load_n: f64) {
        self.home.add(load_n);
    }

    /// The readings' noise learnt at home \[N\] (1 SD).
    pub fn noise_n(&self) -> f64 {
        self.home.sd()
    }

    /// The load carried, as read since the carry began \[N\].
    pub fn carried_n(&self) -> f64 {
        self.carried_n
    }

    /// How many readings the fall is averaged over.
    pub fn window_ticks(&self) -> usize {
        self.ticks_to_see(self.fall_fraction * self.carried_n)
    }

    /// Whether the cue can see the fall it looks for (see the module docs).
    pub fn armed(&self) -> bool {
        self.can_see(self.fall_fraction * self.carried_n)
    }

    /// How many readings a change of `change_n` \[N\] is averaged over to stand [`Z`] SDs clear of
    /// the noise (at most [`LONG_WINDOW_TICKS`]).
    fn ticks_to_see(&self, change_n: f64) -> usize {
        let k = (Z * self.noise_n() / change_n).powi(2).ceil();
        if change_n > 0.0 && k.is_finite() { (k as usize).clamp(1, LONG_WINDOW_TICKS) } else { LONG_WINDOW_TICKS }
    }

    /// Whether a change of `change_n` \[N\] stands [`Z`] SDs clear of the noise of the mean it is
    /// read from (and the noise has been learnt).
    fn can_see(&self, change_n: f64) -> bool {
        self.home.count() >= 2
            && change_n > 0.0
            && change_n >= Z * self.noise_n() / (self.ticks_to_see(change_n) as f64).sqrt()
    }

    /// The mean of the last `k` readings, once there are `k`.
    fn recent_mean(&self, k: usize) -> Option<f64> {
        (self.recent.len() >= k).then(|| self.recent.iter().rev().take(k).sum::<f64>() / k as f64)
    }

    /// Takes one reading \[N\] while `carrying`; `expected_n` is the object's weight \[N\] once the
    /// hand should carry it (else `None`). A missing or non-finite reading changes nothing. Outside
    /// the carry the window empties and the carried load is forgotten.
    pub fn update(&mut self, load_n: Option<f64>, carrying: bool, expected_n: Option<f64>) -> LoadCues {
        if !carrying {
            self.recent.clear();
            self.carried_n = 0.0;
            return LoadCues::default();
        }
        let Some(load) = load_n.filter(|l| l.is_finite()) else { return LoadCues::default() };
        let load = load - self.home.mean();
        self.recent.push_back(load);
        if self.recent.len() > LONG_WINDOW_TICKS {
            self.recent.pop_front();
        }
        self.carried_n += (load - self.carried_n) / LONG_WINDOW_TICKS as f64;
        let keep = 1.0 - self.fall_fraction;
        let fell =
            self.armed() && self.recent_mean(self.window_ticks()).is_some_and(|mean| mean <= keep * self.carried_n);
        let short = expected_n.is_some_and(|weight| {
            let change = self.fall_fraction * weight;
            self.can_see(change)
                && self.recent_mean(self.ticks_to_see(change)).is_some_and(|mean| mean <= keep * weight)
        });
        LoadCues { fell, short }
    }
}

/// The wrist's cues on one reading.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LoadCues {
    /// The load fell by `fall_fraction` of the carried load (the cue armed).
    pub fell: bool,
    /// The hand should carry the object, and the load is short of its weight by `fall_fraction`
    /// or more (the check armed).
    pub short: bool,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::gaussian;

    /// A cue that learnt `sigma` at home around a zero of 0.7 N.
    fn learnt(sigma: f64) -> LoadCue {
        let mut cue = LoadCue::new(0.5);
        for e in gaussian(sigma, 50, 3) {
            cue.observe_home(0.7 + e);
        }
        cue
    }

    /// Feeds `load(t)` plus noise at 100 Hz for `seconds` while carrying; the first tick the cue
    /// was on \[s\].
    fn first_on(cue: &mut LoadCue, sigma: f64, seconds: f64, load: impl Fn(f64) -> f64) -> Option<f64> {
        let n = (seconds * 100.0) as usize;
        let mut first = None;
        for (i, e) in gaussian(sigma, n, 17).into_iter().enumerate() {
            let t = i as f64 * 0.01;
            if cue.update(Some(0.7 + load(t) + e), true, None).fell && first.is_none() {
                first = Some(t);
            }
        }
        first
    }

    #[test]
    fn the_shampoo_leaving_the_hand_is_seen_within_a_tenth_of_a_second_and_its_noise_never() {
        // 0.78 N: the default 1.75 N per 500 Hz reading, averaged over a 10 ms tick.
        let sigma = 0.78;
        let mut held = learnt(sigma);
        assert_eq!(first_on(&mut held, sigma, 30.0, |_| 2.18), None);
        // The zero learnt from 50 readings at home is good to σ/√50 = 0.11 N.
        assert!(held.armed() && (1.9..2.5).contains(&held.carried_n()), "{}", held.carried_n());
        let mut dropped = learnt(sigma);
        let seen = first_on(&mut dropped, sigma, 10.0, |t| if t < 5.0 { 2.18 } else { 0.0 }).unwrap();
        assert!((5.0..5.1).contains(&seen), "{seen}");
    }

    #[test]
    fn a_load_too_light_for_the_noise_never_arms_the_cue() {
        let mut cue = learnt(0.78);
        assert_eq!(first_on(&mut cue, 0.78, 10.0, |t| if t < 5.0 { 0.3 } else { 0.0 }), None);
        assert!(!cue.armed(), "{}", cue.carried_n());
    }

    #[test]
    fn a_cell_without_the_sensor_or_outside_the_carry_never_alarms() {
        let mut cue = learnt(0.1);
        for _ in 0..200 {
            assert_eq!(cue.update(None, true, Some(3.4)), LoadCues::default());
        }
        for _ in 0..200 {
            assert_eq!(cue.update(Some(3.0), false, Some(3.4)), LoadCues::default());
        }
        assert_eq!(cue.carried_n(), 0.0);
    }

    #[test]
    fn an_object_the_hand_never_took_up_is_short_of_its_weight_once_it_should_carry_it() {
        // A slick crimper (3.4 N) stays on the table: the wrist reads the grip's drag, 0.5 N. Until
        // the hand should carry it nothing is short; from then on the check sees it at once.
        let sigma = 0.78;
        let mut cue = learnt(sigma);
        let noise = gaussian(sigma, 300, 23);
        let mut first_short = None;
        for (i, e) in noise.iter().enumerate() {
            let t = i as f64 * 0.01;
            let expected = (t >= 2.0).then_some(3.4);
            let cues = cue.update(Some(0.7 + 0.5 + e), true, expected);
            assert!(!cues.fell, "nothing carried, nothing to fall from");
            if cues.short && first_short.is_none() {
                first_short = Some(t);
            }
        }
        let seen = first_short.expect("the missing weight is seen");
        assert!((2.0..2.1).contains(&seen), "{seen}");
        // Carried, the same check stays quiet through the noise.
        let mut carried = learnt(sigma);
        for (i, e) in gaussian(sigma, 3000, 29).into_iter().enumerate() {
            let expected = (i >= 200).then_some(3.4);
            assert!(!carried.update(Some(0.7 + 3.4 + e), true, expected).short, "tick {i}");
        }
        // An object too light for the sensor never arms the check.
        let mut light = learnt(sigma);
        for e in gaussian(sigma, 300, 31) {
            assert!(!light.update(Some(0.7 + e), true, Some(0.5)).short);
        }
    }
}
