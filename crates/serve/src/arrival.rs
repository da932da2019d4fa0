//! The RTDE inputs as the virtual controller's program sees them: each package from the twin time
//! it arrived at, never earlier.
//!
//! A real controller's clock is the wall clock. The twin's clock is too, until the twin falls
//! behind (a stalled process, a busy or virtual machine): it then runs its ticks back to back
//! until it has caught up, and a package that arrived at the end of a stall was visible to every
//! tick of the catch-up, up to a stall earlier in twin time than it came. The follow program reads
//! that as a package that came early and takes its arrival as the new earliest, which moves its
//! playback forward at once by the stall: the arm's setpoint jumped. Measured on the short array
//! lift (`scenarios/hammer-array.toml`, the real-path test's short task) against `tendril serve`
//! at `--rt-priority 19`: the twin fell 4-8 ms behind about once a second, the program's earliest
//! arrival moved 6-8 ms, and in 6 of 18 runs one such jump shook the hammer in the lift (the pad's
//! true force 1.66 → 2.2 → 0 → 3.0 N over four steps; the estimate's 95th percentile in the lift
//! 1.62-1.67 N against the twin's 1.556 N). Held back to their arrival, packages reach the program
//! as they would reach a controller that never stalls.

use std::collections::VecDeque;
use std::time::Instant;
use tendril_rtde::{RobotInputs, SharedInputs};

/// Packages held for a stalled twin at most (10 s of a client's 100 Hz stream); beyond it the
/// oldest are let through (the twin is then far behind real time and its devices' timing is lost
/// anyway; its clients' watchdogs stop them long before).
pub const MAX_HELD: usize = 1000;

/// The inputs the program reads, and the packages not yet due.
#[derive(Debug, Default)]
pub struct ProgramInputs {
    /// Wall instant of twin time 0, once the twin runs (before: packages are visible at once).
    twin_clock: Option<Instant>,
    /// Twin time each held package arrived at \[s\], the inputs after it and the packages applied
    /// up to it; oldest first.
    held: VecDeque<(f64, RobotInputs, u64)>,
    /// What the program reads.
    pub values: RobotInputs,
    /// Input packages applied up to [`ProgramInputs::values`].
    pub packages: u64,
}

impl ProgramInputs {
    /// Starts the twin's clock: twin time 0 is `origin`.
    pub fn start_clock(&mut self, origin: Instant) {
        self.twin_clock = Some(origin);
    }

    /// Records `inputs` as they stand after a package that arrived now.
    pub fn arrived(&mut self, inputs: &SharedInputs) {
        let at_s = self.twin_clock.map_or(0.0, |origin| origin.elapsed().as_secs_f64());
        self.arrived_at(at_s, inputs);
    }

    /// Records `inputs` as they stand after a package that arrived at twin time `at_s` \[s\].
    pub fn arrived_at(&mut self, at_s: f64, inputs: &SharedInputs) {
        if self.held.len() >= MAX_HELD {
            self.release_oldest();
        }
        self.held.push_back((at_s, inputs.values.clone(), inputs.packages));
    }

    /// Makes every package that arrived by twin time `now_s` \[s\] visible to the program.
    pub fn advance_to(&mut self, now_s: f64) {
        while self.held.front().is_some_and(|(at_s, ..)| *at_s <= now_s) {
            self.release_oldest();
        }
    }

    fn release_oldest(&mut self) {
        if let Some((_, values, packages)) = self.held.pop_front() {
            (self.values, self.packages) = (values, packages);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tendril_rtde::RtdeValue;

    fn inputs_with(register_30: f64, packages: u64) -> SharedInputs {
        let mut inputs = SharedInputs::new();
        inputs.values.apply("input_double_register_30", RtdeValue::Double(register_30));
        inputs.packages = packages;
        inputs
    }

    #[test]
    fn a_package_reaches_the_program_at_the_twin_time_it_arrived_not_before() {
        let mut p = ProgramInputs::default();
        p.arrived_at(0.010, &inputs_with(1.0, 1));
        p.arrived_at(0.020, &inputs_with(2.0, 2));
        // A twin 8 ms behind catches up: its ticks before 10 ms see nothing yet.
        p.advance_to(0.009);
        assert_eq!((p.values.double_registers[30], p.packages), (0.0, 0));
        p.advance_to(0.015);
        assert_eq!((p.values.double_registers[30], p.packages), (1.0, 1));
        p.advance_to(0.020);
        assert_eq!((p.values.double_registers[30], p.packages), (2.0, 2));
    }

    #[test]
    fn before_the_twin_runs_packages_are_visible_at_once_and_a_long_stall_holds_a_bounded_number() {
        let mut p = ProgramInputs::default();
        p.arrived(&inputs_with(1.0, 1));
        p.advance_to(0.0);
        assert_eq!(p.packages, 1);
        for k in 0..(MAX_HELD as u64 + 5) {
            p.arrived_at(10.0 + k as f64 * 0.01, &inputs_with(k as f64, k + 2));
        }
        assert_eq!(p.held.len(), MAX_HELD);
        assert_eq!(p.packages, 6, "the five oldest let through");
    }
}
