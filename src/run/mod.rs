//! Running the pick-and-place task on a cell and recording it.
//!
//! - [`runner`]: the control loop over any [`crate::hardware::Cell`].
//! - [`trace`]: `trace.csv`, one row per tick.
//! - [`metrics`]: rise time, overshoot, fluctuation, estimate error.
//! - [`summary`]: the `summary.json` record.

pub mod metrics;
pub mod runner;
pub mod summary;
pub mod trace;
