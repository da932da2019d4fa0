//! The search: CMA-ES ([`cmaes`]) over the parameters' unit cube, each generation's candidates
//! evaluated in parallel, every evaluation logged ([`super::log`]) before it counts.
//!
//! Why CMA-ES: the objective is a black box (a full simulated run per recording), a little noisy
//! (contacts) and has 2-10 parameters on very different scales; CMA-ES needs no gradient, uses only
//! the ranking of candidates (so the objective's scale and a failed run's penalty do not distort
//! it), adapts its step to the parameters' correlations (relaxation time against relaxed fraction)
//! and converges in a few hundred evaluations at this size. Bounds are handled by searching the
//! unit cube of [`Parameter::to_unit`]: a candidate outside is evaluated at the nearest point inside
//! and charged its squared distance, so the search is pulled back without a wall.

use super::log::{EvalLog, EvalRecord, LogError};
use super::space::Parameter;
use cmaes::{CMAESOptions, DVector};
use std::collections::HashMap;
use std::sync::Mutex;

/// The objective of a candidate whose run failed (diverged, or could not start): worse than any
/// real objective, finite so the ranking stays defined.
pub const FAILED: f64 = 1.0e3;

/// How the search runs (`[budget]`).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Budget {
    /// Most candidates evaluated (each runs every recording once).
    pub evaluations: usize,
    /// Candidates per generation (default: CMA-ES's 4 + 3 ln n).
    pub population: Option<usize>,
    /// Initial step, as a fraction of each parameter's range on its scale.
    pub step: f64,
    /// Seed of the search's sampling: the same seed, spec and recordings give the same search.
    pub seed: u64,
    /// Stop when the step is below this fraction of every range (converged).
    pub tolerance: f64,
}

impl Default for Budget {
    fn default() -> Budget {
        Budget { evaluations: 300, population: None, step: 0.3, seed: 1, tolerance: 1e-4 }
    }
}

impl Budget {
    /// The first bad value, as (key, reason).
    pub fn check(&self) -> Option<(String, String)> {
        if self.evaluations == 0 {
            return Some(("budget.evaluations".into(), "must be at least 1, got 0".into()));
        }
        if self.population.is_some_and(|p| p < 2) {
            return Some(("budget.population".into(), "must be at least 2".into()));
        }
        if !(self.step > 0.0 && self.step <= 1.0) {
            return Some(("budget.step".into(), format!("must be in (0, 1], got {}", self.step)));
        }
        if !(self.tolerance > 0.0 && self.tolerance < 1.0) {
            return Some(("budget.tolerance".into(), format!("must be in (0, 1), got {}", self.tolerance)));
        }
        None
    }
}

/// One candidate's result, as the search's evaluator returns it.
#[derive(Debug, Clone, PartialEq)]
pub struct Evaluation {
    /// The objective (lower is better); [`FAILED`] for a failed run.
    pub objective: f64,
    /// A run failed.
    pub failed: bool,
    /// What to log with it.
    pub detail: serde_json::Value,
}

/// What a search did.
#[derive(Debug, Clone)]
pub struct SearchResult {
    /// The best candidate's values (the start's when nothing better was found).
    pub best: Vec<f64>,
    /// Its log record.
    pub best_record: Option<EvalRecord>,
    /// Every evaluation, in log order (earlier sessions' first).
    pub history: Vec<EvalRecord>,
    /// Evaluations taken from the log of an earlier session.
    pub reused: usize,
    /// Why the search ended.
    pub stop: String,
    /// Wall time of this session's search \[s\].
    pub wall_time_s: f64,
}

