//! One scenario on the real cell (or the virtual devices): the same control loop as the twin,
//! behind [`LimitedCell`] over [`RealCell`]; writes the same `trace.csv` and `summary.json`
//! (`backend: "real"`).

use super::execute::run_on_cell;
use super::runner::RunReport;
use super::scenario::PickPlaceScenario;
use super::summary::RunSummary;
use std::path::Path;
use tendril_control::limits::{LimitedCell, SafetyLimits};
use tendril_drivers::{RealCell, RealCellConfig};

/// Runs `scenario` on the real cell. A device fault during the run is an `error` outcome (after a
/// clean stop); `Err` is for what prevents the run from starting (output folder not writable).
pub fn run_on_real(
    scenario: &PickPlaceScenario,
    config: RealCellConfig,
    out: Option<&Path>,
) -> anyhow::Result<(RunSummary, RunReport)> {
    // Disturbances are the twin's: refuse before any device is contacted.
    scenario.disturbance.refuse_on_real().map_err(|e| anyhow::anyhow!("{e}"))?;
    let started = super::clock::RunClock::start();
    let limits = SafetyLimits::for_task(&scenario.task.limits, &scenario.estimator);
    let mut cell = LimitedCell::new(RealCell::new(config), limits);
    run_on_cell(&mut cell, scenario, out, started)
}
