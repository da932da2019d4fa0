//! Pacing the twin against the wall clock at a speed factor (`tendril view --speed`).

use std::time::Duration;

/// Largest lag behind the wall clock \[s\] the pacer catches up on. When the physics cannot keep
/// up (a slow machine, a high `--speed`), the pacer re-anchors instead of rushing through the
/// backlog, so the picture never jumps ahead in a burst.
pub const MAX_LAG_S: f64 = 0.25;

/// Maps cell time to wall time: `speed` cell seconds per wall second from an anchor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pacer {
    speed: f64,
    anchor_wall: Duration,
    anchor_cell_s: f64,
}

impl Pacer {
    /// A pacer at `speed` (cell seconds per wall second, > 0) that shows cell time `cell_s` at
    /// wall time `now`.
    pub fn new(speed: f64, now: Duration, cell_s: f64) -> Pacer {
        Pacer { speed, anchor_wall: now, anchor_cell_s: cell_s }
    }

    /// The speed factor.
    pub fn speed(&self) -> f64 {
        self.speed
    }

    /// Starts counting again from `cell_s` at `now` (after a pause: the paused time is not made
    /// up for).
    pub fn restart(&mut self, now: Duration, cell_s: f64) {
        self.anchor_wall = now;
        self.anchor_cell_s = cell_s;
    }

    /// Wall time at which cell time `cell_s` is due.
    pub fn due(&self, cell_s: f64) -> Duration {
        let offset = ((cell_s - self.anchor_cell_s) / self.speed).max(0.0);
        self.anchor_wall + Duration::from_secs_f64(offset)
    }

    /// How long to wait at wall time `now` before cell time `cell_s` is due; zero when it is
    /// due or late. More than [`MAX_LAG_S`] late, the pacer re-anchors on (`now`, `cell_s`).
    pub fn wait(&mut self, now: Duration, cell_s: f64) -> Duration {
        let due = self.due(cell_s);
        if due >= now {
            return due - now;
        }
        if (now - due).as_secs_f64() > MAX_LAG_S {
            self.restart(now, cell_s);
        }
        Duration::ZERO
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn s(x: f64) -> Duration {
        Duration::from_secs_f64(x)
    }

    /// Equal to the microsecond (durations from decimal seconds round in the last nanosecond).
    fn close(a: Duration, b: Duration) -> bool {
        a.abs_diff(b) < Duration::from_micros(1)
    }

    #[test]
    fn real_time_waits_out_the_cell_time() {
        let mut p = Pacer::new(1.0, s(10.0), 0.0);
        assert!(close(p.wait(s(10.0), 0.5), s(0.5)));
        assert!(close(p.wait(s(10.2), 0.5), s(0.3)));
        assert_eq!(p.wait(s(10.6), 0.5), Duration::ZERO, "late: no wait");
    }

    #[test]
    fn the_speed_factor_divides_the_wall_time() {
        let mut p = Pacer::new(2.0, s(0.0), 1.0);
        assert!(close(p.wait(s(0.0), 3.0), s(1.0)), "2 cell seconds at 2x are 1 wall second");
        let mut slow = Pacer::new(0.5, s(0.0), 0.0);
        assert!(close(slow.wait(s(0.0), 1.0), s(2.0)));
    }

    #[test]
    fn a_pause_is_not_made_up_for() {
        let mut p = Pacer::new(1.0, s(0.0), 0.0);
        // Paused from wall 1 s to wall 5 s at cell time 1 s.
        p.restart(s(5.0), 1.0);
        assert!(close(p.wait(s(5.0), 1.1), s(0.1)));
    }

    #[test]
    fn a_large_lag_re_anchors_instead_of_rushing() {
        let mut p = Pacer::new(1.0, s(0.0), 0.0);
        // The physics fell 2 s behind: no burst, the next tick is paced from now.
        assert_eq!(p.wait(s(3.0), 1.0), Duration::ZERO);
        assert!(close(p.wait(s(3.0), 1.01), s(0.01)));
        // A small lag is caught up on (no re-anchor).
        let mut q = Pacer::new(1.0, s(0.0), 0.0);
        assert_eq!(q.wait(s(1.1), 1.0), Duration::ZERO);
        assert!(close(q.wait(s(1.1), 1.15), s(0.05)));
    }
}
