//! Running a fit: each candidate re-runs every recording's effective scenario (its seed, its
//! feedback mode) and every target's scenario (its feedback mode, each of its seeds) with the
//! candidate's values, and is scored against the recordings and the targets' figures; the best is
//! written as an overlay, a report and a chart.

use super::log::EvalLog;
use super::objective::{Residual, compare};
use super::optimizer::{Evaluation, FAILED, SearchResult, minimize};
use super::recording::{Events, Recording};
use super::spec::Fit;
use super::target::{Target, TargetResidual};
use rayon::prelude::*;
use serde::Serialize;
use std::path::{Path, PathBuf};
use tendril_config::Override;
use tendril_run::execute::{ModelCache, run_on_twin};
use tendril_run::runner::RunReport;
use tendril_run::scenario::PickPlaceScenario;
use tendril_run::summary::RunSummary;

/// Name of the evaluations log in a fit's or tune's output folder.
pub const LOG_FILE: &str = "evaluations.jsonl";

/// Runs `base` (a scenario table) with `overrides` on the twin, without writing files. `file` is
/// only used in messages.
pub fn simulate(base: &toml::Table, file: &Path, overrides: &[Override]) -> anyhow::Result<(RunSummary, RunReport)> {
    let mut table = base.clone();
    tendril_config::apply_overrides(&mut table, overrides)?;
    let scenario: PickPlaceScenario = tendril_config::from_table(table, file)?;
    // A model per run: candidates differ in the scene's parameters, so nothing would be shared.
    run_on_twin(&scenario, &ModelCache::default(), None)
}

/// The overrides `values` make for the run named `name` (scoped parameters apply to their own).
fn overrides_for(fit: &Fit, name: &str, values: &[f64]) -> Vec<Override> {
    fit.params.iter().zip(values).filter(|(p, _)| p.applies_to(name)).map(|(p, &v)| p.override_at(v)).collect()
}

/// One recording re-run with `values` and compared with it; `None` rows when the run could not
/// start.
pub fn replay(fit: &Fit, r: &Recording, values: &[f64]) -> (Residual, Option<RunReport>) {
    match simulate(&r.table, &r.source, &overrides_for(fit, &r.name, values)) {
        Ok((summary, report)) => {
            let residual = compare(&r.name, &r.ticks, &r.events, &report.rows, &Events::of(&summary), &fit.weights);
            (residual, Some(report))
        }
        Err(e) => (
            Residual {
                recording: r.name.clone(),
                force_rmse_n: None,
                smoothed_rmse_n: None,
                twine_motor_rmse_rad: None,
                drop_time_error_s: None,
                same_outcome: false,
                outcome: format!("error: {e:#}"),
                drop_phase: None,
                drop_time_s: None,
                score: FAILED,
            },
            None,
        ),
    }
}

/// One target's run with `seed` and `values`, scored against its figures; `None` rows when the
/// run could not start.
pub fn replay_target(fit: &Fit, t: &Target, seed: u64, values: &[f64]) -> (TargetResidual, Option<RunReport>) {
    let mut overrides = vec![Override { key: "seed".into(), value: toml::Value::Integer(seed as i64) }];
    overrides.extend(overrides_for(fit, &t.name, values));
    match simulate(&t.table, &t.file, &overrides) {
        Ok((summary, report)) => (t.compare(seed, &summary, &report), Some(report)),
        Err(e) => (
            TargetResidual {
                target: t.label(seed),
                outcome: format!("error: {e:#}"),
                score: FAILED,
                ..TargetResidual::default()
            },
            None,
        ),
    }
}

/// Every run of a candidate: the recordings' and the targets' (each seed), run in parallel.
pub struct Replays {
    /// Per recording.
    pub recordings: Vec<(Residual, Option<RunReport>)>,
    /// Per target and seed, in the fit file's order.
    pub targets: Vec<(TargetResidual, Option<RunReport>)>,
}

