//! Scheduling options of the time-critical threads: the control thread of `tendril run --hardware
//! real` and `tendril latency`, the virtual devices' threads of `tendril serve`.

use tendril_drivers::realtime::RealtimeOptions;

/// How the time-critical threads are scheduled (default: as any other thread).
#[derive(Debug, Clone, clap::Args)]
pub struct RealtimeArgs {
    /// Run the time-critical threads (the control loop; for `serve`, the twin, bus and network)
    /// under SCHED_FIFO at this priority (1-99; needs root or CAP_SYS_NICE); 0: normal scheduling.
    #[arg(long, default_value_t = 0)]
    rt_priority: i32,
    /// Run those threads on this CPU only (0-based).
    #[arg(long)]
    cpu: Option<usize>,
    /// Lock the process's memory (mlockall) so no page fault delays a tick.
    #[arg(long)]
    mlock: bool,
}

impl RealtimeArgs {
    /// The options, checked.
    pub fn options(&self) -> anyhow::Result<RealtimeOptions> {
        anyhow::ensure!((0..=99).contains(&self.rt_priority), "--rt-priority must be 0-99, got {}", self.rt_priority);
        Ok(RealtimeOptions { priority: self.rt_priority, cpu: self.cpu, lock_memory: self.mlock })
    }
}
