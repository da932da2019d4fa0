//! One scenario, start to finish, on the twin: build (or reuse) the scene model, run the task,
//! write `trace.csv`, `summary.json` and `frames.bin`.

use super::bag::RunBag;
use super::runner::RunReport;
use super::scenario::PickPlaceScenario;
use super::session::{Action, Session};
use super::summary::RunSummary;
use super::trace::TraceWriter;
use std::path::Path;
use std::sync::{Arc, Mutex};
use tendril_cell::{Cell, CellError};
use tendril_control::controller::ForceController;
use tendril_twin::physics::{SceneModel, SceneSpec};

/// What drives a run besides its scenario ([`run_on_twin_with`]); the default is what
/// `tendril run` does: the scenario's own controller, every tick to the end.
#[derive(Default)]
pub struct Driver<'a> {
    /// The force controller (`None`: the one the scenario's `[controller]` describes).
    pub controller: Option<Box<dyn ForceController>>,
    /// Asked after every tick; an error it returns ends the run with that error (the cell
    /// deactivated, the outcome `error`): how a controller that cannot fail through
    /// [`ForceController::update`] reports that it did.
    pub check: Option<&'a mut (dyn FnMut() -> Option<CellError> + Send)>,
    /// Also record the run as a rosbag2 bag in its directory's `bag/` (`--bag`; refused when one
    /// is there already).
    pub bag: bool,
}

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

/// Runs `scenario` on the twin. With `out`, writes `trace.csv` (streamed, kept on failure),
/// `summary.json`, `scenario.toml` and `frames.bin` (the scene's state in MuJoCo's layout at
/// 30 frames/s of cell time, for `tendril render`) there. A physics failure is an `error` outcome
/// in the summary, not an `Err`; `Err` is for what prevents the run from starting (scene does not
/// compile, folder not writable).
pub fn run_on_twin(
    scenario: &PickPlaceScenario,
    models: &ModelCache,
    out: Option<&Path>,
) -> anyhow::Result<(RunSummary, RunReport)> {
    run_on_twin_with(scenario, models, out, Driver::default())
}

/// As [`run_on_twin`], driven by `driver` (a force controller defined outside the workspace, a
/// check between ticks).
pub fn run_on_twin_with(
    scenario: &PickPlaceScenario,
    models: &ModelCache,
    out: Option<&Path>,
    driver: Driver<'_>,
) -> anyhow::Result<(RunSummary, RunReport)> {
    let started = super::clock::RunClock::start();
    // Warnings left on this thread by an earlier run are not this run's.
    let _ = tendril_twin::mujoco_log::take_warnings();
    let mut cell = scenario.sim_cell(models.get(&scenario.scene_spec())?);
    if out.is_some() {
        cell.record_frames(tendril_twin::frames::RECORD_FPS);
    }
    let result = run_on_cell_with(&mut cell, scenario, out, started, driver);
    // The frames too when the run failed to write a file: they show what happened.
    if let (Some(dir), Some(frames)) = (out, cell.take_frames())
        && let Err(e) = frames.write(&dir.join(tendril_twin::frames::FRAMES_FILE))
    {
        return Err(match result {
            Ok(_) => anyhow::anyhow!("{e}: cannot write"),
            Err(first) => anyhow::anyhow!("{first:#}; {e}: cannot write"),
        });
    }
    result
}

/// Runs `scenario` on any cell, writing `trace.csv` and `summary.json` into `out` when given;
/// the summary names the cell's backend. `started` is when the run's set-up began (its wall and CPU
/// time count from there).
pub fn run_on_cell(
    cell: &mut dyn Cell,
    scenario: &PickPlaceScenario,
    out: Option<&Path>,
    started: super::clock::RunClock,
) -> anyhow::Result<(RunSummary, RunReport)> {
    run_on_cell_with(cell, scenario, out, started, Driver::default())
}

