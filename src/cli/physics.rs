//! `tendril physics-check`.

use crate::cell::physics::check::CheckScenario;
use crate::scenario::Override;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Arguments of `tendril physics-check`.
#[derive(Debug, clap::Args)]
pub struct PhysicsCheckArgs {
    /// Scenario TOML with optional [physics], [finger], [object], [check] sections.
    scenario: Option<PathBuf>,
    /// Overrides `key=value`, e.g. `finger.relaxation_time_s=8`.
    #[arg(long = "set")]
    set: Vec<Override>,
}

pub fn run(a: PhysicsCheckArgs) -> anyhow::Result<ExitCode> {
    let s: CheckScenario = match a.scenario {
        Some(path) => crate::scenario::load(&path, &a.set)?,
        None => crate::scenario::from_str("", Path::new("(defaults)"), &a.set)?,
    };
    crate::cell::physics::check::run(&s)?;
    Ok(ExitCode::SUCCESS)
}
