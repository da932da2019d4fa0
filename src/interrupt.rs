//! Operator stops: SIGINT (Ctrl-C), SIGTERM and SIGHUP all ask for the same clean stop.
//!
//! [`install`] (called by the CLI, never by the library on its own) replaces the signals' default
//! action (die on the spot, the trace's last row torn, no `summary.json`, the arm not stopped) with a
//! flag: the control loop ([`crate::run::runner::run_task`]) checks it every tick and ends the run
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

/// Turns SIGINT, SIGTERM and SIGHUP into a stop request, on a small thread of its own. A second
/// signal of any kind after the first ends the process at once (exit `128 + signal`), for a stop
/// that does not come.
pub fn install() -> std::io::Result<()> {
    use tokio::signal::unix::{SignalKind, signal};
    let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build()?;
    // Registered here, before the thread starts, so no signal is missed after `install` returns.
    let mut streams = runtime.block_on(async {
        Ok::<_, std::io::Error>([
            (SIGINT, signal(SignalKind::interrupt())?),
            (SIGTERM, signal(SignalKind::terminate())?),
            (SIGHUP, signal(SignalKind::hangup())?),
        ])
    })?;
    std::thread::Builder::new().name("signals".into()).spawn(move || {
        runtime.block_on(async move {
            loop {
                let [(n1, s1), (n2, s2), (n3, s3)] = &mut streams;
                let n = tokio::select! {
                    _ = s1.recv() => *n1,
                    _ = s2.recv() => *n2,
                    _ = s3.recv() => *n3,
                };
                if let Some(first) = requested() {
                    eprintln!("tendril: {} again after {}: exiting now", name(n), name(first));
                    std::process::exit(i32::from(exit_code(n)));
                }
                eprintln!("tendril: {}: stopping cleanly (send it again to exit at once)", name(n));
                request(n);
            }
        });
    })?;
    Ok(())
}
