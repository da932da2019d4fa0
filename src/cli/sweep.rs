//! `tendril sweep` and `tendril merge`.

use super::emit;
use crate::sweep::adaptive::RefineOptions;
use crate::sweep::execute::{SweepOptions, run_sweep};
use crate::sweep::{Shard, load_sweep};
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `tendril sweep`.
#[derive(Debug, clap::Args)]
pub struct SweepArgs {
    /// The sweep file (scenarios/sweep-gains.toml, ...).
    sweep: PathBuf,
    /// Output folder [default: out/<sweep file name>].
    #[arg(long)]
    out: Option<PathBuf>,
    /// Worker threads [default: all cores], 1 to 1024.
    #[arg(long, value_parser = threads)]
    threads: Option<usize>,
    /// Run only slice K of N (`--shard 2/8`), for a cluster's job array.
    #[arg(long)]
    shard: Option<Shard>,
    /// Skip the runs already in the results file and append the rest.
    #[arg(long)]
    resume: bool,
    /// Scenario keys applied to every run from a file (what `tendril fit` and `tendril tune` write), applied after the
    /// scenario file and before `--set`.
    #[arg(long)]
    overlay: Option<PathBuf>,
    /// Keep each run's directory under runs/<id>/ (trace.csv, summary.json) with its rosbag2 bag in bag/.
    #[arg(long)]
    bag: bool,
    /// Refine adaptively over two grid keys (`--refine controller.kp,controller.ki`): each map of
    /// those two keys runs every STRIDE-th value of each first, then only the cells whose runs
    /// disagree (outcome, oscillation, `--contour`), down to every point; `map.csv` holds every
    /// point, run or filled in from its cell (column `ran`). Not with `--shard` or `--resume`.
    #[arg(long, value_name = "KEY1,KEY2")]
    refine: Option<String>,
    /// With `--refine`: the coarse grid's stride (1 runs every point).
    #[arg(long, default_value_t = crate::sweep::refine::DEFAULT_STRIDE, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..=1024))]
    stride: usize,
    /// With `--refine`: also follow where a summary field crosses a value, `FIELD=VALUE` (e.g.
    /// `max_fluctuation_pct=10`).
    #[arg(long, value_name = "FIELD=VALUE", requires = "refine")]
    contour: Option<crate::sweep::contour::Contour>,
}

/// Most worker threads a sweep may ask for. Why: runs are CPU-bound and each holds its own
/// simulation state, so threads beyond the cores only cost memory; 1024 is above the hardware
/// threads of any single machine this runs on (`--threads 100000` once created 10 000 threads).
pub const MAX_THREADS: usize = 1024;

/// `--threads N` with 1 <= N <= [`MAX_THREADS`].
fn threads(s: &str) -> Result<usize, String> {
    match s.trim().parse::<usize>() {
        Ok(n) if (1..=MAX_THREADS).contains(&n) => Ok(n),
        _ => Err(format!("must be a whole number from 1 to {MAX_THREADS}, got {s}")),
    }
}

/// `--threads N` with 0 (all cores) or 1 <= N <= [`MAX_THREADS`], for `chart`.
pub(super) fn threads_or_all(s: &str) -> Result<usize, String> {
    if s.trim() == "0" { Ok(0) } else { threads(s) }
}

/// Arguments of `tendril merge`.
#[derive(Debug, clap::Args)]
pub struct MergeArgs {
    /// The merged file to write.
    #[arg(long)]
    out: PathBuf,
    /// The shard files (results-K-of-N.csv).
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
}

pub fn run(a: SweepArgs) -> anyhow::Result<ExitCode> {
    let mut sweep = load_sweep(&a.sweep)?;
    sweep.overlay = tendril_config::Overlay::load(a.overlay.as_deref())?;
    let stem = a.sweep.file_stem().map_or("sweep".into(), |s| s.to_string_lossy().to_string());
    let options = SweepOptions {
        out_dir: a.out.unwrap_or_else(|| PathBuf::from("out").join(stem)),
        threads: a.threads,
        shard: a.shard,
        resume: a.resume,
        bag: a.bag,
        refine: match a.refine.as_deref().map(|k| k.split_once(',')) {
            None => None,
            Some(Some((x, y))) if !x.trim().is_empty() && !y.trim().is_empty() && !y.contains(',') => {
                Some(RefineOptions {
                    keys: [x.trim().to_string(), y.trim().to_string()],
                    stride: a.stride,
                    contour: a.contour.clone(),
                })
            }
            Some(_) => anyhow::bail!("--refine {}: give two grid keys, KEY1,KEY2", a.refine.unwrap_or_default()),
        },
    };
    // Ctrl-C, SIGTERM and SIGHUP: no new run starts; every finished row is kept whole.
    crate::signals::install_signal_handlers()?;
    let stats = run_sweep(&sweep, &options)?;
    if let Some(bytes) = stats.dropped_tail {
        emit(&format!("{}: cut off a torn last row ({bytes} bytes); its run is run again\n", stats.results.display()));
    }
    if let Some(signal) = tendril_cell::interrupt::requested() {
        emit(&format!(
            "stopped by {}: {} runs finished and written\n",
            tendril_cell::interrupt::name(signal),
            stats.ran
        ));
    }
    emit(&format!(
        "{} runs in this sweep{}: {} run now ({} errors), {} already done; {:.0} simulated s in {:.1} s wall ({}x real time)\nwrote {}\n",
        stats.planned,
        a.shard.map_or(String::new(), |s| format!(" shard {}/{}", s.index, s.count)),
        stats.ran,
        stats.errors,
        stats.skipped,
        stats.sim_time_s,
        stats.wall_time_s,
        tendril_run::summary::speed_factor(stats.sim_time_s / stats.wall_time_s.max(1e-9)),
        stats.results.display()
    ));
    if options.refine.is_some() && tendril_cell::interrupt::requested().is_none() {
        emit(&format!(
            "refined: {} of {} points run; every point in {}\n",
            stats.ran,
            stats.planned,
            options.out_dir.join("map.csv").display()
        ));
    }
    Ok(super::exit_for_runs(stats.errors > 0))
}

pub fn merge(a: MergeArgs) -> anyhow::Result<ExitCode> {
    let inputs: Vec<&std::path::Path> = a.inputs.iter().map(|p| p.as_path()).collect();
    let n = crate::sweep::results::merge(&inputs, &a.out)?;
    emit(&format!("merged {} rows from {} files into {}\n", n, inputs.len(), a.out.display()));
    Ok(ExitCode::SUCCESS)
}
