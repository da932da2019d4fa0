//! URScript: the program the real path sends to the controller's secondary interface (TCP 30002),
//! and the interpreter the virtual UR5e (`tendril serve`) runs programs with.
//!
//! The interpreter, sans-IO (the arm and the RTDE registers come through
//! [`interp::Controller`]): [`lexer`] → [`parser`] ([`ast`]) → [`compile`] (a stack code a thread
//! can stop in at any wait) → [`interp`] (threads in the controller's 2 ms cycle), with
//! [`value`] (types and arithmetic), [`builtins`] and [`motion`] (the setpoint generator).
//!
//! Our program, `urscript/follow.script`, runs through that interpreter like any other.
//! What it does:
//!
//! The program (`urscript/follow.script`, written by this project) loops forever:
//! - `input_int_register_24` = 1: read the six joint targets from `input_double_register_24..29`
//!   \[rad\] and their time on the client's clock from `input_double_register_30` \[s\] (a new
//!   time is a new target), and `servoj` every 2 ms controller cycle to the targets played back at
//!   their own times: on the controller's clock, `delay` (30 ms) behind the earliest any target
//!   arrived (the smallest controller-minus-client time seen; when no target came as early for a
//!   second it forgets at 1 ms/s, so the two clocks may drift apart), interpolated between the two targets around the playback time (eight kept).
//!   A target that arrives up to `delay` less one client tick late (20 ms at 100 Hz), or bunched
//!   with others, moves the arm exactly as one on time would. Past the newest target the playback
//!   goes on along the last two for at most 0.1 s (a client's watchdog stops sooner), then holds.
//!   `output_int_register_24` = 1.
//! - anything else: `stopj(2.0)` (2 rad/s² deceleration), `output_int_register_24` = 0; the next
//!   enabled target starts the playback afresh.
//!
//! Why stamped targets: the program before played each new target over as many cycles as the one
//! before took to arrive. On an ordinary PC a package is now and then several milliseconds late and
//! the next follows at once; that stretched one target over too many cycles and squeezed the next
//! into too few, and the arm's speed jumped. Against the virtual devices with 5-20 ms stalls twice
//! a second on the RTDE inputs alone (`--jitter busy-pc`), the lift's force estimate fell to
//! 0.17 N at its 5th percentile (the twin: 0.54 N) while the other links' jitter changed nothing;
//! docs/hardware.md, "Timing on an ordinary PC".
//!
//! From the first enabled target on, `rtde_set_watchdog("input_int_register_24", 2, "stop")`
//! (URScript manual: `rtde_set_watchdog(variable_name, min_frequency, action="pause")`, actions
//! "ignore", "pause", "stop") makes the controller stop the program, and so the arm, when the
//! client writes no package with the enable register for more than 0.5 s (it writes one every
//! control tick, about 100 Hz). Armed only once enabled, because our client uploads the program
//! at configure and streams targets only from the first tick on. Why 2 Hz and not faster: the
//! client's own watchdogs stop a run on a stream stalled for 0.1 s already (`RealCell`), so this one is only the
//! backstop for a client that died (it plays the targets it has, then holds), and a stalled shared
//! machine (400 ms seen) would turn a 10 Hz watchdog into stopped runs.
//!
//! Registers 24..30 leave 0..23 free for SDU's `ur_rtde`, whose control script uses the lower half.
//! The client writes the targets, their time and the enable flag in one RTDE input recipe, so they
//! always arrive together; speed and acceleration limits are applied before (see
//! [`crate::cell::real::limits`]). The controller's own safety limits still apply on top.

pub mod ast;
pub mod builtins;
pub mod compile;
pub mod interp;
pub mod lexer;
pub mod motion;
pub mod parser;
pub mod value;

pub use interp::{Controller, DigitalOut, Interpreter, Status};

/// An error in a program: where and what. Line 0 means no single line (a motion that fails
/// between calls, such as a `movel` through an unreachable pose).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ScriptError {
    /// Line number, 1-based (0: not tied to a line).
    pub line: u32,
    /// What is wrong.
    pub message: String,
}

impl std::fmt::Display for ScriptError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.line > 0 { write!(f, "line {}: {}", self.line, self.message) } else { write!(f, "{}", self.message) }
    }
}

impl std::error::Error for ScriptError {}

/// The program text (newline-terminated `def ... end`, as the secondary interface expects).
pub const FOLLOW_SCRIPT: &str = include_str!("urscript/follow.script");

/// First input double register holding a joint target (six consecutive registers).
pub const TARGET_REGISTER: usize = 24;
/// Input double register holding the target's time on the client's clock \[s\].
pub const STAMP_REGISTER: usize = 30;
/// Input int register holding the enable flag (1 follow, 0 stop).
pub const ENABLE_REGISTER: usize = 24;
/// Output int register the program sets to 1 while following.
pub const FOLLOWING_REGISTER: usize = 24;

/// RTDE input names in recipe order: six targets, their time, then the enable flag.
pub fn input_names() -> Vec<String> {
    let mut names: Vec<String> = (0..6).map(|i| format!("input_double_register_{}", TARGET_REGISTER + i)).collect();
    names.push(format!("input_double_register_{STAMP_REGISTER}"));
    names.push(format!("input_int_register_{ENABLE_REGISTER}"));
    names
}

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

/// Whether `text` looks like a complete program: a `def name():` line and a final `end`.
pub fn is_complete_program(text: &str) -> bool {
    let lines: Vec<&str> = text.lines().map(str::trim).filter(|l| !l.is_empty() && !l.starts_with('#')).collect();
    lines.first().is_some_and(|l| l.starts_with("def ") && l.ends_with("):")) && lines.last() == Some(&"end")
}

#[cfg(test)]
mod tests;
