//! [`CommandClock`]: when a ROS 2 commander's arm targets are due on the twin's clock.
//!
//! A commander (a ros2_control update loop, tendril's own `--hardware ros2`) sends a target every
//! control period, stamped with its clock. Acting on each when it arrives would copy the network's
//! and the scheduler's jitter into the arm's motion: on a loaded machine two targets arrive in one
//! twin tick and the next none for 20 ms, and the setpoint's speed swings with them (measured: the
//! short lift's force then read 0.15-3.3 N at its 5th-95th percentiles against the twin's
//! 0.54-0.58 N). So each target is placed at its stamp, shifted onto the twin's clock by the
//! smallest delay seen lately (the least delayed command arrived when it was sent), and the arm
//! passes through it one of the commander's periods later: late commands up to a period behind
//! still arrive before they are due, and the arm moves at the commander's own cadence.
//!
//! Two things keep that shift steady:
//! - Arrivals are timed on the wall clock, not by the twin's ticks. On a loaded machine the twin
//!   falls behind and catches up (0 to 280 ms behind, over and over, with two busy processes on
//!   two cores); timed by its ticks, the delays seemed to shrink while it fell behind, the least
//!   was taken from there, and every target after the catch-up came late and was jumped to (the
//!   short lift's force read 0.15-2.2 N at its 5th-95th percentiles). Timed on the wall clock it
//!   read 0.53-0.58 N, as the twin's.
//! - The shift slews toward the least delay at [`SLEW`], as NTP slews a clock instead of
//!   stepping it. The least delay changes when the least delayed command leaves the window or a
//!   less delayed one comes (by 3 ms now and then on an idle machine); applied at once, each
//!   change moved every later target by as much, and the arm stopped or leapt for it.
use std::collections::VecDeque;

/// Commands the least delay is taken over \[-\]: 100, a second at 100 Hz, so the clock follows a
/// commander whose clock drifts against the twin's, and one delayed command never sets it.
pub const WINDOW: usize = 100;

/// Least and greatest spacing of a commander's targets the delay allows for \[s\]: 2 ms (the
/// virtual UR5e's own program cycle) to 50 ms (a 20 Hz commander).
pub const CADENCE_S: (f64, f64) = (0.002, 0.05);

/// How fast the offset the targets are placed with follows the least delay \[s/s\]: 0.01, a
/// hundredth of the commander's time, so the arm's speed changes by at most 1 % while it does
/// (the grip does not feel it). It follows clocks that drift apart by up to 1 %, a hundred times
/// a quartz clock's 100 ppm, and closes a 10 ms change of the least delay in a second.
pub const SLEW: f64 = 0.01;

/// Places a commander's stamped targets on the twin's clock.
#[derive(Debug, Default, Clone)]
pub struct CommandClock {
    /// Arrival minus stamp of the last [`WINDOW`] commands \[s\].
    offsets: VecDeque<f64>,
    /// Their stamps \[s\].
    stamps: VecDeque<f64>,
    /// The offset the targets are placed with \[s\]: the first command's, then slewed toward
    /// the least of `offsets`.
    applied: Option<f64>,
}

impl CommandClock {
    /// When a target stamped `stamp_s` that arrived at twin time `arrival_s` is due, and how much
    /// later than that the arm passes it (the commander's period, within [`CADENCE_S`]). A
    /// commander whose stamps do not advance (all zero, say) has its targets placed at arrival.
    pub fn place(&mut self, stamp_s: f64, arrival_s: f64) -> (f64, f64) {
        let advancing = self.stamps.back().is_none_or(|&last| stamp_s > last);
        if !advancing {
            self.offsets.clear();
            self.stamps.clear();
            self.applied = None;
        }
        let since_last_s = self.stamps.back().map_or(0.0, |&last| stamp_s - last);
        if self.offsets.len() == WINDOW {
            self.offsets.pop_front();
            self.stamps.pop_front();
        }
        self.offsets.push_back(arrival_s - stamp_s);
        self.stamps.push_back(stamp_s);
        let mut gaps: Vec<f64> = self.stamps.iter().zip(self.stamps.iter().skip(1)).map(|(a, b)| b - a).collect();
        if !advancing || gaps.is_empty() {
            return (arrival_s, CADENCE_S.0);
        }
        gaps.sort_by(f64::total_cmp);
        let cadence = gaps[gaps.len() / 2].clamp(CADENCE_S.0, CADENCE_S.1);
        let least = self.offsets.iter().copied().fold(f64::INFINITY, f64::min);
        let step = SLEW * since_last_s;
        let offset = self.applied.map_or(least, |a| a + (least - a).clamp(-step, step));
        self.applied = Some(offset);
        (stamp_s + offset, cadence)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jittered_arrivals_are_placed_at_the_commanders_cadence() {
        let mut clock = CommandClock::default();
        // Stamps on the wall clock since 1970 (what a ROS node without sim time sends): f64 holds
        // them to 0.24 µs.
        let epoch = 1.7e9;
        let mut placed = Vec::new();
        for k in 0..50 {
            let stamp = epoch + k as f64 * 0.01;
            // Arrivals 0-6 ms late, two bunched now and then.
            let late = [0.0, 0.006, 0.001, 0.0055, 0.003][k % 5];
            placed.push(clock.place(stamp, 3.0 + k as f64 * 0.01 + late));
        }
        for w in placed[10..].windows(2) {
            assert!((w[1].0 - w[0].0 - 0.01).abs() < 1e-6, "{w:?}");
            assert!((w[1].1 - 0.01).abs() < 1e-6, "a period of allowance: {w:?}");
        }
        assert!((placed[49].0 - (3.0 + 0.49)).abs() < 1e-6, "on the least delayed command's clock");
    }

    #[test]
    fn a_change_of_the_least_delay_is_slewed_not_stepped() {
        let mut clock = CommandClock::default();
        // 1 ms late for two windows, then 6 ms late: the least delay rises by 5 ms once the
        // last 1 ms arrival leaves the window.
        let placed: Vec<(f64, f64)> = (0..400)
            .map(|k| {
                let stamp = k as f64 * 0.01;
                let late = if k < 200 { 0.001 } else { 0.006 };
                clock.place(stamp, stamp + late)
            })
            .collect();
        for (k, w) in placed.windows(2).enumerate().skip(1) {
            let spacing = w[1].0 - w[0].0;
            assert!((spacing - 0.01).abs() <= SLEW * 0.01 + 1e-9, "target {k}: spacing {spacing}");
        }
        // Slewed at 1 %, the 5 ms are closed within 0.5 s of the commander's time.
        let last = placed[399].0 - 3.99;
        assert!((last - 0.006).abs() < 1e-9, "on the new least delay at the end: {last}");
    }

    #[test]
    fn stamps_that_do_not_advance_are_placed_at_arrival() {
        let mut clock = CommandClock::default();
        assert_eq!(clock.place(0.0, 2.0), (2.0, CADENCE_S.0));
        assert_eq!(clock.place(0.0, 2.5), (2.5, CADENCE_S.0));
    }
}
