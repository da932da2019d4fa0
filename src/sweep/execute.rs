//! Running a sweep: check every run first, then run them in parallel, appending each result
//! to `results.csv` as it finishes.

use super::columns::{header, row, sweep_id};
use super::durable::ResultsFile;
use super::{Shard, Sweep, SweepRun};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use tendril_run::execute::{Driver, ModelCache, run_on_twin, run_on_twin_with};
use tendril_run::scenario::PickPlaceScenario;
use tendril_run::summary::RunSummary;

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
    /// Keep each run's directory, `runs/<id>/` (trace, summary and its rosbag2 bag in `bag/`).
    pub bag: bool,
}

/// The folder under a sweep's output where `--bag` keeps each run's directory.
pub const RUNS_DIR: &str = "runs";

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
    /// Bytes of a torn last row `--resume` cut off the results file (that run was run again).
    pub dropped_tail: Option<usize>,
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
///
/// A bad value that came from the sweep file (a grid or list value) is reported against the
/// sweep file, at `grid."key"` or `list[i].key`, with the run and scenario it was found in.
pub fn check_runs(sweep: &Sweep) -> Result<(), tendril_config::ScenarioError> {
    use tendril_config::ScenarioError;
    // Each scenario file is read and parsed once; the runs only differ in their overrides.
    let mut tables: std::collections::HashMap<&Path, toml::Table> = Default::default();
    for run in &sweep.runs {
        if !tables.contains_key(run.scenario.as_path()) {
            let text = tendril_config::read_text(&run.scenario)?;
            let table = text.parse().map_err(|e: toml::de::Error| ScenarioError::Syntax {
                file: run.scenario.clone(),
                message: e.to_string(),
            })?;
            tables.insert(&run.scenario, table);
        }
        let mut table = tables[run.scenario.as_path()].clone();
        let loaded = tendril_config::apply_overrides(&mut table, &sweep.overlay.then(&run.overrides))
            .and_then(|()| tendril_config::from_table::<PickPlaceScenario>(table, &run.scenario))
            .map_err(|e| sweep.overlay.attribute(e, &run.overrides));
        match loaded {
            Ok(_) => {}
            Err(ScenarioError::Invalid { key, reason, .. }) if run.overrides.iter().any(|o| o.key == key) => {
                let place = match run.list_index.filter(|_| list_sets(sweep, run, &key)) {
                    Some(i) => format!("list[{i}].{key}"),
                    None => format!("grid.\"{key}\""),
                };
                return Err(ScenarioError::Invalid {
                    file: sweep.file.clone(),
                    key: place,
                    reason: format!("{reason} (run {} on {})", run.id, run.scenario.display()),
                });
            }
            Err(e) => return Err(e),
        }
    }
    Ok(())
}

/// Whether `run`'s list entry sets `key` (list values override grid values).
fn list_sets(sweep: &Sweep, run: &SweepRun, key: &str) -> bool {
    run.list_index.is_some_and(|i| sweep.list_keys.get(i).is_some_and(|keys| keys.iter().any(|k| k == key)))
}

fn execute_one(sweep: &Sweep, run: &SweepRun, models: &ModelCache, options: &SweepOptions) -> RunSummary {
    let name = run.scenario.file_stem().map_or("?".into(), |s| s.to_string_lossy().to_string());
    let scenario = match sweep.overlay.load_scenario::<PickPlaceScenario>(&run.scenario, &run.overrides) {
        Ok(s) => s,
        Err(e) => return RunSummary::failed_to_start(&name, e.to_string()),
    };
    let result = if options.bag {
        // A directory left by an attempt that has no row (a sweep stopped mid-run) is not a
        // result: --resume runs it again from scratch.
        let dir = options.out_dir.join(RUNS_DIR).join(run.id.to_string());
        let _ = std::fs::remove_dir_all(&dir);
        run_on_twin_with(&scenario, models, Some(&dir), Driver { bag: true, ..Driver::default() })
    } else {
        run_on_twin(&scenario, models, None)
    };
    match result {
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
    let id = sweep_id(sweep);
    let (file, opened) =
        ResultsFile::open(&results, sweep, &id, &header(sweep, &RunSummary::columns()), options.resume, options.shard)?;
    let done = opened.done;
    let mine: Vec<&SweepRun> = sweep.runs.iter().filter(|r| options.shard.is_none_or(|s| s.owns(r.id))).collect();
    let todo: Vec<&SweepRun> = mine.iter().copied().filter(|r| !done.contains(&r.id)).collect();
    let writer = Mutex::new(file);
    let progress = indicatif::ProgressBar::new(todo.len() as u64);
    progress.set_style(
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} runs  {per_sec}  ETA {eta}")
            .expect("the template is valid"),
    );
    let models = ModelCache::default();
    let pool = rayon::ThreadPoolBuilder::new().num_threads(options.threads.unwrap_or(0)).build()?;
    // After a write error (a full disk) no further run starts: its row could not be kept.
    let write_failed = std::sync::atomic::AtomicBool::new(false);
    let outcomes: Vec<anyhow::Result<Option<(bool, f64)>>> = pool.install(|| {
        todo.par_iter()
            .map(|run| {
                if tendril_cell::interrupt::requested().is_some()
                    || write_failed.load(std::sync::atomic::Ordering::SeqCst)
                {
                    return Ok(None);
                }
                let summary = execute_one(sweep, run, &models, options);
                // A run cut short by an operator stop is not done: no row, so --resume runs it.
                if tendril_cell::interrupt::requested().is_some() {
                    return Ok(None);
                }
                let cells = row(sweep, &id, run, &summary);
                if let Err(e) = writer.lock().unwrap_or_else(|p| p.into_inner()).append(&cells) {
                    write_failed.store(true, std::sync::atomic::Ordering::SeqCst);
                    return Err(e.into());
                }
                progress.inc(1);
                Ok(Some((summary.outcome == "error", summary.sim_time_s)))
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
        dropped_tail: opened.dropped_tail,
    };
    for o in outcomes {
        let Some((error, sim)) = o? else { continue };
        stats.ran += 1;
        stats.errors += usize::from(error);
        stats.sim_time_s += sim;
    }
    stats.wall_time_s = started.elapsed().as_secs_f64();
    Ok(stats)
}
