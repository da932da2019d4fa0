//! The arguments that pick and adjust a scenario, shared by the commands that run one on the
//! twin (`tendril run`, `tendril view`).

use std::path::PathBuf;
use tendril_config::Override;
use tendril_run::scenario::PickPlaceScenario;

/// A scenario file and what the command line changes in it.
#[derive(Debug, clap::Args)]
pub struct ScenarioArgs {
    /// The scenario file (scenarios/crimper.toml, ...).
    pub scenario: PathBuf,
    /// Seed of the sensor noise (same scenario and seed: identical trace).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Keep force control on while the arm moves (`on`) or switch it off before (`off`).
    #[arg(long, value_parser = ["on", "off"])]
    pub feedback: Option<String>,
    /// Scenario keys from a file (what `tendril fit` and `tendril tune` write), applied after the
    /// scenario file and before `--set`.
    #[arg(long)]
    pub overlay: Option<PathBuf>,
    /// Override a scenario value: `--set key.path=value` (repeatable), checked like the file.
    #[arg(long = "set")]
    pub set: Vec<Override>,
    /// Folder of the scene's model parts (finger.xml, ur5e.xml, ...) [default: models/ beside the
    /// scenario's folder, else the built-in copies]; `physics.models_dir`.
    #[arg(long)]
    pub models: Option<PathBuf>,
}

impl ScenarioArgs {
    /// `--set`, then `--seed`, `--feedback` and `--models` as overrides like any `--set`, so they
    /// are validated alike; `extra` (a command's own, such as `--backend`) go between.
    pub fn overrides(&self, extra: impl IntoIterator<Item = Override>) -> Vec<Override> {
        let mut o = self.set.clone();
        o.extend(extra);
        if let Some(seed) = self.seed {
            o.push(Override { key: "seed".into(), value: tendril_config::seed::to_toml(seed) });
        }
        if let Some(f) = &self.feedback {
            o.push(Override { key: "feedback".into(), value: toml::Value::Boolean(f == "on") });
        }
        o.extend(self.models.as_deref().map(Override::models_dir));
        o
    }

    /// The scenario with the overlay and the overrides applied, validated.
    pub fn load(&self, extra: impl IntoIterator<Item = Override>) -> anyhow::Result<PickPlaceScenario> {
        let overlay = tendril_config::Overlay::load(self.overlay.as_deref())?;
        Ok(overlay.load_scenario(&self.scenario, &self.overrides(extra))?)
    }
}
