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
    /// Refine adaptively over two grid keys instead of running every point (`--refine`).
    pub refine: Option<super::adaptive::RefineOptions>,
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

/// Runs the sweep. A run that fails is a row with outcome "error"; the sweep goes on. With
/// `options.refine`, only the runs the adaptive maps need ([`super::adaptive`]), and `map.csv`.
pub fn run_sweep(sweep: &Sweep, options: &SweepOptions) -> anyhow::Result<SweepStats> {
    let started = std::time::Instant::now();
    check_runs(sweep)?;
    if options.refine.is_some() && (options.shard.is_some() || options.resume) {
        anyhow::bail!(
            "--refine chooses each run from the results of the runs before it, so it runs whole: \
             leave out --shard and --resume"
        );
    }
    std::fs::create_dir_all(&options.out_dir)
        .map_err(|e| anyhow::anyhow!("{}: cannot create: {e}", options.out_dir.display()))?;
    let results = results_path(&options.out_dir, options.shard);
    let id = sweep_id(sweep);
    let (file, opened) =
        ResultsFile::open(&results, sweep, &id, &header(sweep, &RunSummary::columns()), options.resume, options.shard)?;
    let done = opened.done;
    let mine: Vec<&SweepRun> = sweep.runs.iter().filter(|r| options.shard.is_none_or(|s| s.owns(r.id))).collect();
    let todo: Vec<&SweepRun> = mine.iter().copied().filter(|r| !done.contains(&r.id)).collect();
    let runner = Runner {
        sweep,
        options,
        id: &id,
        writer: Mutex::new(file),
        models: ModelCache::default(),
        pool: rayon::ThreadPoolBuilder::new().num_threads(options.threads.unwrap_or(0)).build()?,
        write_failed: std::sync::atomic::AtomicBool::new(false),
        finished: Mutex::new(Vec::new()),
    };
    let planned = match &options.refine {
        None => {
            // A stop by signal is not a failure: the rows made are kept and counted below.
            if let Err(e) = runner.run(&todo)
                && tendril_cell::interrupt::requested().is_none()
            {
                return Err(e);
            }
            mine.len()
        }
        Some(refine) => {
            let outcome = super::adaptive::refine_sweep(sweep, &id, refine, |batch| runner.run(batch));
            // A stop by signal ends the refinement between batches; the rows made are kept.
            if tendril_cell::interrupt::requested().is_none() {
                let (rows, _) = outcome?;
                write_map(sweep, &options.out_dir, &rows)?;
            }
            sweep.runs.len()
        }
    };
    let finished = runner.finished.into_inner().unwrap_or_else(|p| p.into_inner());
    let mut stats = SweepStats {
        results,
        planned,
        skipped: mine.len() - todo.len(),
        ran: finished.len(),
        errors: finished.iter().filter(|(error, _)| *error).count(),
        sim_time_s: finished.iter().map(|(_, sim)| sim).sum(),
        wall_time_s: 0.0,
        dropped_tail: opened.dropped_tail,
    };
    stats.wall_time_s = started.elapsed().as_secs_f64();
    Ok(stats)
}

/// The adaptive map of every point of the sweep (`map.csv` beside `results.csv`), written whole.
fn write_map(sweep: &Sweep, out_dir: &Path, rows: &[Vec<String>]) -> anyhow::Result<()> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut head = header(sweep, &[]);
    head.extend(super::adaptive::MAP_COLUMNS.map(String::from));
    w.write_record(&head)?;
    for r in rows {
        w.write_record(r)?;
    }
    let bytes = w.into_inner().map_err(|e| anyhow::anyhow!("map.csv: {e}"))?;
    super::durable::write_atomically(&out_dir.join("map.csv"), &bytes)?;
    Ok(())
}

/// Runs batches of a sweep's runs in parallel, appending each row as it finishes.
struct Runner<'a> {
    sweep: &'a Sweep,
    options: &'a SweepOptions,
    id: &'a str,
    writer: Mutex<super::durable::ResultsFile>,
    models: ModelCache,
    pool: rayon::ThreadPool,
    /// After a write error (a full disk) no further run starts: its row could not be kept.
    write_failed: std::sync::atomic::AtomicBool,
    /// Every run finished and written: whether it ended in "error", and its simulated seconds.
    finished: Mutex<Vec<(bool, f64)>>,
}

impl Runner<'_> {
    /// Runs `runs`, writing each row; their summaries in order, or the first write error. A run
    /// cut short by an operator stop has no row (so `--resume` runs it), and then the batch
    /// ends in an error saying so.
    fn run(&self, runs: &[&SweepRun]) -> anyhow::Result<Vec<RunSummary>> {
        use std::sync::atomic::Ordering::SeqCst;
        let progress = indicatif::ProgressBar::new(runs.len() as u64);
        progress.set_style(
            indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} runs  {per_sec}  ETA {eta}")
                .expect("the template is valid"),
        );
        let outcomes: Vec<anyhow::Result<Option<RunSummary>>> = self.pool.install(|| {
            runs.par_iter()
                .map(|run| {
                    if tendril_cell::interrupt::requested().is_some() || self.write_failed.load(SeqCst) {
                        return Ok(None);
                    }
                    let summary = execute_one(self.sweep, run, &self.models, self.options);
                    if tendril_cell::interrupt::requested().is_some() {
                        return Ok(None);
                    }
                    let cells = row(self.sweep, self.id, run, &summary);
                    if let Err(e) = self.writer.lock().unwrap_or_else(|p| p.into_inner()).append(&cells) {
                        self.write_failed.store(true, SeqCst);
                        return Err(e.into());
                    }
                    let mut finished = self.finished.lock().unwrap_or_else(|p| p.into_inner());
                    finished.push((summary.outcome == "error", summary.sim_time_s));
                    progress.inc(1);
                    Ok(Some(summary))
                })
                .collect()
        });
        progress.finish_and_clear();
        let mut summaries = Vec::with_capacity(runs.len());
        for o in outcomes {
            match o? {
                Some(s) => summaries.push(s),
                None => anyhow::bail!("stopped before every run of the batch finished"),
            }
        }
        Ok(summaries)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A shipped sweep file is what a user runs first: each one expands and every run's scenario,
    /// with its grid values, loads as `tendril sweep` would check it before running anything.
    #[test]
    fn every_shipped_sweep_file_expands_into_runs_that_load() {
        let scenarios = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios");
        let mut checked = 0;
        for entry in std::fs::read_dir(&scenarios).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            if !(name.starts_with("sweep-") && name.ends_with(".toml")) {
                continue;
            }
            let sweep = crate::sweep::load_sweep(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(!sweep.runs.is_empty(), "{name}");
            check_runs(&sweep).unwrap_or_else(|e| panic!("{name}: {e}"));
            checked += 1;
        }
        assert!(checked >= 4, "found {checked} sweep files in {}", scenarios.display());
    }
}
