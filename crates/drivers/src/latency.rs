//! Control-tick latency of a cell: how long after each tick's deadline its read → write finished.
//!
//! [`measure_idle`] runs the same schedule with no work at all: what the machine alone gives (on a
//! shared or virtual machine the thread is sometimes not run for milliseconds, whatever it does),
//! the floor against which [`measure`]'s figures are read.

use super::realtime;
use std::time::{Duration, Instant};
use tendril_cell::{Cell, CellCommand, CellError};

/// Latency figures over a run.
#[derive(Debug, Clone, PartialEq)]
pub struct LatencyReport {
    /// Ticks measured.
    pub ticks: usize,
    /// Median latency \[s\].
    pub p50_s: f64,
    /// 99th percentile \[s\].
    pub p99_s: f64,
    /// Largest \[s\].
    pub max_s: f64,
    /// Ticks whose read → write finished after the next tick's deadline.
    pub missed_deadlines: usize,
    /// Runs of consecutive missed deadlines: one stall of the thread makes the ticks behind it
    /// late too, so this counts the stalls.
    pub missed_runs: usize,
    /// 99th percentile of the read → write time alone, without the wake-up lateness \[s\].
    pub work_p99_s: f64,
}

/// Runs `cell` (configured and activated here) at `rate_hz` for `seconds`, holding the measured
/// pose; latency = end of `write` − the tick's deadline (wake-up lateness + read + write).
pub fn measure(cell: &mut dyn Cell, rate_hz: f64, seconds: f64) -> Result<LatencyReport, CellError> {
    cell.configure()?;
    cell.activate()?;
    // The schedule is the cell's clock: its time 0, from a first read. Taken before the read, so
    // the deadlines are never later than the cell's and latency is never understated.
    let before = Instant::now();
    let result = cell.read().and_then(|first| {
        let start = before.checked_sub(Duration::from_secs_f64(first.time_s)).unwrap_or(before);
        tick_loop(&mut OnCell(&mut *cell), rate_hz, seconds, start)
    });
    let stop = cell.deactivate();
    let report = result?;
    stop?;
    Ok(report)
}

/// The same schedule as [`measure`] with nothing to do in a tick, waiting as the real cell does
/// ([`realtime::sleep_until`], 1 ns timer slack): the latency the calling thread gets from the
/// machine alone.
pub fn measure_idle(rate_hz: f64, seconds: f64) -> LatencyReport {
    realtime::set_timer_slack_ns(1);
    let start = Instant::now();
    match tick_loop(&mut Idle { start }, rate_hz, seconds, start) {
        Ok(report) => report,
        Err(never) => match never {},
    }
}

/// What runs on the fixed schedule: one tick's work, and the wait for the next deadline.
trait Ticks {
    type Error;
    /// One tick's work.
    fn tick(&mut self) -> Result<(), Self::Error>;
    /// Waits until `time_s` after the schedule's start.
    fn wait_until(&mut self, time_s: f64) -> Result<(), Self::Error>;
}

/// A cell's read → write, holding the pose it reads.
struct OnCell<'a>(&'a mut dyn Cell);

impl Ticks for OnCell<'_> {
    type Error = CellError;

    fn tick(&mut self) -> Result<(), CellError> {
        let s = self.0.read()?;
        self.0.write(&CellCommand {
            arm_q: s.arm_q,
            growth_motor_rad: s.growth_motor_rad,
            twine_motor_rad: s.twine_motor_rad,
        })
    }

    fn wait_until(&mut self, time_s: f64) -> Result<(), CellError> {
        self.0.wait_until(time_s)
    }
}

/// Nothing to do, waiting as [`super::RealCell`] does.
struct Idle {
    start: Instant,
}

impl Ticks for Idle {
    type Error = std::convert::Infallible;

    fn tick(&mut self) -> Result<(), Self::Error> {
        Ok(())
    }

    fn wait_until(&mut self, time_s: f64) -> Result<(), Self::Error> {
        realtime::sleep_until(self.start + Duration::from_secs_f64(time_s));
        Ok(())
    }
}

/// Runs `ticks` on a fixed schedule from `start` at `rate_hz` for `seconds` and reports each
/// tick's latency.
fn tick_loop<T: Ticks>(ticks: &mut T, rate_hz: f64, seconds: f64, start: Instant) -> Result<LatencyReport, T::Error> {
    let period = 1.0 / rate_hz;
    let n = (seconds * rate_hz).round().max(1.0) as usize;
    // Allocated and written once up front: the loop neither allocates nor faults pages in.
    let mut latencies = vec![f64::NAN; n];
    let mut work = vec![f64::NAN; n];
    let (mut missed, mut missed_runs, mut missed_previous) = (0, 0, false);
    for k in 0..n {
        let deadline = start + Duration::from_secs_f64(k as f64 * period);
        let woke = Instant::now();
        ticks.tick()?;
        let latency = Instant::now().saturating_duration_since(deadline).as_secs_f64();
        let late = latency > period;
        missed += usize::from(late);
        missed_runs += usize::from(late && !missed_previous);
        missed_previous = late;
        latencies[k] = latency;
        work[k] = woke.elapsed().as_secs_f64();
        ticks.wait_until((k + 1) as f64 * period)?;
    }
    latencies.sort_by(f64::total_cmp);
    work.sort_by(f64::total_cmp);
    let at = |v: &[f64], p: f64| v[((v.len() - 1) as f64 * p).round() as usize];
    Ok(LatencyReport {
        ticks: latencies.len(),
        p50_s: at(&latencies, 0.5),
        p99_s: at(&latencies, 0.99),
        max_s: latencies.last().copied().unwrap_or(0.0),
        missed_deadlines: missed,
        missed_runs,
        work_p99_s: at(&work, 0.99),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_idle_loop_reports_every_tick() {
        let r = measure_idle(1000.0, 0.05);
        assert_eq!(r.ticks, 50);
        assert!(r.p50_s <= r.p99_s && r.p99_s <= r.max_s);
        assert!(r.work_p99_s < 1e-3, "an empty tick takes no time: {r:?}");
    }
}
