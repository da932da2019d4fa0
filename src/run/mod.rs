//! Running the pick-and-place task on a cell and recording it.
//!
//! - [`clock`]: a run's wall and CPU time.
//! - [`drop_watch`]: when a simulated object counts as dropped.
//! - [`execute`]: one scenario on the twin, files written.
//! - [`runner`]: the control loop over any [`crate::hardware::Cell`].
//! - [`scenario`]: the pick-and-place scenario file.
//! - [`trace`]: `trace.csv`, one row per tick.
//! - [`output`]: the default output folder derived from a scenario's name.
//! - [`metrics`]: rise time, overshoot, fluctuation, estimate error.
//! - [`summary`]: the `summary.json` record.
//! - [`compare`]: two runs of a scenario, phase by phase (the real path against the twin).

pub mod clock;
pub mod compare;
pub mod drop_watch;
pub mod execute;
pub mod metrics;
pub mod output;
pub mod real;
pub mod runner;
pub mod scenario;
pub mod summary;
pub mod trace;
