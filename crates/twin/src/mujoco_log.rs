//! MuJoCo's messages into our own log and summaries.
//!
//! MuJoCo's default handler appends warnings to `MUJOCO_LOG.TXT` in the working directory (and
//! prints them). [`install`] replaces it, through mujoco-rs's log handler (the structured successor
//! of `mju_user_warning`), with [`handle`]: a warning is printed to standard error as
//! `tendril: MuJoCo warning: …` and kept for the run on the thread that raised it, which
//! [`take_warnings`] hands to that run's `summary.json` (a sweep's runs each step MuJoCo on their
//! own worker thread, so each gets its own). Info and debug messages are dropped; an error is
//! printed and ends the process (MuJoCo cannot continue after one).

use mujoco_rs::prelude::{MjLogMessage, MjtLogLevel};
use std::cell::RefCell;

/// Most warnings kept per run: a diverging run can warn every step; the first ones say why.
pub const MAX_KEPT: usize = 20;

thread_local! {
    static WARNINGS: RefCell<Vec<String>> = const { RefCell::new(Vec::new()) };
}

/// Routes MuJoCo's messages to [`handle`] (the CLI calls it first thing).
///
/// # Safety
/// No other thread may use MuJoCo while this runs: the handler is process-wide state that MuJoCo
/// reads without synchronisation. Call it at the start of the program.
pub unsafe fn install() {
    // SAFETY: the caller guarantees that no other thread uses MuJoCo yet.
    unsafe { mujoco_rs::logging::set_log_handler(handle) };
}

/// The handler: warnings and errors to standard error, warnings also kept for the run.
pub fn handle(message: &MjLogMessage) {
    let level = message.level();
    if level != MjtLogLevel::mjLOG_WARNING && level != MjtLogLevel::mjLOG_ERROR {
        return;
    }
    let text = message.subject().trim().to_string();
    let kind = if level == MjtLogLevel::mjLOG_ERROR { "error" } else { "warning" };
    eprintln!("tendril: MuJoCo {kind}: {text}");
    WARNINGS.with(|w| {
        let mut w = w.borrow_mut();
        if w.len() < MAX_KEPT {
            w.push(text);
        }
    });
}

/// The warnings raised on this thread since the last call, oldest first.
pub fn take_warnings() -> Vec<String> {
    WARNINGS.with(|w| std::mem::take(&mut *w.borrow_mut()))
}
