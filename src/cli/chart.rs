//! `tendril chart`: studies over many runs, each written as CSV and charted.

use super::emit;
use crate::cell::physics::{FingerConfig, PhysicsConfig};
use crate::study;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `tendril chart`.
#[derive(Debug, clap::Args)]
pub struct ChartArgs {
    /// Which study: `speed-accuracy`, `stability` or `gain-map`.
    #[arg(value_parser = ["speed-accuracy", "stability", "gain-map"])]
    study: String,
    /// Scenario to study [default: speed-accuracy the crimper (its fine reference drops it too, so
    /// drop times compare), stability the hammer (the heaviest load); gain-map: the three objects].
    #[arg(long)]
    scenario: Vec<PathBuf>,
    /// Output folder [default: out/<study>].
    #[arg(long)]
    out: Option<PathBuf>,
    /// A small grid, for a quick look.
    #[arg(long)]
    quick: bool,
    /// Worker threads for the studies that do not time runs (stability, gain-map); 0: all cores,
    /// at most 1024.
    #[arg(long, default_value_t = 0, value_parser = super::sweep::threads_or_all)]
    threads: usize,
}

pub fn run(a: ChartArgs) -> anyhow::Result<ExitCode> {
    let out = a.out.clone().unwrap_or_else(|| PathBuf::from("out").join(&a.study));
    let first = |default: &str| a.scenario.first().cloned().unwrap_or_else(|| PathBuf::from(default));
    let files = match a.study.as_str() {
        "speed-accuracy" => {
            let grid = if a.quick { study::speed_accuracy::Grid::quick() } else { study::speed_accuracy::Grid::full() };
            let p = PhysicsConfig::default();
            let defaults = (p.timestep_s, "implicitfast", "elliptic", FingerConfig::default().segments);
            study::speed_accuracy::run(&first("scenarios/crimper.toml"), &grid, defaults, &out)?
        }
        "stability" => {
            let steps: &[f64] = if a.quick { &[0.005, 0.04] } else { &study::stability::TIMESTEPS_S };
            study::stability::run(&first("scenarios/hammer.toml"), steps, &out, a.threads)?
        }
        _ => {
            let scenarios = if a.scenario.is_empty() {
                ["crimper", "shampoo", "hammer"].map(|o| PathBuf::from(format!("scenarios/{o}.toml"))).to_vec()
            } else {
                a.scenario.clone()
            };
            let (kp, ki): (&[f64], &[f64]) =
                if a.quick { (&[5.0, 20.0], &[0.05]) } else { (&study::gain_map::KP, &study::gain_map::KI) };
            study::gain_map::run(&scenarios, kp, ki, &out, a.threads)?
        }
    };
    for f in files {
        emit(&format!("{}\n", f.display()));
    }
    Ok(ExitCode::SUCCESS)
}
