//! `tendril view`.

use crate::run::scenario::PickPlaceScenario;
use crate::scenario::Override;
use crate::view::{ViewOptions, view};
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `tendril view`.
#[derive(Debug, clap::Args)]
pub struct ViewArgs {
    /// The scenario file (scenarios/hammer.toml, ...).
    scenario: PathBuf,
    /// Cell seconds per wall second: 1 is real time, 2 twice as fast, 0.5 half (0.01 to 100).
    #[arg(long, default_value_t = 1.0, value_parser = speed_arg)]
    speed: f64,
    /// Close the window after this many wall seconds [default: when you close it].
    #[arg(long, value_parser = super::seconds_arg)]
    seconds: Option<f64>,
    /// Save the last frame shown as a PNG file when the window closes.
    #[arg(long)]
    screenshot: Option<PathBuf>,
    /// Seed of the sensor noise.
    #[arg(long)]
    seed: Option<u64>,
    /// Keep force control on while the arm moves (`on`) or switch it off before (`off`); the F
    /// key switches it during the run.
    #[arg(long, value_parser = ["on", "off"])]
    feedback: Option<String>,
    /// Scenario keys from a file (what `tendril fit` and `tendril tune` write), applied after the
    /// scenario file and before `--set`.
    #[arg(long)]
    overlay: Option<PathBuf>,
    /// Override a scenario value: `--set key.path=value` (repeatable), checked like the file.
    #[arg(long = "set")]
    set: Vec<Override>,
    /// Folder of the scene's model parts (finger.xml, ur5e.xml, ...) [default: models/ beside the
    /// scenario's folder, else the built-in copies]; `physics.models_dir`.
    #[arg(long)]
    models: Option<PathBuf>,
}

/// Slowest and fastest speed factors accepted.
pub const SPEED_RANGE: (f64, f64) = (0.01, 100.0);

/// Parses `--speed`: a finite factor within [`SPEED_RANGE`].
fn speed_arg(s: &str) -> Result<f64, String> {
    let (lo, hi) = SPEED_RANGE;
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && (lo..=hi).contains(&v) => Ok(v),
        _ => Err(format!("must be a speed factor in [{lo}, {hi}] (1 is real time), got {s}")),
    }
}

impl ViewArgs {
    /// `--seed` and `--feedback` are overrides like any `--set`, validated alike (as `tendril run`).
    fn overrides(&self) -> Vec<Override> {
        let mut o = self.set.clone();
        if let Some(seed) = self.seed {
            o.push(Override { key: "seed".into(), value: crate::scenario::seed::to_toml(seed) });
        }
        if let Some(f) = &self.feedback {
            o.push(Override { key: "feedback".into(), value: toml::Value::Boolean(f == "on") });
        }
        o.extend(self.models.as_deref().map(Override::models_dir));
        o
    }
}

/// `tendril view`: the scenario on the twin in MuJoCo's interactive viewer.
pub fn run(a: ViewArgs) -> anyhow::Result<ExitCode> {
    let overlay = crate::scenario::Overlay::load(a.overlay.as_deref())?;
    let scenario: PickPlaceScenario = overlay.load_scenario(&a.scenario, &a.overrides())?;
    // Ctrl-C, SIGTERM and SIGHUP: the run's safe stop, then the window closes.
    crate::interrupt::install()?;
    let opts = ViewOptions { speed: a.speed, seconds: a.seconds, screenshot: a.screenshot.clone() };
    let report = view(&scenario, &opts)?;
    let shot = opts.screenshot.as_ref().map_or(String::new(), |p| format!("; wrote {}", p.display()));
    let end = match &report.error {
        Some(e) => format!("not finished ({e})"),
        None => format!("{:?}", report.outcome).to_lowercase(),
    };
    super::emit(&format!(
        "viewed {}: task {end}, {:.1} s of cell time in {:.1} s ({} ticks, {} frames){shot}\n",
        a.scenario.display(),
        report.cell_time_s,
        report.wall_s,
        report.ticks,
        report.frames
    ));
    // Closing the window or the --seconds limit is a normal end; an operator stop is 128 + signal.
    Ok(super::exit_for_runs(false))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_speed_is_a_bounded_finite_factor() {
        assert_eq!(speed_arg("2"), Ok(2.0));
        assert_eq!(speed_arg(" 0.5 "), Ok(0.5));
        for bad in ["0", "-1", "nan", "inf", "1000", "fast"] {
            assert!(speed_arg(bad).is_err(), "{bad}");
        }
    }
}
