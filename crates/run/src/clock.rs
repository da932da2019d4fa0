//! How long a run took: wall time, and the CPU time of the thread that ran it.
//!
//! The twin steps its physics on the thread that calls the run, so that thread's CPU time is the
//! run's cost whatever else the machine is doing; wall time is not, on a shared machine (a run
//! beside a build takes up to twice as long). Speed charts use the CPU time.

use std::time::Instant;

/// When a run began, on both clocks.
#[derive(Debug, Clone, Copy)]
pub struct RunClock {
    wall: Instant,
    thread_cpu_s: f64,
}

impl RunClock {
    /// Starts both clocks now, on the calling thread.
    pub fn start() -> RunClock {
        RunClock { wall: Instant::now(), thread_cpu_s: thread_cpu_time_s() }
    }

    /// Wall time since the start \[s\].
    pub fn wall_s(&self) -> f64 {
        self.wall.elapsed().as_secs_f64()
    }

    /// CPU time the calling thread used since the start \[s\] (call it on the thread that started
    /// the clock).
    pub fn thread_cpu_s(&self) -> f64 {
        (thread_cpu_time_s() - self.thread_cpu_s).max(0.0)
    }
}

/// CPU time the calling thread has used \[s\] (`CLOCK_THREAD_CPUTIME_ID`; 0 if the clock is not
/// available, so a speed is then reported as infinite rather than failing the run).
fn thread_cpu_time_s() -> f64 {
    let mut t = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: clock_gettime writes one timespec through a valid pointer to a local.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut t) };
    if rc == 0 { t.tv_sec as f64 + t.tv_nsec as f64 * 1e-9 } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thread_cpu_time_counts_work_and_not_sleep() {
        let clock = RunClock::start();
        std::thread::sleep(std::time::Duration::from_millis(50));
        let asleep = clock.thread_cpu_s();
        // A fixed amount of work (tens of milliseconds on any machine), not a fixed wall time: on
        // a loaded machine a wall-timed spin may get little CPU.
        let mut x = 0u64;
        for i in 0..50_000_000u64 {
            x = std::hint::black_box(x.wrapping_add(i));
        }
        let worked = clock.thread_cpu_s() - asleep;
        assert!(asleep < 0.005, "sleeping used {asleep} s of CPU");
        assert!(worked > 0.005, "the work used only {worked} s of CPU");
        assert!(clock.wall_s() >= 0.05);
    }
}
