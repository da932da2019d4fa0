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
//!
//! CMA-ES is a local search: from a start on a plateau, or beside a narrow valley, it settles
//! where it began (the paper fit: docs/studies/fit-paper.md#why-a-prescreen-was-needed). `budget.prescreen` first evaluates
//! that many quasi-random points spread evenly over the whole cube ([`spread_points`]) and starts
//! the search from the best of them and the start.

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
    /// Points spread over the whole range ([`spread_points`]) evaluated before the search, which
    /// then starts from the best of them and the start (0: none, the search starts at the start).
    /// Part of `evaluations`.
    pub prescreen: usize,
}

impl Default for Budget {
    fn default() -> Budget {
        Budget { evaluations: 300, population: None, step: 0.3, seed: 1, tolerance: 1e-4, prescreen: 0 }
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
        if self.prescreen >= self.evaluations {
            return Some((
                "budget.prescreen".into(),
                format!(
                    "must be below budget.evaluations ({}), which it is part of, got {}",
                    self.evaluations, self.prescreen
                ),
            ));
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
        let stopping = tendril_cell::interrupt::requested().is_some()
            || write_error.lock().unwrap_or_else(|p| p.into_inner()).is_some();
        // Beyond the budget (the last generation's remainder) or stopping: not run, not logged.
        if stopping || used.fetch_add(1, SeqCst) >= budget.evaluations {
            return FAILED + outside;
        }
        let e = evaluate(&values);
        if tendril_cell::interrupt::requested().is_some() {
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
    // the chart); then the prescreen, in parallel, and the search from the best point so far (the
    // first of equals: the choice does not depend on the threads' timing).
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads.unwrap_or(0)).build()?;
    let dim = params.len();
    let mut candidates = vec![start];
    candidates.extend(spread_points(budget.prescreen, dim));
    let scores: Vec<f64> = pool.install(|| {
        use rayon::prelude::*;
        candidates.par_iter().map(|u| objective(&DVector::from_vec(u.clone()))).collect()
    });
    let best_first = scores.iter().enumerate().min_by(|a, b| a.1.total_cmp(b.1)).map_or(0, |(k, _)| k);
    let start = candidates.swap_remove(best_first);
    // Whole generations only, so the budget never cuts one short: which candidates of a cut
    // generation ran would depend on the threads' timing, and the search would not repeat.
    let left = budget.evaluations - 1 - budget.prescreen;
    let mut lambda = budget.population.unwrap_or(4 + (3.0 * (dim as f64).ln()).floor() as usize);
    let mut generations = left / lambda;
    if generations == 0 && left > 1 {
        (lambda, generations) = (left, 1);
    }
    let options = CMAESOptions::new(start, budget.step)
        .seed(budget.seed)
        .population_size(lambda.max(2))
        .max_generations(generations.max(1))
        .tol_x(budget.tolerance)
        .tol_fun(1e-9)
        .tol_fun_hist(1e-9)
        .tol_stagnation(usize::MAX / 2);
    let mut cmaes = options.build(&objective).map_err(|e| anyhow::anyhow!("the search cannot start: {e:?}"))?;
    let stop = pool.install(|| {
        if generations == 0 {
            let what = if budget.prescreen > 0 { "the start and the prescreen" } else { "the start" };
            return format!("the budget holds {what} only");
        }
        loop {
            let end = cmaes.next_parallel();
            if tendril_cell::interrupt::requested().is_some() {
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

/// `n` points of the unit cube of `dim` dimensions, spread evenly over it whatever `n`: Roberts'
/// R_d sequence, x_k = frac(1/2 + k α) with α_i = φ_d^-(i+1) and φ_d the root of x^(d+1) = x + 1
/// (the golden ratio for d = 1). Its points cover every dimension and every projection without the
/// lines a Halton sequence draws in high dimensions at small `n`, and need no seed: the prescreen
/// is the same in every session, so a resumed search finds its points in the log.
pub fn spread_points(n: usize, dim: usize) -> Vec<Vec<f64>> {
    let d = dim as f64;
    // Newton on x^(d+1) - x - 1 from 2 (the root is in (1, 2) and the function convex there).
    let mut phi = 2.0_f64;
    for _ in 0..50 {
        phi -= (phi.powf(d + 1.0) - phi - 1.0) / ((d + 1.0) * phi.powf(d) - 1.0);
    }
    let alpha: Vec<f64> = (1..=dim).map(|i| phi.powi(-(i as i32))).collect();
    (1..=n).map(|k| alpha.iter().map(|a| (0.5 + k as f64 * a).fract()).collect()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::space::{ParameterSpec, Scale};

    #[test]
    fn spread_points_fill_every_dimension_evenly() {
        for dim in [1, 2, 5, 10] {
            let points = spread_points(64, dim);
            assert_eq!(points.len(), 64);
            for i in 0..dim {
                // Each coordinate visits every eighth of its range 8 ± 3 times in 64 points.
                let mut bins = [0; 8];
                for p in &points {
                    assert!((0.0..1.0).contains(&p[i]), "{p:?}");
                    bins[(p[i] * 8.0) as usize] += 1;
                }
                assert!(bins.iter().all(|&b| (5..=11).contains(&b)), "dim {dim}, axis {i}: {bins:?}");
            }
        }
        assert_eq!(spread_points(5, 3), spread_points(5, 3), "no seed: the same points every time");
    }

    /// Two basins: a wide, shallow one around the start (0.2, 0.2) and a narrow, deep one at
    /// (0.8, 0.7) that a local search from the start does not see (its minimum is -1).
    fn two_basins(x: &[f64]) -> f64 {
        let r2 = |c: (f64, f64), w: f64| ((x[0] - c.0).powi(2) + (x[1] - c.1).powi(2)) / (w * w);
        1.0 - 0.5 * (-r2((0.2, 0.2), 0.3)).exp() - 2.0 * (-r2((0.8, 0.7), 0.1)).exp()
    }

    fn search(prescreen: usize) -> SearchResult {
        let spec =
            |start| ParameterSpec { min: 0.0, max: 1.0, scale: Scale::Linear, start: Some(start), integer: false };
        let params =
            vec![Parameter::from_spec("a", &spec(0.2)).unwrap(), Parameter::from_spec("b", &spec(0.2)).unwrap()];
        let dir = tempfile::tempdir().unwrap();
        let keys = vec!["a".to_string(), "b".to_string()];
        let (log, _) = EvalLog::open(&dir.path().join("evaluations.jsonl"), "test", &keys, false).unwrap();
        let budget = Budget { evaluations: 120, step: 0.1, prescreen, ..Budget::default() };
        minimize(&params, &budget, Some(2), log, Vec::new(), "test", |x| Evaluation {
            objective: two_basins(x),
            failed: false,
            detail: serde_json::Value::Null,
        })
        .unwrap()
    }

    #[test]
    fn a_prescreen_finds_the_narrow_basin_a_local_search_from_the_start_misses() {
        let local = search(0);
        assert!(local.best[0] < 0.5, "without a prescreen the search stays by its start: {:?}", local.best);
        let screened = search(40);
        let objective = screened.best_record.as_ref().and_then(EvalRecord::exact_objective).unwrap();
        assert!((screened.best[0] - 0.8).abs() < 0.02 && (screened.best[1] - 0.7).abs() < 0.02, "{:?}", screened.best);
        assert!(objective < -0.99, "{objective}");
        assert!(screened.history.len() <= 120, "the prescreen is part of the budget: {}", screened.history.len());
    }

    #[test]
    fn a_prescreen_as_large_as_the_budget_is_refused() {
        let budget = Budget { evaluations: 10, prescreen: 10, ..Budget::default() };
        let (key, reason) = budget.check().unwrap();
        assert_eq!(key, "budget.prescreen");
        assert!(reason.contains("below budget.evaluations"), "{reason}");
    }
}
