//! Running a sweep: check every run first, then run them in parallel, appending each result
//! to `results.csv` as it finishes.

use super::results::{ResultsWriter, finished_ids, header, row};
use super::{Shard, Sweep, SweepRun};
use crate::run::execute::{ModelCache, run_on_twin};
use crate::run::scenario::PickPlaceScenario;
use crate::run::summary::RunSummary;
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// How to run a sweep.
#[derive(Debug, Clone)]
pub struct SweepOptions {
    /// Folder for `results.csv` (created if needed).
    pub out_dir: PathBuf,
    /// Worker threads (default: all cores).
    pub threads: Option<usize>,
    /// Run only this slice.
    pub shard: Option<Shard>,
    /// Skip runs already in the results file.
    pub resume: bool,
}

/// What a sweep did.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepStats {
    /// The results file.
    pub results: PathBuf,
    /// Runs in this shard.
    pub planned: usize,
    /// Runs skipped because `--resume` found them done.
    pub skipped: usize,
    /// Runs executed now.
    pub ran: usize,
    /// Of those, how many ended in "error".
    pub errors: usize,
    /// Simulated seconds over all runs executed.
    pub sim_time_s: f64,
    /// Wall time of the whole sweep \[s\].
    pub wall_time_s: f64,
}

/// The results file of a sweep (one per shard, so shards never write the same file).
pub fn results_path(out_dir: &Path, shard: Option<Shard>) -> PathBuf {
    match shard {
        None => out_dir.join("results.csv"),
        Some(s) => out_dir.join(format!("results-{}-of-{}.csv", s.index, s.count)),
    }
}

/// Loads every run's scenario with its overrides: the first bad key or value stops the sweep
/// before anything runs.
pub fn check_runs(sweep: &Sweep) -> Result<(), crate::scenario::ScenarioError> {
    for run in &sweep.runs {
        crate::scenario::load::<PickPlaceScenario>(&run.scenario, &run.overrides)?;
    }
    Ok(())
}

fn execute_one(run: &SweepRun, models: &ModelCache) -> RunSummary {
    let name = run.scenario.file_stem().map_or("?".into(), |s| s.to_string_lossy().to_string());
    let scenario = match crate::scenario::load::<PickPlaceScenario>(&run.scenario, &run.overrides) {
        Ok(s) => s,
        Err(e) => return RunSummary::failed_to_start(&name, e.to_string()),
    };
    match run_on_twin(&scenario, models, None) {
        Ok((summary, _)) => summary,
        Err(e) => RunSummary::failed_to_start(&scenario.name, format!("{e:#}")),
    }
}

/// Runs the sweep. A run that fails is a row with outcome "error"; the sweep goes on.
pub fn run_sweep(sweep: &Sweep, options: &SweepOptions) -> anyhow::Result<SweepStats> {
    let started = std::time::Instant::now();
    check_runs(sweep)?;
    std::fs::create_dir_all(&options.out_dir)
        .map_err(|e| anyhow::anyhow!("{}: cannot create: {e}", options.out_dir.display()))?;
    let results = results_path(&options.out_dir, options.shard);
    let done = if options.resume { finished_ids(&results)? } else { Default::default() };
    if !options.resume && results.exists() {
        anyhow::bail!("{} exists: pass --resume to continue it, or choose another --out", results.display());
    }
    let mine: Vec<&SweepRun> = sweep.runs.iter().filter(|r| options.shard.is_none_or(|s| s.owns(r.id))).collect();
    let todo: Vec<&SweepRun> = mine.iter().copied().filter(|r| !done.contains(&r.id)).collect();

    let writer = Mutex::new(
        ResultsWriter::open(&results, &header(sweep, &RunSummary::columns()))
            .map_err(|e| anyhow::anyhow!("{}: {e}", results.display()))?,
    );
    let progress = indicatif::ProgressBar::new(todo.len() as u64);
    progress.set_style(
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} runs  {per_sec}  ETA {eta}")
            .expect("the template is valid"),
    );
    let models = ModelCache::default();
    let pool = rayon::ThreadPoolBuilder::new().num_threads(options.threads.unwrap_or(0)).build()?;
    let outcomes: Vec<anyhow::Result<(bool, f64)>> = pool.install(|| {
        todo.par_iter()
            .map(|run| {
                let summary = execute_one(run, &models);
                let cells = row(sweep, run, &summary);
                writer
                    .lock()
                    .unwrap_or_else(|p| p.into_inner())
                    .append(&cells)
                    .map_err(|e| anyhow::anyhow!("{}: {e}", results.display()))?;
                progress.inc(1);
                Ok((summary.outcome == "error", summary.sim_time_s))
            })
            .collect()
    });
    progress.finish_and_clear();
    let mut stats = SweepStats {
        results,
        planned: mine.len(),
        skipped: mine.len() - todo.len(),
        ran: 0,
        errors: 0,
        sim_time_s: 0.0,
        wall_time_s: 0.0,
    };
    for o in outcomes {
        let (error, sim) = o?;
        stats.ran += 1;
        stats.errors += usize::from(error);
        stats.sim_time_s += sim;
    }
    stats.wall_time_s = started.elapsed().as_secs_f64();
    Ok(stats)
}
