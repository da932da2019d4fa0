//! One scenario, start to finish, on the twin: build (or reuse) the scene model, run the task,
//! write `trace.csv` and `summary.json`.

use super::runner::{RunReport, run_task};
use super::scenario::PickPlaceScenario;
use super::summary::{Gains, RunIdentity, RunSummary};
use super::trace::TraceWriter;
use crate::cell::physics::{SceneModel, SceneSpec};
use crate::cell::sim::SimCell;
use std::path::Path;
use std::sync::{Arc, Mutex};

/// Compiled scene models, shared between runs whose scenes are identical (a gain sweep
/// compiles the model once per object). `MjModel` is `Send + Sync`; each run has its own data.
#[derive(Default)]
pub struct ModelCache {
    models: Mutex<Vec<(SceneSpec, Arc<SceneModel>)>>,
}

impl ModelCache {
    /// The model for `spec`, compiled on first use.
    pub fn get(&self, spec: &SceneSpec) -> anyhow::Result<Arc<SceneModel>> {
        let mut models = self.models.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        if let Some((_, m)) = models.iter().find(|(s, _)| s == spec) {
            return Ok(m.clone());
        }
        let model = SceneModel::build(spec)?;
        models.push((spec.clone(), model.clone()));
        Ok(model)
    }
}

/// Runs `scenario` on the twin. With `out`, writes `trace.csv` (streamed, kept on failure) and
/// `summary.json` there. A physics failure is an `error` outcome in the summary, not an `Err`;
/// `Err` is for what prevents the run from starting (scene does not compile, folder not writable).
pub fn run_on_twin(
    scenario: &PickPlaceScenario,
    models: &ModelCache,
    out: Option<&Path>,
) -> anyhow::Result<(RunSummary, RunReport)> {
    let started = std::time::Instant::now();
    let model = models.get(&scenario.scene_spec())?;
    let mut cell = SimCell::new(
        model,
        scenario.sensor.clone(),
        scenario.interrogator.clone(),
        scenario.gripper,
        scenario.environment,
        scenario.seed,
    );
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
        object: scenario.object.name.to_string(),
        mass_kg: scenario.object.name.paper_mass_kg(),
        feedback: scenario.feedback,
        gains: Gains { kp: scenario.controller.kp, ki: scenario.controller.ki, kd: scenario.controller.kd },
        setpoint_n: scenario.setpoint_n,
        seed: scenario.seed,
        backend: "mujoco".into(),
    };
    let summary = RunSummary::new(identity, &report, started.elapsed().as_secs_f64());
    if let Some(dir) = out {
        let path = dir.join("summary.json");
        std::fs::write(&path, serde_json::to_string_pretty(&summary)? + "\n")
            .map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", path.display()))?;
    }
    Ok((summary, report))
}
