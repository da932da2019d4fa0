//! Helpers shared by the integration tests: the binary as a user calls it ([`cli`]), and the
//! real-time tests' turn-taking, scenario and phase comparison.
// Each test crate compiles this module for the helpers it needs; the others would warn as unused.
#![allow(dead_code)]

pub mod cli;
pub mod phases;
pub mod table;

use tendril_run::scenario::PickPlaceScenario;

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
    let overrides: Vec<tendril_config::Override> = overrides.iter().map(|o| o.parse().unwrap()).collect();
    tendril_config::load(&path, &overrides).unwrap()
}
