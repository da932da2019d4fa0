//! `tendril tune`: search controller parameters on the twin for each object.

use super::emit;
use crate::fit::tune::{load_tune, run_tune};
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `tendril tune`.
#[derive(Debug, clap::Args)]
pub struct TuneArgs {
    /// The tune file (scenarios/fit/tune-*.toml): scenarios, seeds, disturbances, parameters,
    /// weights, budget.
    tune: PathBuf,
    /// Output folder: per scenario an evaluations log, a landscape chart and overlay.toml; and
    /// tune.json [default: out/tune-<tune file name>].
    #[arg(long)]
    out: Option<PathBuf>,
    /// Scenario keys applied to every scenario after its file (a fitted twin's overlay.toml).
    #[arg(long)]
    overlay: Option<PathBuf>,
    /// Worker threads [default: all cores], 1 to 1024.
    #[arg(long, value_parser = super::sweep::threads_or_all)]
    threads: Option<usize>,
    /// Continue the searches logged in the output folder.
    #[arg(long)]
    resume: bool,
}

pub fn run(a: TuneArgs) -> anyhow::Result<ExitCode> {
    let overlay = tendril_config::Overlay::load(a.overlay.as_deref())?;
    let tune = load_tune(&a.tune, &overlay)?;
    let stem = a.tune.file_stem().map_or("tune".into(), |s| s.to_string_lossy().to_string());
    let out_dir = a.out.unwrap_or_else(|| PathBuf::from("out").join(format!("tune-{stem}")));
    crate::signals::install_signal_handlers()?;
    let (results, written) = run_tune(&tune, &out_dir, a.threads.filter(|&n| n > 0), a.resume)?;
    let mut text = String::new();
    let mut scenarios: Vec<&str> = results.iter().map(|r| r.scenario.as_str()).collect();
    scenarios.dedup();
    for s in scenarios {
        let Some(best) = results.iter().filter(|r| r.scenario == s).min_by(|a, b| a.objective.total_cmp(&b.objective))
        else {
            continue;
        };
        text += &format!(
            "{s}: best{} objective {:.4} (start {}) after {} evaluations\n",
            best.controller_type.as_ref().map_or(String::new(), |t| format!(" {t}")),
            best.objective,
            best.start_objective.map_or("-".into(), |v| format!("{v:.4}")),
            best.evaluations
        );
        for (k, v) in &best.best {
            text += &format!("  {k:<28} {v:.5}\n");
        }
        if let Some(runs) = best.best_detail["runs"].as_array() {
            for r in runs {
                text += &format!(
                    "  seed {}: {}, fluctuation {} %, rise {} s, overshoot {} %\n",
                    r["seed"],
                    r["outcome"].as_str().unwrap_or("?"),
                    r["max_fluctuation_pct"].as_f64().map_or("-".into(), |v| format!("{v:.1}")),
                    r["rise_time_90_s"].as_f64().map_or("-".into(), |v| format!("{v:.2}")),
                    r["overshoot_pct"].as_f64().map_or("-".into(), |v| format!("{v:.1}")),
                );
            }
        }
    }
    text += &format!("wrote {}\n", written.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", "));
    emit(&text);
    if let Some(signal) = tendril_cell::interrupt::requested() {
        emit(&format!(
            "stopped by {}: every finished evaluation is in the logs; --resume continues\n",
            tendril_cell::interrupt::name(signal)
        ));
    }
    Ok(super::exit_for_runs(false))
}