/// As [`run_on_cell`], driven by `driver`.
pub fn run_on_cell_with(
    cell: &mut dyn Cell,
    scenario: &PickPlaceScenario,
    out: Option<&Path>,
    started: super::clock::RunClock,
    driver: Driver<'_>,
) -> anyhow::Result<(RunSummary, RunReport)> {
    if let Some(dir) = out {
        std::fs::create_dir_all(dir).map_err(|e| anyhow::anyhow!("{}: cannot create: {e}", dir.display()))?;
    }
    // The bag first: a bag already there refuses the run before any file is written over.
    let bag = match (driver.bag, out) {
        (true, Some(dir)) => Some(RunBag::create(dir, &scenario.ros2, &scenario.array)?),
        (true, None) => anyhow::bail!("a bag is written into the run's directory: give the run one"),
        (false, _) => None,
    };
    let trace = match out {
        Some(dir) => {
            // Frames of an earlier run in this folder are not this run's (a run on the real cell
            // records none; a twin run writes its own after the run).
            let _ = std::fs::remove_file(dir.join(tendril_twin::frames::FRAMES_FILE));
            let path = dir.join("trace.csv");
            Some(TraceWriter::create(&path).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?)
        }
        None => None,
    };
    let plan = scenario.control_plan();
    let Driver { controller, mut check, .. } = driver;
    let controller = controller.unwrap_or_else(|| plan.controller.build());
    let mut session = Session::start(&mut *cell, &plan, controller, trace);
    if let Some(bag) = bag {
        session.record_bag(bag);
    }
    match check.as_mut() {
        None => session.run_to_end(),
        Some(check) => {
            while session.step(Action::Controller).is_some() {
                if let Some(e) = check() {
                    session.abort(e);
                    break;
                }
            }
        }
    }
    let (mut report, trace) = session.finish();
    let summary = summarize(scenario, cell.backend(), &mut report, started);
    if let Some(dir) = out {
        // Every file is attempted, and every failure is reported: a trace that could not be
        // written is an error even when summary.json could be.
        let mut failures = Vec::new();
        if let Some(e) = trace.as_ref().and_then(TraceWriter::error) {
            failures.push(format!("{}: cannot write: {e}", dir.join("trace.csv").display()));
        }
        if let Err(e) = write_summary(dir, &summary, scenario) {
            failures.push(format!("{e:#}"));
        }
        if !failures.is_empty() {
            anyhow::bail!("{}", failures.join("; "));
        }
    }
    Ok((summary, report))
}

/// The summary of a finished run of `scenario` on the cell named `backend` (`"mujoco"`, ...), with
/// the push's metric narrowed when the scenario has one and MuJoCo's warnings on this thread;
/// `started` is when the run's set-up began. Call it on the thread that ran the run.
pub fn summarize(
    scenario: &PickPlaceScenario,
    backend: &str,
    report: &mut RunReport,
    started: super::clock::RunClock,
) -> RunSummary {
    if let Some(push) = &scenario.disturbance.push {
        let drop_time_s = report.drop.map(|d| d.cell_time_s);
        report.metrics.max_fluctuation_outside_push_pct =
            super::metrics::fluctuation_outside_push_pct(&report.rows, drop_time_s, push);
    }
    let mut summary = RunSummary::new(scenario.identity(backend), report, started.wall_s(), started.thread_cpu_s());
    if scenario.task.settled_grasp.enabled {
        summary.grasp_duration_s = report.grasp.map(|g| g.duration_s);
    }
    summary.detection = scenario.detection();
    // The run's own thread stepped its physics (and compiled its model, if not cached).
    summary.warnings = tendril_twin::mujoco_log::take_warnings();
    summary
}

/// Writes `summary.json` with the effective scenario under `"effective_scenario"` (every key after the
/// defaults, the file and the `--set` overrides: what tools read to know the timestep, links,
/// gains... a run used), and that scenario again as `scenario.toml`, which `tendril run` takes
/// as it is to repeat the run from its own directory.
pub fn write_summary(dir: &Path, summary: &RunSummary, scenario: &PickPlaceScenario) -> anyhow::Result<()> {
    // Atomically: a failed write (a full disk) keeps the previous file whole.
    let write = |path: &Path, text: &str| {
        tendril_config::write_atomically(path, text.as_bytes())
            .map_err(|(file, e)| anyhow::anyhow!("{}: cannot write: {e}", file.display()))
    };
    write(&dir.join("summary.json"), &summary_json(summary, scenario)?)?;
    let path = dir.join("scenario.toml");
    let text = toml::to_string(scenario).map_err(|e| anyhow::anyhow!("{}: cannot encode: {e}", path.display()))?;
    write(
        &path,
        &format!(
            "# The effective scenario of this run (defaults, file and --set applied): `tendril run` repeats it.\n{text}"
        ),
    )
}

/// The text of `summary.json`: `summary` with the effective scenario under `"effective_scenario"`.
pub fn summary_json(summary: &RunSummary, scenario: &PickPlaceScenario) -> anyhow::Result<String> {
    let mut record = serde_json::to_value(summary)?;
    if let serde_json::Value::Object(fields) = &mut record {
        fields.insert("effective_scenario".into(), serde_json::to_value(scenario)?);
    }
    Ok(serde_json::to_string_pretty(&record)? + "\n")
}
