//! `tendril run`.

use super::emit;
use std::path::PathBuf;
use std::process::ExitCode;
use tendril_config::Override;
use tendril_run::execute::{Driver, run_on_twin_with};
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
    /// Which cell runs the task: the twin (`sim`), the devices (`real`), or a lab's ROS 2 drivers
    /// (`ros2`: the scenario's `[ros2]` topics; docs/cell/ros2.md).
    #[arg(long, value_parser = ["sim", "real", "ros2"], default_value = "sim")]
    hardware: String,
    /// With `--hardware ros2`, keep the cell's time from `/clock` (a ROS node's `use_sim_time`):
    /// needed against a lock-step twin; short for `--set ros2.use_sim_time=true`.
    #[arg(long)]
    use_sim_time: bool,
    /// Also record the run as a rosbag2 bag (MCAP storage) in OUT/bag, on the topics the ROS 2
    /// participant uses live (refused when OUT/bag exists).
    #[arg(long)]
    bag: bool,
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
        if self.use_sim_time {
            extra.push(Override { key: "ros2.use_sim_time".into(), value: toml::Value::Boolean(true) });
        }
        extra
    }
}

pub fn run(a: RunArgs) -> anyhow::Result<ExitCode> {
    let scenario: PickPlaceScenario = a.scenario.load(a.overrides())?;
    let dir = a.out.clone().unwrap_or_else(|| tendril_run::output::default_run_dir(&scenario.name));
    if a.video {
        // Said before the run, not after it.
        crate::features::Feature::Video.require("tendril run --video")?;
    }
    if a.video && a.hardware != "sim" {
        anyhow::bail!(
            "--video renders the twin's recorded frames; a {} cell records none (leave out --video)",
            a.hardware
        );
    }
    if a.use_sim_time && a.hardware != "ros2" {
        anyhow::bail!("--use-sim-time is for --hardware ros2 (the twin and the devices keep their own time)");
    }
    // Ctrl-C, SIGTERM and SIGHUP: the safe stop, the trace whole and summary.json written.
    crate::signals::install_signal_handlers()?;
    let driver = Driver { bag: a.bag, ..Driver::default() };
    let (summary, _) = match a.hardware.as_str() {
        "real" => {
            scenario.disturbance.refuse_on_real().map_err(anyhow::Error::msg)?;
            let config = a.devices.config(&scenario)?;
            // This thread runs the ticks; the cell's IO threads, started from it, inherit its priority.
            a.devices.realtime()?.apply_to_current_thread()?;
            tendril_run::real::run_on_real_with(&scenario, config, Some(&dir), driver)?
        }
        "ros2" => {
            let config = tendril_run::ros2::ros2_cell_config(&scenario);
            tendril_run::ros2::run_on_ros2(&scenario, config, Some(&dir), driver)?
        }
        _ => run_on_twin_with(&scenario, &Default::default(), Some(&dir), driver)?,
    };
    emit(&render_text(&summary));
    let frames = if dir.join(tendril_twin::frames::FRAMES_FILE).is_file() && a.hardware == "sim" {
        format!(", {}/{}", dir.display(), tendril_twin::frames::FRAMES_FILE)
    } else {
        String::new()
    };
    let bag = if a.bag { format!(", {}/{}", dir.display(), tendril_run::bag::BAG_DIR) } else { String::new() };
    emit(&format!("wrote {0}/trace.csv, {0}/summary.json{frames}{bag} and {0}/scenario.toml\n", dir.display()));
    if a.video {
        // A run that ended in an error still rendered up to its last recorded frame.
        let opts = crate::render::RenderOptions { out: dir.join("video.mp4"), ..Default::default() };
        super::render::render_and_report(&dir, &opts)?;
    }
    Ok(super::exit_for_runs(summary.outcome == "error"))
}