impl Replays {
    /// Runs them all with `values`.
    pub fn run(fit: &Fit, values: &[f64]) -> Replays {
        // One parallel loop over every run, so a slow recording does not idle a thread the
        // targets could use.
        enum Job<'a> {
            Recording(&'a Recording),
            Target(&'a Target, u64),
        }
        enum Done {
            Recording((Residual, Option<RunReport>)),
            Target((TargetResidual, Option<RunReport>)),
        }
        let jobs: Vec<Job> = fit
            .recordings
            .iter()
            .map(Job::Recording)
            .chain(fit.targets.iter().flat_map(|t| t.spec.seeds.iter().map(move |&s| Job::Target(t, s))))
            .collect();
        let done: Vec<Done> = jobs
            .par_iter()
            .map(|j| match j {
                Job::Recording(r) => Done::Recording(replay(fit, r, values)),
                Job::Target(t, seed) => Done::Target(replay_target(fit, t, *seed, values)),
            })
            .collect();
        let mut out = Replays { recordings: Vec::new(), targets: Vec::new() };
        for d in done {
            match d {
                Done::Recording(r) => out.recordings.push(r),
                Done::Target(t) => out.targets.push(t),
            }
        }
        out
    }

    /// Whether a run failed to start or run.
    pub fn failed(&self) -> bool {
        self.recordings.iter().any(|(r, _)| r.outcome.starts_with("error"))
            || self.targets.iter().any(|(t, _)| t.outcome.starts_with("error"))
    }

    /// The mean of every run's score.
    pub fn objective(&self) -> f64 {
        let scores: Vec<f64> =
            self.recordings.iter().map(|(r, _)| r.score).chain(self.targets.iter().map(|(t, _)| t.score)).collect();
        scores.iter().sum::<f64>() / scores.len().max(1) as f64
    }
}

/// Scores a candidate: the mean of its runs' scores (recordings and target seeds); any run that
/// fails makes it a failed candidate ([`FAILED`]), and the fit goes on.
pub fn evaluate(fit: &Fit, values: &[f64]) -> Evaluation {
    let replays = Replays::run(fit, values);
    let failed = replays.failed();
    let objective = if failed { FAILED } else { replays.objective() };
    let residuals: Vec<&Residual> = replays.recordings.iter().map(|(r, _)| r).collect();
    let targets: Vec<&TargetResidual> = replays.targets.iter().map(|(t, _)| t).collect();
    Evaluation { objective, failed, detail: serde_json::json!({ "residuals": residuals, "targets": targets }) }
}

/// The identity of a fit, for its log: a 64-bit FNV-1a hash of the parameters, weights and budget,
/// of each target's figures and scenario, and of each recording's summary and trace.
pub fn search_id(fit: &Fit) -> String {
    let mut parts: Vec<Vec<u8>> = vec![
        format!("{:?}", fit.params).into_bytes(),
        format!("{:?}", fit.weights).into_bytes(),
        format!("{:?}", fit.budget).into_bytes(),
    ];
    for t in &fit.targets {
        parts.push(format!("{:?}", t.spec).into_bytes());
        parts.push(toml::to_string(&t.table).unwrap_or_default().into_bytes());
    }
    for r in &fit.recordings {
        parts.push(std::fs::read(&r.source).unwrap_or_default());
        parts.push(format!("{:?}", r.ticks).into_bytes());
    }
    fnv(&parts)
}

/// 16 hex digits of a 64-bit FNV-1a hash of `parts` (each followed by a 0 byte).
pub fn fnv(parts: &[Vec<u8>]) -> String {
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    for part in parts {
        for b in part.iter().chain([&0u8]) {
            hash ^= u64::from(*b);
            hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    format!("{hash:016x}")
}

/// One parameter's result in `fit.json`.
#[derive(Debug, Clone, Serialize)]
pub struct FittedParameter {
    /// Scenario key.
    pub key: String,
    /// Lower bound.
    pub min: f64,
    /// Upper bound.
    pub max: f64,
    /// Where the search started.
    pub start: f64,
    /// The best value found.
    pub best: f64,
}

/// `fit.json`.
#[derive(Debug, Clone, Serialize)]
pub struct FitReport {
    /// The fit file.
    pub fit_file: PathBuf,
    /// The parameters and their best values.
    pub parameters: Vec<FittedParameter>,
    /// The best objective.
    pub objective: f64,
    /// The objective at the start values.
    pub start_objective: Option<f64>,
    /// Each recording's residual at the best values.
    pub residuals: Vec<Residual>,
    /// Each target run's residual at the best values.
    pub targets: Vec<TargetResidual>,
    /// Evaluations used (including those taken from the log of an earlier session).
    pub evaluations: usize,
    /// Of those, evaluations taken from the log.
    pub reused: usize,
    /// Why the search ended.
    pub stop: String,
    /// Wall time of this session's search \[s\].
    pub wall_time_s: f64,
}

/// How to run a fit.
#[derive(Debug, Clone)]
pub struct FitOptions {
    /// Output folder.
    pub out_dir: PathBuf,
    /// Worker threads (default: all cores).
    pub threads: Option<usize>,
    /// Continue the search logged in the folder.
    pub resume: bool,
}

/// Runs the fit: the search (logged to `out_dir`/evaluations.jsonl), then the best re-run on every
/// recording; writes `overlay.toml`, `fit.json` and `fit.png`/`fit.svg`.
pub fn run_fit(fit: &Fit, options: &FitOptions) -> anyhow::Result<(FitReport, Vec<PathBuf>)> {
    std::fs::create_dir_all(&options.out_dir)
        .map_err(|e| anyhow::anyhow!("{}: cannot create: {e}", options.out_dir.display()))?;
    let keys: Vec<String> = fit.params.iter().map(|p| p.key.clone()).collect();
    let (log, previous) = EvalLog::open(&options.out_dir.join(LOG_FILE), &search_id(fit), &keys, options.resume)?;
    let result = minimize(&fit.params, &fit.budget, options.threads, log, previous, "fit", |x| evaluate(fit, x))?;
    let (report, written) = write_results(fit, &result, &options.out_dir, options.threads)?;
    Ok((report, written))
}

/// Re-runs the best candidate on every recording and writes the overlay, `fit.json` and the chart.
fn write_results(
    fit: &Fit,
    result: &SearchResult,
    out_dir: &Path,
    threads: Option<usize>,
) -> anyhow::Result<(FitReport, Vec<PathBuf>)> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads.unwrap_or(0)).build()?;
    // Stopped by a signal: the best candidate's residuals as logged (a replay would be cut short).
    let replays = if tendril_cell::interrupt::requested().is_some() {
        let logged = |key: &str| result.best_record.as_ref().map(|r| r.detail[key].clone());
        let recordings: Vec<Residual> =
            logged("residuals").and_then(|v| serde_json::from_value(v).ok()).unwrap_or_default();
        let targets: Vec<TargetResidual> =
            logged("targets").and_then(|v| serde_json::from_value(v).ok()).unwrap_or_default();
        Replays {
            recordings: recordings.into_iter().map(|r| (r, None)).collect(),
            targets: targets.into_iter().map(|t| (t, None)).collect(),
        }
    } else {
        pool.install(|| Replays::run(fit, &result.best))
    };
    let objective = result.best_record.as_ref().and_then(|r| r.exact_objective()).unwrap_or(FAILED);
    let start: Vec<f64> = fit.params.iter().map(|p| p.start).collect();
    let start_objective = result
        .history
        .iter()
        .find(|r| r.exact_values().is_some_and(|v| super::space::same_point(&v, &start)))
        .and_then(|r| r.exact_objective());
    let report = FitReport {
        fit_file: fit.file.clone(),
        parameters: fit
            .params
            .iter()
            .zip(&result.best)
            .map(|(p, &best)| FittedParameter { key: p.key.clone(), min: p.min, max: p.max, start: p.start, best })
            .collect(),
        objective,
        start_objective,
        residuals: replays.recordings.iter().map(|(r, _)| r.clone()).collect(),
        targets: replays.targets.iter().map(|(t, _)| t.clone()).collect(),
        evaluations: result.history.len(),
        reused: result.reused,
        stop: result.stop.clone(),
        wall_time_s: result.wall_time_s,
    };
    let mut written = Vec::new();
    let overlay = out_dir.join("overlay.toml");
    super::write_overlay(
        &overlay,
        &format!(
            "tendril fit {}: the best of {} evaluations, objective {objective:.6}",
            fit.file.display(),
            report.evaluations
        ),
        &fit.params,
        &result.best,
    )?;
    written.push(overlay);
    let json = out_dir.join("fit.json");
    super::write_text(&json, &(serde_json::to_string_pretty(&report)? + "\n"))?;
    written.push(json);
    let empty = (Residual::default(), None);
    let fitted = |rep: &Option<RunReport>| {
        rep.as_ref().map_or_else(Vec::new, |rep| rep.rows.iter().map(|t| (t.time_s, t.force_n)).collect())
    };
    let chart = tendril_plot::fit::FitChart {
        title: format!("tendril fit {}", fit.file.display()),
        traces: fit
            .recordings
            .iter()
            .zip(replays.recordings.iter().chain(std::iter::repeat(&empty)))
            .map(|(r, (res, rep))| tendril_plot::fit::TracePair {
                name: format!("{} (RMSE {})", r.name, res.force_rmse_n.map_or("-".into(), |v| format!("{v:.3} N"))),
                recorded: r.ticks.iter().map(|t| (t.time_s, t.force_n)).collect(),
                fitted: fitted(rep),
            })
            // A target has figures, not a trace: its panel shows the fitted run alone.
            .chain(replays.targets.iter().map(|(t, rep)| tendril_plot::fit::TracePair {
                name: format!("{} ({}, score {:.3})", t.target, t.outcome, t.score),
                recorded: Vec::new(),
                fitted: fitted(rep),
            }))
            .collect(),
        objective: result.history.iter().map(|r| (r.index, r.exact_objective().unwrap_or(FAILED), r.failed)).collect(),
    };
    written.extend(tendril_plot::save(&chart, out_dir, "fit")?);
    Ok((report, written))
}
