//! `tendril run`.

use super::emit;
use crate::run::execute::run_on_twin;
use crate::run::scenario::PickPlaceScenario;
use crate::run::summary::render_text;
use crate::scenario::Override;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `tendril run`.
#[derive(Debug, clap::Args)]
pub struct RunArgs {
    /// The scenario file (scenarios/crimper.toml, ...).
    scenario: PathBuf,
    /// Output folder [default: out/<scenario name>].
    #[arg(long)]
    out: Option<PathBuf>,
    /// Seed of the sensor noise (same scenario and seed: identical trace).
    #[arg(long)]
    seed: Option<u64>,
    /// Keep force control on while the arm moves (`on`) or switch it off before (`off`).
    #[arg(long, value_parser = ["on", "off"])]
    feedback: Option<String>,
    /// Scenario keys from a file (what `tendril fit` and `tendril tune` write), applied after the
    /// scenario file and before `--set`.
    #[arg(long)]
    overlay: Option<PathBuf>,
    /// Override a scenario value: `--set key.path=value` (repeatable), checked like the file.
    #[arg(long = "set")]
    set: Vec<Override>,
    /// The twin's physics engine, `mujoco` or `rapier` (the scenario's `physics.backend`).
    #[arg(long)]
    backend: Option<crate::cell::physics::Backend>,
    /// Folder of the scene's model parts (finger.xml, ur5e.xml, ...) [default: models/ beside the
    /// scenario's folder, else the built-in copies]; `physics.models_dir`.
    #[arg(long)]
    models: Option<PathBuf>,
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
    /// `--seed`, `--feedback` and `--dxl-baud` are overrides like any `--set`, so they are
    /// validated alike.
    fn overrides(&self) -> Vec<Override> {
        let mut o = self.set.clone();
        o.extend(self.devices.overrides());
        if let Some(seed) = self.seed {
            o.push(Override { key: "seed".into(), value: crate::scenario::seed::to_toml(seed) });
        }
        if let Some(f) = &self.feedback {
            o.push(Override { key: "feedback".into(), value: toml::Value::Boolean(f == "on") });
        }
        o.extend(self.backend.map(Override::backend));
        o.extend(self.models.as_deref().map(Override::models_dir));
        o
    }
}

pub fn run(a: RunArgs) -> anyhow::Result<ExitCode> {
    let overlay = crate::scenario::Overlay::load(a.overlay.as_deref())?;
    let scenario: PickPlaceScenario = overlay.load_scenario(&a.scenario, &a.overrides())?;
    let dir = a.out.clone().unwrap_or_else(|| crate::run::output::default_run_dir(&scenario.name));
    if a.video && a.hardware == "real" {
        anyhow::bail!("--video renders the twin's recorded frames; the real cell records none (leave out --video)");
    }
    // Ctrl-C, SIGTERM and SIGHUP: the safe stop, the trace whole and summary.json written.
    crate::interrupt::install()?;
    let (summary, _) = if a.hardware == "real" {
        scenario.disturbance.refuse_on_real().map_err(anyhow::Error::msg)?;
        let config = a.devices.config(&scenario)?;
        // This thread runs the ticks; the cell's IO threads, started from it, inherit its priority.
        a.devices.realtime()?.apply_to_current_thread()?;
        crate::run::real::run_on_real(&scenario, config, Some(&dir))?
    } else {
        run_on_twin(&scenario, &Default::default(), Some(&dir))?
    };
    emit(&render_text(&summary));
    let frames = if dir.join(crate::render::frames::FRAMES_FILE).is_file() && a.hardware == "sim" {
        format!(", {}/{}", dir.display(), crate::render::frames::FRAMES_FILE)
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
