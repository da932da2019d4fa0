//! `tendril reproduce`.

use super::{emit, exit_all, write_file};
use crate::reproduce::{Row, render_table};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

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
}

pub fn run(a: ReproduceArgs) -> anyhow::Result<ExitCode> {
    let rows = reproduce_rows(&a.what, &a.scenarios)?;
    emit(&render_table(&rows));
    if let Some(path) = a.json {
        write_file(&path, &(serde_json::to_string_pretty(&rows)? + "\n"))?;
    }
    Ok(exit_all(rows.iter().all(|r| r.pass)))
}

/// The rows of `tendril reproduce WHAT`: `sensor` (Sec. IV), `gripper` (Sec. V) or `all`.
pub fn reproduce_rows(what: &str, scenario_dir: &Path) -> anyhow::Result<Vec<Row>> {
    match what {
        "sensor" => crate::reproduce::sensor::rows(scenario_dir),
        "gripper" => crate::reproduce::gripper::rows(scenario_dir, &[]),
        "all" => {
            let mut rows = crate::reproduce::sensor::rows(scenario_dir)?;
            rows.extend(crate::reproduce::gripper::rows(scenario_dir, &[])?);
            Ok(rows)
        }
        other => anyhow::bail!("reproduce {other}: unknown (expected sensor, gripper or all)"),
    }
}
