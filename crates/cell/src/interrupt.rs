//! Operator stops: SIGINT (Ctrl-C), SIGTERM and SIGHUP all ask for the same clean stop.
//!
//! The CLI's signal handler (`tendril`'s `install_signal_handlers`; the library never installs one on its own) replaces the signals' default
//! action (die on the spot, the trace's last row torn, no `summary.json`, the arm not stopped) with a
//! flag: the control loop (`tendril_run`'s run loop) checks it every tick and ends the run
//! through the cell's safe stop, so the trace's rows are whole and `summary.json` is written; a
//! sweep starts no new run and keeps every finished row; `serve` shuts its devices down.
//! The process then exits with `128 + signal` ([`exit_code`]).

use std::sync::atomic::{AtomicI32, Ordering};

/// The signal that asked for a stop, 0 while none has.
static REQUESTED: AtomicI32 = AtomicI32::new(0);

/// SIGHUP's number on Linux (the terminal went away).
pub const SIGHUP: i32 = 1;
/// SIGINT's number (Ctrl-C).
pub const SIGINT: i32 = 2;
/// SIGTERM's number (`kill`, a scheduler's job end).
pub const SIGTERM: i32 = 15;

/// The signal that asked for a stop, if one has.
pub fn requested() -> Option<i32> {
    match REQUESTED.load(Ordering::SeqCst) {
        0 => None,
        n => Some(n),
    }
}

/// Records a stop request as if signal `signal` had arrived (for tests and for in-process stops).
pub fn request(signal: i32) {
    let _ = REQUESTED.compare_exchange(0, signal, Ordering::SeqCst, Ordering::SeqCst);
}

/// The name of a signal number, for messages.
pub fn name(signal: i32) -> &'static str {
    match signal {
        SIGHUP => "SIGHUP",
        SIGINT => "SIGINT (Ctrl-C)",
        SIGTERM => "SIGTERM",
        _ => "a signal",
    }
}

/// The exit code of a process stopped by `signal`: `128 + signal`, as a shell reports a process
/// killed by it (130 Ctrl-C, 143 SIGTERM, 129 SIGHUP), though here after a clean stop.
pub fn exit_code(signal: i32) -> u8 {
    u8::try_from(128 + signal).unwrap_or(1)
}
