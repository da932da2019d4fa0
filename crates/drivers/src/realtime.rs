//! Real-time set-up of a control thread, and a precise wait for its tick deadlines.
//!
//! What a robot driver's control thread usually asks of Linux (ur_rtde and ros2_control do the
//! same): `SCHED_FIFO` priority so other processes cannot delay it, optionally one CPU of its own,
//! all memory locked so no page fault stalls a tick, and a 1 ns timer slack so sleeps end on time
//! (the default slack of an ordinary thread is 50 µs). [`sleep_until`] then sleeps to just before
//! a deadline and spins the rest of the way: waking from a sleep takes tens of microseconds, more
//! on a busy machine, spinning a fraction of that.

use std::time::{Duration, Instant};

/// How long before a deadline [`sleep_until`] stops sleeping and spins. 150 µs covers the usual
/// wake-up delay of a sleeping thread (timer, scheduler, cache) with room to spare, at the cost
/// of 7.5 % of a core at 500 Hz.
pub const SPIN_BEFORE_DEADLINE: Duration = Duration::from_micros(150);

/// Why the real-time set-up failed.
#[derive(Debug, thiserror::Error)]
pub enum RealtimeError {
    /// `sched_setscheduler(SCHED_FIFO)` refused (needs root or CAP_SYS_NICE) or the priority is
    /// outside 1-99.
    #[error("SCHED_FIFO priority {priority}: {source}")]
    Priority {
        /// The priority asked for.
        priority: i32,
        /// The system's answer.
        source: std::io::Error,
    },
    /// The CPU does not exist or is not available to this process.
    #[error("pinning to CPU {cpu}: {source}")]
    Affinity {
        /// The CPU asked for.
        cpu: usize,
        /// The system's answer.
        source: std::io::Error,
    },
    /// `mlockall` refused (memory lock limit, `ulimit -l`).
    #[error("locking memory: {0}")]
    LockMemory(std::io::Error),
}

/// Scheduling of a control thread; the default changes nothing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct RealtimeOptions {
    /// `SCHED_FIFO` priority 1-99 (0: normal scheduling).
    pub priority: i32,
    /// Run only on this CPU.
    pub cpu: Option<usize>,
    /// Lock all current and future memory of the process (`mlockall`).
    pub lock_memory: bool,
}

impl RealtimeOptions {
    /// Applies the options to the calling thread (threads it starts afterwards inherit priority
    /// and CPU), and sets its timer slack to 1 ns whatever the options.
    pub fn apply_to_current_thread(&self) -> Result<(), RealtimeError> {
        set_timer_slack_ns(1);
        if self.lock_memory {
            lock_memory()?;
        }
        if let Some(cpu) = self.cpu {
            pin_to_cpu(cpu)?;
        }
        if self.priority > 0 {
            set_realtime_priority(self.priority)?;
        }
        Ok(())
    }
}

/// Puts the calling thread under `SCHED_FIFO` at `priority` (1-99). Needs CAP_SYS_NICE or root.
pub fn set_realtime_priority(priority: i32) -> Result<(), RealtimeError> {
    let param = libc::sched_param { sched_priority: priority };
    // SAFETY: plain syscall on the calling thread with a valid parameter struct.
    let rc = unsafe { libc::sched_setscheduler(0, libc::SCHED_FIFO, &param) };
    if rc == 0 { Ok(()) } else { Err(RealtimeError::Priority { priority, source: std::io::Error::last_os_error() }) }
}

/// Restricts the calling thread to `cpu`.
pub fn pin_to_cpu(cpu: usize) -> Result<(), RealtimeError> {
    let fail = |source| RealtimeError::Affinity { cpu, source };
    if cpu >= libc::CPU_SETSIZE as usize {
        return Err(fail(std::io::Error::from(std::io::ErrorKind::InvalidInput)));
    }
    // SAFETY: the set is a plain bit mask, zeroed, with one in-range bit set; the syscall reads it.
    let rc = unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        libc::CPU_SET(cpu, &mut set);
        libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &set)
    };
    if rc == 0 { Ok(()) } else { Err(fail(std::io::Error::last_os_error())) }
}

/// Locks all current and future pages of the process in memory.
pub fn lock_memory() -> Result<(), RealtimeError> {
    // SAFETY: plain syscall with constant flags.
    let rc = unsafe { libc::mlockall(libc::MCL_CURRENT | libc::MCL_FUTURE) };
    if rc == 0 { Ok(()) } else { Err(RealtimeError::LockMemory(std::io::Error::last_os_error())) }
}

/// Sets the calling thread's timer slack; best effort (a failure only makes sleeps less exact).
pub fn set_timer_slack_ns(ns: u64) {
    // SAFETY: prctl with an integer argument; no memory is passed.
    unsafe {
        libc::prctl(libc::PR_SET_TIMERSLACK, ns as libc::c_ulong, 0, 0, 0);
    }
}

/// Waits until `deadline`: sleeps until [`SPIN_BEFORE_DEADLINE`] before it, then spins.
pub fn sleep_until(deadline: Instant) {
    let now = Instant::now();
    if deadline <= now {
        return;
    }
    if let Some(sleep) = (deadline - now).checked_sub(SPIN_BEFORE_DEADLINE) {
        std::thread::sleep(sleep);
    }
    while Instant::now() < deadline {
        std::hint::spin_loop();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sleep_until_never_returns_early() {
        set_timer_slack_ns(1);
        for us in [0, 50, 400, 2000] {
            let deadline = Instant::now() + Duration::from_micros(us);
            sleep_until(deadline);
            assert!(Instant::now() >= deadline);
        }
    }

    #[test]
    fn a_cpu_that_does_not_exist_is_an_error() {
        let err = pin_to_cpu(usize::MAX).unwrap_err();
        assert!(err.to_string().contains("CPU"), "{err}");
    }
}
