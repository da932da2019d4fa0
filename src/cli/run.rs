//! `tendril run`.

use super::emit;
use std::path::PathBuf;
use std::process::ExitCode;
use tendril_config::Override;
use tendril_run::execute::run_on_twin;
use tendril_run::scenario::PickPlaceScenario;
use tendril_run::summary::render_text;

/// Arguments of `tendril run`.
#[derive(Debug, clap::Args)]
pub struct RunArgs {
    #[command(flatten)]
    scenario: super::scenario_args::ScenarioArgs,
    /// Output folder [default: out/<scenario name>].
    #[arg(long)]
    out: Option<PathBuf>,
    /// The twin's physics engine, `mujoco` or `rapier` (the scenario's `physics.backend`).
    #[arg(long)]
    backend: Option<tendril_twin::physics::Backend>,
    /// Which cell runs the task: the twin (`sim`) or the devices (`real`).
    #[arg(long, value_parser = ["sim", "real"], default_value = "sim")]
    hardware: String,
    /// When the run ends, also render it as OUT/video.mp4 with `tendril render`'s defaults (the
    /// twin only: the real cell records no frames).
    #[arg(long)]
    video: bool,
    #[command(flatten)]
    devices: super::devices::DeviceArgs,
}

impl RunArgs {
    /// `--dxl-baud` and `--backend` are overrides like any `--set`, so they are validated alike.
    fn overrides(&self) -> Vec<Override> {
        let mut extra = self.devices.overrides();
        extra.extend(self.backend.map(|b| b.as_override()));
        extra
    }
}

pub fn run(a: RunArgs) -> anyhow::Result<ExitCode> {
    let scenario: PickPlaceScenario = a.scenario.load(a.overrides())?;
    let dir = a.out.clone().unwrap_or_else(|| tendril_run::output::default_run_dir(&scenario.name));
    if a.video && a.hardware == "real" {
        anyhow::bail!("--video renders the twin's recorded frames; the real cell records none (leave out --video)");
    }
    // Ctrl-C, SIGTERM and SIGHUP: the safe stop, the trace whole and summary.json written.
    crate::signals::install_signal_handlers()?;
    let (summary, _) = if a.hardware == "real" {
        scenario.disturbance.refuse_on_real().map_err(anyhow::Error::msg)?;
        let config = a.devices.config(&scenario)?;
        // This thread runs the ticks; the cell's IO threads, started from it, inherit its priority.
        a.devices.realtime()?.apply_to_current_thread()?;
        tendril_run::real::run_on_real(&scenario, config, Some(&dir))?
    } else {
        run_on_twin(&scenario, &Default::default(), Some(&dir))?
    };
    emit(&render_text(&summary));
    let frames = if dir.join(tendril_twin::frames::FRAMES_FILE).is_file() && a.hardware == "sim" {
        format!(", {}/{}", dir.display(), tendril_twin::frames::FRAMES_FILE)
    } else {
        String::new()
    };
    emit(&format!("wrote {0}/trace.csv, {0}/summary.json{frames} and {0}/scenario.toml\n", dir.display()));
    if a.video {
        // A run that ended in an error still rendered up to its last recorded frame.
        let opts = crate::render::RenderOptions { out: dir.join("video.mp4"), ..Default::default() };
        super::render::render_and_report(&dir, &opts)?;
    }
    Ok(super::exit_for_runs(summary.outcome == "error"))
}
