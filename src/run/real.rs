//! One scenario on the real cell (or the virtual devices): the same control loop as the twin,
//! behind [`LimitedCell`] over [`RealCell`]; writes the same `trace.csv` and `summary.json`
//! (`backend: "real"`).

use super::runner::{RunReport, run_task};
use super::scenario::PickPlaceScenario;
use super::summary::{Gains, RunIdentity, RunSummary};
use super::trace::TraceWriter;
use crate::cell::real::{LimitedCell, RealCell, RealCellConfig, SafetyLimits};
use std::path::Path;

/// Runs `scenario` on the real cell. A device fault during the run is an `error` outcome (after a
/// clean stop); `Err` is for what prevents the run from starting (output folder not writable).
pub fn run_on_real(
    scenario: &PickPlaceScenario,
    config: RealCellConfig,
    out: Option<&Path>,
) -> anyhow::Result<(RunSummary, RunReport)> {
    let started = std::time::Instant::now();
    let limits = SafetyLimits::for_task(&scenario.task.limits, &scenario.estimator);
    let mut cell = LimitedCell::new(RealCell::new(config), limits);
    let mut trace = match out {
        Some(dir) => {
            std::fs::create_dir_all(dir).map_err(|e| anyhow::anyhow!("{}: cannot create: {e}", dir.display()))?;
            let path = dir.join("trace.csv");
            Some(TraceWriter::create(&path).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?)
        }
        None => None,
    };
    let report = run_task(&mut cell, &scenario.control_plan(), trace.as_mut());
    let identity = RunIdentity {
        scenario: scenario.name.clone(),
        object: format!("{:?}", scenario.object.name).to_lowercase(),
        mass_kg: scenario.object.name.paper_mass_kg(),
        feedback: scenario.feedback,
        gains: Gains { kp: scenario.controller.kp, ki: scenario.controller.ki, kd: scenario.controller.kd },
        setpoint_n: scenario.setpoint_n,
        seed: scenario.seed,
        backend: "real".into(),
    };
    let summary = RunSummary::new(identity, &report, started.elapsed().as_secs_f64());
    if let Some(dir) = out {
        let path = dir.join("summary.json");
        std::fs::write(&path, serde_json::to_string_pretty(&summary)? + "\n")
            .map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", path.display()))?;
    }
    Ok((summary, report))
}
