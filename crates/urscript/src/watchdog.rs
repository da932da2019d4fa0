//! `rtde_set_watchdog`: what a program asks the controller to watch, and what it does then.

/// What the controller does when a watched RTDE input is not updated in time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WatchdogAction {
    /// Nothing.
    Ignore,
    /// Pause the program (the arm stops; the program can be resumed).
    Pause,
    /// Stop the program (the arm stops).
    Stop,
}

/// An `rtde_set_watchdog(variable_name, min_frequency, action)` call found in a program.
#[derive(Debug, Clone, PartialEq)]
pub struct RtdeWatchdog {
    /// The RTDE input watched, e.g. `input_int_register_24`.
    pub variable: String,
    /// Lowest update rate accepted \[Hz\]: the timeout is its inverse.
    pub min_frequency_hz: f64,
    /// What happens on a timeout.
    pub action: WatchdogAction,
}
