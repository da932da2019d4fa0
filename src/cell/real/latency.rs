//! Control-tick latency of a cell: how long after each tick's deadline its read → write finished.

use crate::hardware::{Cell, CellCommand, CellError};
use std::time::{Duration, Instant};

/// Latency figures over a run.
#[derive(Debug, Clone, PartialEq)]
pub struct LatencyReport {
    /// Ticks measured.
    pub ticks: usize,
    /// Median latency [s].
    pub p50_s: f64,
    /// 99th percentile [s].
    pub p99_s: f64,
    /// Largest [s].
    pub max_s: f64,
    /// Ticks whose read → write finished after the next tick's deadline.
    pub missed_deadlines: usize,
    /// 99th percentile of the read → write time alone, without the wake-up lateness [s].
    pub work_p99_s: f64,
}

/// Runs `cell` (configured and activated here) at `rate_hz` for `seconds`, holding the measured
/// pose; latency = end of `write` − the tick's deadline (wake-up lateness + read + write).
pub fn measure(cell: &mut dyn Cell, rate_hz: f64, seconds: f64) -> Result<LatencyReport, CellError> {
    let period = 1.0 / rate_hz;
    cell.configure()?;
    // Deadlines count from just before activation (cell time 0), so latency is never understated.
    let start = Instant::now();
    cell.activate()?;
    let n = (seconds * rate_hz).round().max(1.0) as usize;
    let mut latencies = Vec::with_capacity(n);
    let mut work = Vec::with_capacity(n);
    let mut missed = 0;
    let result = (|| {
        for k in 0..n {
            let deadline = start + Duration::from_secs_f64(k as f64 * period);
            let woke = Instant::now();
            let s = cell.read()?;
            cell.write(&CellCommand {
                arm_q: s.arm_q,
                growth_motor_rad: s.growth_motor_rad,
                twine_motor_rad: s.twine_motor_rad,
            })?;
            let latency = Instant::now().saturating_duration_since(deadline).as_secs_f64();
            if latency > period {
                missed += 1;
            }
            latencies.push(latency);
            work.push(woke.elapsed().as_secs_f64());
            cell.wait_until((k + 1) as f64 * period)?;
        }
        Ok::<(), CellError>(())
    })();
    let stop = cell.deactivate();
    result?;
    stop?;
    latencies.sort_by(f64::total_cmp);
    work.sort_by(f64::total_cmp);
    let at = |v: &[f64], p: f64| v[((v.len() - 1) as f64 * p).round() as usize];
    let pct = |p: f64| at(&latencies, p);
    Ok(LatencyReport {
        ticks: latencies.len(),
        p50_s: pct(0.5),
        p99_s: pct(0.99),
        max_s: latencies.last().copied().unwrap_or(0.0),
        missed_deadlines: missed,
        work_p99_s: at(&work, 0.99),
    })
}

/// Puts the calling thread under `SCHED_FIFO` at `priority` (1-99), as real-time robot drivers do
/// (ur_rtde's `rt_priority`). Needs CAP_SYS_NICE or root; the error says why it failed.
pub fn set_realtime_priority(priority: i32) -> std::io::Result<()> {
    let param = libc::sched_param { sched_priority: priority };
    // SAFETY: plain syscall on the calling thread with a valid parameter struct.
    let rc = unsafe { libc::sched_setscheduler(0, libc::SCHED_FIFO, &param) };
    if rc == 0 { Ok(()) } else { Err(std::io::Error::last_os_error()) }
}
