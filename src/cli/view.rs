//! `tendril view`.

use crate::view::{ViewOptions, view};
use std::path::PathBuf;
use std::process::ExitCode;
use tendril_run::scenario::PickPlaceScenario;

/// Arguments of `tendril view`.
#[derive(Debug, clap::Args)]
pub struct ViewArgs {
    #[command(flatten)]
    scenario: super::scenario_args::ScenarioArgs,
    /// Cell seconds per wall second: 1 is real time, 2 twice as fast, 0.5 half (0.01 to 100).
    #[arg(long, default_value_t = 1.0, value_parser = speed_arg)]
    speed: f64,
    /// Close the window after this many wall seconds [default: when you close it].
    #[arg(long, value_parser = super::seconds_arg)]
    seconds: Option<f64>,
    /// Save the last frame shown as a PNG file when the window closes.
    #[arg(long)]
    screenshot: Option<PathBuf>,
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

/// `tendril view`: the scenario on the twin in MuJoCo's interactive viewer.
pub fn run(a: ViewArgs) -> anyhow::Result<ExitCode> {
    crate::features::Feature::Viewer.require("tendril view")?;
    let scenario: PickPlaceScenario = a.scenario.load([])?;
    // Ctrl-C, SIGTERM and SIGHUP: the run's safe stop, then the window closes.
    crate::signals::install_signal_handlers()?;
    let opts = ViewOptions { speed: a.speed, seconds: a.seconds, screenshot: a.screenshot.clone() };
    let report = view(&scenario, &opts)?;
    let shot = opts.screenshot.as_ref().map_or(String::new(), |p| format!("; wrote {}", p.display()));
    let end = match &report.error {
        Some(e) => format!("not finished ({e})"),
        None => format!("{:?}", report.outcome).to_lowercase(),
    };
    super::emit(&format!(
        "viewed {}: task {end}, {:.1} s of cell time in {:.1} s ({} ticks, {} frames){shot}\n",
        a.scenario.scenario.display(),
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
