//! How old a topic's latest message may be before a cell over ROS 2 stops: the device path's rule
//! (`tendril_drivers::Watchdog`, docs/cell/timing.md#watchdogs) with the topics' own periods.

use tendril_cell::BLIND_TICKS;

/// The limits \[s\] of a cell ticking every `control_period_s` on topics published every
/// `topic_period_s`: the loop may run [`BLIND_TICKS`] ticks on held values, and a fresh message is
/// up to one of its topic's periods old when a tick reads it. At 100 Hz on 100 Hz topics, 0.11 s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TopicWatchdog {
    /// Joint states (arm and motors) \[s\].
    pub joints_stale_s: f64,
    /// FBG peaks \[s\].
    pub peaks_stale_s: f64,
    /// With `use_sim_time`, how long (wall clock) a tick may wait for the clock to reach its time
    /// before the cell stops \[s\]: 5 s, so that a lock-step twin on a loaded machine (a tick takes
    /// under a millisecond there) is never mistaken for a stopped one, while a commander whose
    /// twin is gone learns it within seconds.
    pub sim_clock_wait_s: f64,
}

impl TopicWatchdog {
    /// The limits for a loop ticking every `control_period_s` on topics every `topic_period_s`.
    pub fn for_control(control_period_s: f64, topic_period_s: f64) -> TopicWatchdog {
        let stale_s = f64::from(BLIND_TICKS) * control_period_s + topic_period_s;
        TopicWatchdog { joints_stale_s: stale_s, peaks_stale_s: stale_s, sim_clock_wait_s: 5.0 }
    }
}
