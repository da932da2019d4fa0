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
//!   \[rad\] and `servoj` towards them every 2 ms controller cycle, `output_int_register_24` = 1.
//!   A new target is reached in even steps over as many cycles as the one before took to arrive
//!   (the client's tick, about 5 cycles), so `servoj` sees a new setpoint every cycle rather than a
//!   step every fifth one; the cost is one client tick of lag;
//! - anything else: `stopj(2.0)` (2 rad/s² deceleration), `output_int_register_24` = 0.
//!
//! From the first enabled target on, `rtde_set_watchdog("input_int_register_24", 2, "stop")`
//! (URScript manual: `rtde_set_watchdog(variable_name, min_frequency, action="pause")`, actions
//! "ignore", "pause", "stop") makes the controller stop the program, and so the arm, when the
//! client writes no package with the enable register for more than 0.5 s (it writes one every
//! control tick, about 100 Hz). Armed only once enabled, because our client uploads the program
//! at configure and streams targets only from the first tick on. Why 2 Hz and not faster: the
//! client's own watchdogs stop a run on a 10 ms stall already (`RealCell`), so this one is only the
//! backstop for a client that died, whose last target is at most one tick's step ahead of the arm;
//! and the real-time tests tolerate 400 ms stalls of a shared machine (`LOOSE_WATCHDOG_S`), which a
//! 10 Hz watchdog would turn into stopped runs.
//!
//! Registers 24..29 leave 0..23 free for SDU's `ur_rtde`, whose control script uses the lower half.
//! The client writes the targets and the enable flag in one RTDE input recipe, so a target and its
//! enable always arrive together; speed and acceleration limits are applied before (see
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
/// Input int register holding the enable flag (1 follow, 0 stop).
pub const ENABLE_REGISTER: usize = 24;
/// Output int register the program sets to 1 while following.
pub const FOLLOWING_REGISTER: usize = 24;

/// RTDE input names in recipe order: six targets, then the enable flag.
pub fn input_names() -> Vec<String> {
    let mut names: Vec<String> = (0..6).map(|i| format!("input_double_register_{}", TARGET_REGISTER + i)).collect();
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
