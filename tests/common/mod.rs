//! Helpers shared by the integration tests: the binary as a user calls it ([`cli`]), and the
//! real-time tests' turn-taking, scenario and phase comparison.
// Each test crate compiles this module for the helpers it needs; the others would warn as unused.
#![allow(dead_code)]

pub mod cli;
pub mod phases;

use tendril::run::scenario::PickPlaceScenario;

/// These tests run the twin in real time behind live sockets and a pty; side by side on a 2-core
/// machine they would starve each other's deadlines, so they take turns.
static REAL_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// Holds the real-time turn until dropped.
pub fn one_at_a_time() -> std::sync::MutexGuard<'static, ()> {
    REAL_TIME.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// The short grasp-hold-lift scenario the real-time tests run (about 15 s of cell time).
pub const SHORT_LIFT: &str = "scenarios/short-lift.toml";

/// [`SHORT_LIFT`], loaded with `overrides` (`key=value`, as `--set` takes them).
pub fn short_lift(overrides: &[&str]) -> PickPlaceScenario {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(SHORT_LIFT);
    let overrides: Vec<tendril::scenario::Override> = overrides.iter().map(|o| o.parse().unwrap()).collect();
    tendril::scenario::load(&path, &overrides).unwrap()
}

/// Watchdog [s] for the real-time tests that do not test the watchdog: a shared virtual machine
/// sometimes does not run a process for tens of milliseconds (60 ms seen), and with both cores
/// busy a reply over the virtual bus's pty took over 50 ms; a run's watchdogs (5 ms, 10 ms, 50 ms)
/// would rightly stop on either, and under a parallel build a motor reply was once 250 ms late.
/// These tests are about agreement, not timing. Below the follow program's 0.5 s RTDE watchdog.
pub const LOOSE_WATCHDOG_S: f64 = 0.4;

/// Loosens `config`'s watchdogs and the motors' reply timeout to [`LOOSE_WATCHDOG_S`].
pub fn loose_watchdog(config: &mut tendril::cell::real::RealCellConfig) {
    config.sensor_stale_samples = LOOSE_WATCHDOG_S / config.sensor_period_s;
    config.arm_stale_s = LOOSE_WATCHDOG_S;
    config.dxl_reply_timeout = std::time::Duration::from_secs_f64(LOOSE_WATCHDOG_S);
}
