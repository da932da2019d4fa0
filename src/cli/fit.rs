//! `tendril fit`: calibrate the twin's scenario keys to recorded runs.

use super::emit;
use crate::fit::execute::{FitOptions, run_fit};
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `tendril fit`.
#[derive(Debug, clap::Args)]
pub struct FitArgs {
    /// The fit file (scenarios/fit/*.toml): recordings and/or targets (published figures),
    /// parameters and bounds, weights, budget.
    fit: PathBuf,
    /// Output folder: evaluations.jsonl, overlay.toml, fit.json, fit.png and fit.svg
    /// [default: out/fit-<fit file name>].
    #[arg(long)]
    out: Option<PathBuf>,
    /// Worker threads [default: all cores], 1 to 1024.
    #[arg(long, value_parser = super::sweep::threads_or_all)]
    threads: Option<usize>,
    /// Start from the values this overlay gives (a previous fit's overlay.toml) instead of the
    /// fit file's `start`; with `evaluations = 1`, scores those values on the recordings (held-out
    /// predictions).
    #[arg(long)]
    start: Option<PathBuf>,
    /// Most evaluations, instead of the fit file's `budget.evaluations` (1 with `--start`: score
    /// those values, e.g. a hand calibration, without searching); the prescreen shrinks to fit
    /// inside it.
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
    evaluations: Option<u64>,
    /// Continue the search logged in the output folder (evaluations already logged are not run
    /// again).
    #[arg(long)]
    resume: bool,
}

pub fn run(a: FitArgs) -> anyhow::Result<ExitCode> {
    let mut fit = crate::fit::load_fit(&a.fit)?;
    fit.start_from(&tendril_config::Overlay::load(a.start.as_deref())?)?;
    if let Some(n) = a.evaluations {
        fit.budget.evaluations = n as usize;
        fit.budget.prescreen = fit.budget.prescreen.min(n as usize - 1);
    }
    let stem = a.fit.file_stem().map_or("fit".into(), |s| s.to_string_lossy().to_string());
    let out_dir = a.out.unwrap_or_else(|| PathBuf::from("out").join(format!("fit-{stem}")));
    crate::signals::install_signal_handlers()?;
    let options = FitOptions { out_dir, threads: a.threads.filter(|&n| n > 0), resume: a.resume };
    let (report, written) = run_fit(&fit, &options)?;
    let mut text = format!(
        "fit {}: {} evaluations ({} from the log), {:.1} s; {}\n  objective {:.6} (start {})\n",
        fit.file.display(),
        report.evaluations,
        report.reused,
        report.wall_time_s,
        report.stop,
        report.objective,
        report.start_objective.map_or("-".into(), |v| format!("{v:.6}")),
    );
    for p in &report.parameters {
        text += &format!(
            "  {:<36} {:>12} (start {}, range [{}, {}])\n",
            p.key,
            format!("{:.6}", p.best),
            p.start,
            p.min,
            p.max
        );
    }
    for r in &report.residuals {
        text += &format!(
            "  {:<24} force RMSE {}  drop time error {}  outcome {}{}\n",
            r.recording,
            r.force_rmse_n.map_or("-".into(), |v| format!("{v:.4} N")),
            r.drop_time_error_s.map_or("-".into(), |v| format!("{v:+.2} s")),
            r.outcome,
            if r.same_outcome { " (as recorded)" } else { " (NOT as recorded)" },
        );
    }
    for t in &report.targets {
        text += &format!(
            "  {:<28} {:<8} drop {:>7} in {:<9} rise {:>6}  fluctuation {:>7}  score {:.3}{}\n",
            t.target,
            t.outcome,
            t.drop_time_s.map_or("-".into(), |v| format!("{v:.2} s")),
            t.drop_phase.as_deref().unwrap_or("-"),
            t.rise_time_90_s.map_or("-".into(), |v| format!("{v:.2} s")),
            t.max_fluctuation_pct.map_or("-".into(), |v| format!("{v:.1} %")),
            t.score,
            if t.same_outcome { "" } else { " (NOT as the target says)" },
        );
    }
    text += &format!("wrote {}\n", written.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", "));
    emit(&text);
    if let Some(signal) = tendril_cell::interrupt::requested() {
        emit(&format!(
            "stopped by {}: every finished evaluation is in the log; --resume continues\n",
            tendril_cell::interrupt::name(signal)
        ));
    }
    Ok(super::exit_for_runs(false))
}
