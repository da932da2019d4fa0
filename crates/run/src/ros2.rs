//! One scenario on a cell whose drivers are a lab's ROS 2 nodes (`--hardware ros2`): the same
//! control loop as on the twin and the device path, behind [`LimitedCell`] over
//! [`Ros2Cell`], with the same `trace.csv` and `summary.json` (`backend: "ros2"`).

use super::execute::{Driver, run_on_cell_with};
use super::runner::RunReport;
use super::scenario::PickPlaceScenario;
use super::summary::RunSummary;
use std::path::Path;
use tendril_control::limits::{LimitedCell, SafetyLimits};
use tendril_ros2::{Ros2Cell, Ros2CellConfig};

/// The cell configuration of `scenario`: its `[ros2]`, its control rate (the watchdogs) and its
/// sensor array's pads.
pub fn ros2_cell_config(scenario: &PickPlaceScenario) -> Ros2CellConfig {
    Ros2CellConfig::new(scenario.ros2.clone(), scenario.control_rate_hz, scenario.array.pads.len())
}

/// Runs `scenario` on the ROS 2 cell `config` describes. A fault during the run (a topic that
/// stops, a malformed message) is an `error` outcome after the safe stop; `Err` is for what
/// prevents the run from starting.
pub fn run_on_ros2(
    scenario: &PickPlaceScenario,
    config: Ros2CellConfig,
    out: Option<&Path>,
    driver: Driver<'_>,
) -> anyhow::Result<(RunSummary, RunReport)> {
    // Disturbances are the twin's: refuse before joining the graph.
    scenario.disturbance.refuse_on_real().map_err(|e| anyhow::anyhow!("{e}"))?;
    let started = super::clock::RunClock::start();
    let limits = SafetyLimits::for_task(&scenario.task.limits, &scenario.estimator, &scenario.gripper);
    let mut cell = LimitedCell::new(Ros2Cell::new(config), limits);
    run_on_cell_with(&mut cell, scenario, out, started, driver)
}
