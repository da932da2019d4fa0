//! `tendril reproduce`.

use super::{emit, exit_all, write_file};
use crate::reproduce::{Row, render_table};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use tendril_config::Override;

/// Arguments of `tendril reproduce`.
#[derive(Debug, clap::Args)]
pub struct ReproduceArgs {
    /// Which results: `sensor` (Sec. IV), `gripper` (Sec. V) or `all`.
    what: String,
    /// Also write the comparison table as JSON to this file.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Folder holding the scenario files.
    #[arg(long, default_value = "scenarios")]
    scenarios: PathBuf,
    /// The twin's physics engine for Sec. V, `mujoco` or `rapier` (default: the scenarios' own).
    #[arg(long)]
    backend: Option<tendril_twin::physics::Backend>,
    /// Scenario keys from a file (what `tendril fit` and `tendril tune` write), applied to the Sec. V
    /// scenarios after each file and before `--set`.
    #[arg(long)]
    overlay: Option<PathBuf>,
    /// Override a value of the Sec. V scenarios: `--set key.path=value` (repeatable).
    #[arg(long = "set")]
    set: Vec<Override>,
}

pub fn run(a: ReproduceArgs) -> anyhow::Result<ExitCode> {
    let overlay = tendril_config::Overlay::load(a.overlay.as_deref())?;
    let mut set = a.set.clone();
    set.extend(a.backend.map(|b| b.as_override()));
    let overrides = overlay.then(&set);
    // A bad overlay value is reported against the overlay, as on every other command.
    let rows = reproduce_rows(&a.what, &a.scenarios, &overrides).map_err(|e| {
        match e.downcast::<tendril_config::ScenarioError>() {
            Ok(e) => anyhow::Error::from(overlay.attribute(e, &set)),
            Err(e) => e,
        }
    })?;
    emit(&render_table(&rows));
    if let Some(path) = a.json {
        write_file(&path, &(serde_json::to_string_pretty(&rows)? + "\n"))?;
    }
    Ok(exit_all(rows.iter().all(|r| r.pass)))
}

/// The rows of `tendril reproduce WHAT`: `sensor` (Sec. IV), `gripper` (Sec. V, with `overrides`
/// on its scenarios) or `all`.
pub fn reproduce_rows(what: &str, scenario_dir: &Path, overrides: &[Override]) -> anyhow::Result<Vec<Row>> {
    match what {
        "sensor" => crate::reproduce::sensor::rows(scenario_dir),
        "gripper" => crate::reproduce::gripper::rows(scenario_dir, overrides),
        "all" => {
            let mut rows = crate::reproduce::sensor::rows(scenario_dir)?;
            rows.extend(crate::reproduce::gripper::rows(scenario_dir, overrides)?);
            Ok(rows)
        }
        other => anyhow::bail!("reproduce {other}: unknown (expected sensor, gripper or all)"),
    }
}
