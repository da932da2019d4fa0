//! Helpers shared by the integration tests that run the twin in real time.

/// These tests run the twin in real time behind live sockets and a pty; side by side on a 2-core
/// machine they would starve each other's deadlines, so they take turns.
static REAL_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// Holds the real-time turn until dropped.
pub fn one_at_a_time() -> std::sync::MutexGuard<'static, ()> {
    REAL_TIME.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}