/// Searches `params` for the lowest `evaluate`, logging each evaluation to `log` (`previous`: the
/// evaluations an earlier session logged, reused when met again). `label` names the search on the
/// progress bar.
pub fn minimize<E>(
    params: &[Parameter],
    budget: &Budget,
    threads: Option<usize>,
    log: EvalLog,
    previous: Vec<EvalRecord>,
    label: &str,
    evaluate: E,
) -> anyhow::Result<SearchResult>
where
    E: Fn(&[f64]) -> Evaluation + Sync,
{
    let started = std::time::Instant::now();
    let start: Vec<f64> = params.iter().map(|p| p.to_unit(p.start)).collect();
    let cache: Mutex<HashMap<Vec<u64>, EvalRecord>> = Mutex::new(
        previous
            .iter()
            .filter_map(|r| Some((r.exact_values()?.iter().map(|v| v.to_bits()).collect(), r.clone())))
            .collect(),
    );
    // The budget counts the earlier sessions' evaluations too: a resumed search ends where the
    // uninterrupted one would have.
    let reused = previous.len();
    let used = std::sync::atomic::AtomicUsize::new(reused);
    let history = Mutex::new(previous);
    let log = Mutex::new(log);
    let write_error: Mutex<Option<LogError>> = Mutex::new(None);
    let progress = indicatif::ProgressBar::new(budget.evaluations as u64);
    progress.set_style(
        indicatif::ProgressStyle::with_template("{prefix} {bar:30} {pos}/{len} evaluations  best {msg}  ETA {eta}")
            .expect("the template is valid"),
    );
    progress.set_prefix(label.to_string());
    let best_so_far = Mutex::new(f64::INFINITY);
    let objective = |u: &DVector<f64>| -> f64 {
        use std::sync::atomic::Ordering::SeqCst;
        let values: Vec<f64> = params.iter().zip(u.iter()).map(|(p, &u)| p.from_unit(u)).collect();
        let outside: f64 = u.iter().map(|&u| (u - u.clamp(0.0, 1.0)).powi(2)).sum();
        let key: Vec<u64> = values.iter().map(|v| v.to_bits()).collect();
        if let Some(r) = cache.lock().unwrap_or_else(|p| p.into_inner()).get(&key) {
            return r.exact_objective().unwrap_or(FAILED) + outside;
        }
        let stopping =
            crate::interrupt::requested().is_some() || write_error.lock().unwrap_or_else(|p| p.into_inner()).is_some();
        // Beyond the budget (the last generation's remainder) or stopping: not run, not logged.
        if stopping || used.fetch_add(1, SeqCst) >= budget.evaluations {
            return FAILED + outside;
        }
        let e = evaluate(&values);
        if crate::interrupt::requested().is_some() {
            // Cut short by the stop: not a result, run again on --resume.
            return FAILED + outside;
        }
        let objective = if e.objective.is_finite() { e.objective } else { FAILED };
        match log.lock().unwrap_or_else(|p| p.into_inner()).append(&values, objective, e.failed, e.detail) {
            Ok(record) => {
                cache.lock().unwrap_or_else(|p| p.into_inner()).insert(key, record.clone());
                history.lock().unwrap_or_else(|p| p.into_inner()).push(record);
            }
            Err(err) => {
                *write_error.lock().unwrap_or_else(|p| p.into_inner()) = Some(err);
            }
        }
        let mut best = best_so_far.lock().unwrap_or_else(|p| p.into_inner());
        if objective < *best {
            *best = objective;
            progress.set_message(format!("{objective:.5}"));
        }
        progress.inc(1);
        objective + outside
    };
    // The start first: the baseline every later candidate is compared with (and the first point of
    // the chart).
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads.unwrap_or(0)).build()?;
    pool.install(|| objective(&DVector::from_vec(start.clone())));
    // Whole generations only, so the budget never cuts one short: which candidates of a cut
    // generation ran would depend on the threads' timing, and the search would not repeat.
    let dim = params.len();
    let mut lambda = budget.population.unwrap_or(4 + (3.0 * (dim as f64).ln()).floor() as usize);
    let mut generations = (budget.evaluations - 1) / lambda;
    if generations == 0 && budget.evaluations > 2 {
        (lambda, generations) = (budget.evaluations - 1, 1);
    }
    let options = CMAESOptions::new(start, budget.step)
        .seed(budget.seed)
        .population_size(lambda.max(2))
        .max_generations(generations.max(1))
        .tol_x(budget.tolerance)
        .tol_fun(1e-9)
        .tol_fun_hist(1e-9)
        .tol_stagnation(usize::MAX / 2);
    let mut cmaes = options.build(objective).map_err(|e| anyhow::anyhow!("the search cannot start: {e:?}"))?;
    let stop = pool.install(|| {
        if generations == 0 {
            return "the budget holds the start only".to_string();
        }
        loop {
            let end = cmaes.next_parallel();
            if crate::interrupt::requested().is_some() {
                break "stopped by a signal".to_string();
            }
            if write_error.lock().unwrap_or_else(|p| p.into_inner()).is_some() {
                break "the log could not be written".to_string();
            }
            if let Some(end) = end {
                break format!("{:?}", end.reasons);
            }
        }
    });
    progress.finish_and_clear();
    if let Some(e) = write_error.into_inner().unwrap_or_else(|p| p.into_inner()) {
        return Err(e.into());
    }
    let history = history.into_inner().unwrap_or_else(|p| p.into_inner());
    let best_record = history
        .iter()
        .filter(|r| !r.failed)
        .min_by(|a, b| a.exact_objective().unwrap_or(FAILED).total_cmp(&b.exact_objective().unwrap_or(FAILED)))
        .cloned();
    let best = best_record
        .as_ref()
        .and_then(EvalRecord::exact_values)
        .unwrap_or_else(|| params.iter().map(|p| p.start).collect());
    Ok(SearchResult { best, best_record, history, reused, stop, wall_time_s: started.elapsed().as_secs_f64() })
}
