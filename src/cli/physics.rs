//! `tendril physics-check`.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use tendril_config::Override;
use tendril_twin::physics::check::CheckScenario;

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
        Some(path) => tendril_config::load(&path, &a.set)?,
        None => tendril_config::from_str("", Path::new("(defaults)"), &a.set)?,
    };
    tendril_twin::physics::check::run(&s)?;
    Ok(ExitCode::SUCCESS)
}

/// Arguments of `tendril scene`.
#[derive(Debug, clap::Args)]
pub struct SceneArgs {
    /// Pick-and-place scenario whose scene to export.
    scenario: PathBuf,
    /// Overrides `key=value`, checked like the file (e.g. `finger.segments=16`).
    #[arg(long = "set")]
    set: Vec<Override>,
    /// Where to write the MJCF.
    #[arg(long, default_value = "scene.xml")]
    out: PathBuf,
    /// Folder of the scene's model parts [default: models/ beside the scenario's folder, else the
    /// built-in copies]; `physics.models_dir`.
    #[arg(long)]
    models: Option<PathBuf>,
}

/// `tendril scene`: the assembled scene as one MJCF MuJoCo's own tools open, with the start state
/// as keyframe `start`.
pub fn scene(a: SceneArgs) -> anyhow::Result<ExitCode> {
    let mut overrides = a.set.clone();
    overrides.extend(a.models.as_deref().map(Override::models_dir));
    let s: tendril_run::scenario::PickPlaceScenario = tendril_config::load(&a.scenario, &overrides)?;
    let model = tendril_twin::physics::SceneModel::build(&s.scene_spec())?;
    let xml = tendril_twin::physics::export::standalone_xml(&model)?;
    std::fs::write(&a.out, xml).map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", a.out.display()))?;
    super::emit(&format!(
        "wrote {} (keyframe `start`: python -m mujoco.viewer --mjcf {})\n",
        a.out.display(),
        a.out.display()
    ));
    Ok(ExitCode::SUCCESS)
}
