//! `tendril tune`: the fit's search pointed at the controller. Each candidate (gains, setpoint, the
//! controller's own keys) runs a scenario across the listed seeds and disturbances; its objective
//! weighs what the run summary measures: held or not, the largest fluctuation while moving, the rise
//! time, the overshoot and the peak force. Each scenario (object) is tuned on its own, and with
//! `controller_types` each type is searched and the best kept.
//!
//! ```toml
//! scenarios = ["../crimper.toml", "../hammer.toml"]   # relative to this file
//! seeds = [1, 2]                                      # default: each scenario's own
//! controller_types = ["pid", "feedforward"]           # optional: search each, keep the best
//! [[disturbances]]                                    # optional override sets; default: none
//! "disturbance.push.force_n" = 2.0
//! [parameters."controller.kp"]
//! min = 5.0
//! max = 80.0
//! scale = "log"
//! [objective]                                         # optional; these are the defaults
//! not_held = 1.0               # per run that does not hold the object
//! max_fluctuation_pct = 0.01   # per % of the setpoint (a run that held nothing: 100 %)
//! rise_time_90_s = 0.05        # per s (a run that never reaches 90 %: its grasp time)
//! overshoot_pct = 0.002        # per %
//! peak_force_n = 0.0           # per N of the largest force while holding
//! [budget]                    # the fit's keys (src/fit/optimizer.rs): population, step, seed,
//! evaluations = 60             # tolerance, prescreen
//! ```

use super::execute::{LOG_FILE, fnv, simulate};
use super::log::EvalLog;
use super::optimizer::{Budget, Evaluation, FAILED, minimize};
use super::space::{Parameter, ParameterSpec};
use super::spec::{invalid, read_spec};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use tendril_config::{Overlay, Override, ScenarioError};
use tendril_run::runner::RunReport;
use tendril_run::summary::RunSummary;

/// The objective's weights (`[objective]` in TUNE.toml).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TuneWeights {
    /// Cost of a run that does not hold the object.
    pub not_held: f64,
    /// Per % of the largest fluctuation while the arm moves.
    pub max_fluctuation_pct: f64,
    /// Per s of rise time to 90 %.
    pub rise_time_90_s: f64,
    /// Per % of overshoot.
    pub overshoot_pct: f64,
    /// Per N of the largest force while holding.
    pub peak_force_n: f64,
}

impl Default for TuneWeights {
    fn default() -> TuneWeights {
        TuneWeights {
            not_held: 1.0,
            max_fluctuation_pct: 0.01,
            rise_time_90_s: 0.05,
            overshoot_pct: 0.002,
            peak_force_n: 0.0,
        }
    }
}

impl TuneWeights {
    fn check(&self) -> Option<(String, String)> {
        let all = [
            ("not_held", self.not_held),
            ("max_fluctuation_pct", self.max_fluctuation_pct),
            ("rise_time_90_s", self.rise_time_90_s),
            ("overshoot_pct", self.overshoot_pct),
            ("peak_force_n", self.peak_force_n),
        ];
        if let Some((k, w)) = all.iter().find(|(_, w)| !(w.is_finite() && *w >= 0.0)) {
            return Some((format!("objective.{k}"), format!("must be a finite number >= 0, got {w}")));
        }
        (all.iter().map(|(_, w)| w).sum::<f64>() <= 0.0)
            .then(|| ("objective".into(), "every weight is 0: nothing to tune".into()))
    }

    /// One run's cost.
    pub fn score(&self, s: &RunSummary, report: &RunReport, grasp_s: f64) -> f64 {
        let peak = report.rows.iter().filter(|r| r.phase.holding()).map(|r| r.force_n).fold(0.0, f64::max);
        self.not_held * f64::from(u8::from(s.outcome != "held"))
            + self.max_fluctuation_pct * s.metrics.max_fluctuation_pct.unwrap_or(100.0)
            + self.rise_time_90_s * s.metrics.rise_time_90_s.unwrap_or(grasp_s)
            + self.overshoot_pct * s.metrics.overshoot_pct
            + self.peak_force_n * peak
    }
}

/// TUNE.toml as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TuneFile {
    /// Scenario files, relative to the tune file; each is tuned on its own.
    pub scenarios: Vec<PathBuf>,
    /// Seeds every candidate runs (default: the scenario's own).
    #[serde(default)]
    pub seeds: Vec<u64>,
    /// Controller types to search (default: the scenario's own).
    #[serde(default)]
    pub controller_types: Vec<String>,
    /// Override sets every candidate runs under (default: one, with none).
    #[serde(default)]
    pub disturbances: Vec<BTreeMap<String, toml::Value>>,
    /// Scenario key → bounds.
    pub parameters: BTreeMap<String, ParameterSpec>,
    /// Weights.
    #[serde(default)]
    pub objective: TuneWeights,
    /// Budget of each search.
    #[serde(default = "tune_budget")]
    pub budget: Budget,
}

fn tune_budget() -> Budget {
    Budget { evaluations: 60, ..Budget::default() }
}

/// One scenario of a tune, read with the overlay.
#[derive(Debug, Clone)]
pub struct TuneScenario {
    /// The scenario file.
    pub file: PathBuf,
    /// Its name (the file's stem), the folder of its results.
    pub name: String,
    /// Its table with the overlay applied.
    pub table: toml::Table,
    /// Its grasp time \[s\] (the rise-time penalty of a run that never rises).
    pub grasp_s: f64,
    /// Its object's class (the label the summary names it by), the row of `table.toml`.
    pub object: String,
    /// Its setpoint \[N\], which `table.toml` records with the tuned keys.
    pub setpoint_n: f64,
}

/// A tune, loaded and checked.
#[derive(Debug, Clone)]
pub struct Tune {
    /// The tune file.
    pub file: PathBuf,
    /// The scenarios.
    pub scenarios: Vec<TuneScenario>,
    /// Seeds (empty: each scenario's own).
    pub seeds: Vec<u64>,
    /// Types searched (empty: each scenario's own).
    pub types: Vec<String>,
    /// Override sets, at least one (possibly empty).
    pub disturbances: Vec<Vec<Override>>,
    /// The parameters.
    pub params: Vec<Parameter>,
    /// The weights.
    pub weights: TuneWeights,
    /// The budget of each search.
    pub budget: Budget,
}

impl Tune {
    /// The override sets one candidate runs (every seed × disturbance), before its values.
    fn cases(&self, controller_type: Option<&str>) -> Vec<Vec<Override>> {
        let seeds: Vec<Option<u64>> =
            if self.seeds.is_empty() { vec![None] } else { self.seeds.iter().copied().map(Some).collect() };
        let mut cases = Vec::new();
        for seed in &seeds {
            for d in &self.disturbances {
                let mut o = d.clone();
                o.extend(seed.map(|s| Override { key: "seed".into(), value: tendril_config::seed::to_toml(s) }));
                o.extend(
                    controller_type
                        .map(|t| Override { key: "controller.type".into(), value: toml::Value::String(t.into()) }),
                );
                cases.push(o);
            }
        }
        cases
    }
}

/// Reads and checks a tune file; `overlay` is applied to every scenario (after the file).
pub fn load_tune(file: &Path, overlay: &Overlay) -> Result<Tune, ScenarioError> {
    let spec: TuneFile = read_spec(file)?;
    if spec.scenarios.is_empty() {
        return Err(invalid(file, ("scenarios".into(), "lists no scenario".into())));
    }
    if let Some(bad) = spec.objective.check() {
        return Err(invalid(file, bad));
    }
    if let Some(bad) = spec.budget.check() {
        return Err(invalid(file, bad));
    }
    for t in &spec.controller_types {
        if !tendril_control::ControllerConfig::TYPES.contains(&t.as_str()) {
            return Err(invalid(
                file,
                (
                    "controller_types".into(),
                    format!("unknown type `{t}` (expected one of {:?})", tendril_control::ControllerConfig::TYPES),
                ),
            ));
        }
    }
    let params = super::space::parameters(file, &spec.parameters)?;
    if let Some(p) = params.iter().find(|p| p.scope().is_some()) {
        return Err(invalid(
            file,
            (
                format!("parameters.\"{}\"", p.key),
                "a scoped key (NAME:KEY) is a fit's; a tune searches each scenario on its own".into(),
            ),
        ));
    }
    let base = file.parent().unwrap_or(Path::new(""));
    let mut scenarios = Vec::new();
    for path in &spec.scenarios {
        let path = base.join(path);
        let text = tendril_config::read_text(&path)?;
        let mut table: toml::Table = text
            .parse()
            .map_err(|e: toml::de::Error| ScenarioError::Syntax { file: path.clone(), message: e.to_string() })?;
        tendril_config::apply_overrides(&mut table, &overlay.overrides)?;
        let scenario: tendril_run::scenario::PickPlaceScenario =
            tendril_config::from_table(table.clone(), &path).map_err(|e| overlay.attribute(e, &[]))?;
        let name = path
            .file_stem()
            .map_or_else(|| "scenario".into(), |s| tendril_run::output::sanitize_component(&s.to_string_lossy()));
        if scenarios.iter().any(|s: &TuneScenario| s.name == name) {
            return Err(invalid(
                file,
                ("scenarios".into(), format!("two scenarios named `{name}`: each needs its own results folder")),
            ));
        }
        scenarios.push(TuneScenario {
            file: path,
            name,
            table,
            grasp_s: scenario.task.grasp_s,
            object: scenario.object.label(),
            setpoint_n: scenario.setpoint_n,
        });
    }
    let disturbances: Vec<Vec<Override>> = if spec.disturbances.is_empty() {
        vec![Vec::new()]
    } else {
        spec.disturbances
            .iter()
            .map(|d| d.iter().map(|(k, v)| Override { key: k.clone(), value: v.clone() }).collect())
            .collect()
    };
    let tune = Tune {
        file: file.into(),
        scenarios,
        seeds: spec.seeds,
        types: spec.controller_types,
        disturbances,
        params,
        weights: spec.objective,
        budget: spec.budget,
    };
    // Every case (seed, disturbance, type) must make a valid scenario, and every bound a valid value.
    let types: Vec<Option<&str>> =
        if tune.types.is_empty() { vec![None] } else { tune.types.iter().map(|t| Some(t.as_str())).collect() };
    let mut tables = Vec::new();
    for s in &tune.scenarios {
        for t in &types {
            for (i, case) in tune.cases(*t).iter().enumerate() {
                let mut table = s.table.clone();
                let checked = tendril_config::apply_overrides(&mut table, case).and_then(|()| {
                    tendril_config::from_table::<tendril_run::scenario::PickPlaceScenario>(table.clone(), &s.file)
                });
                if let Err(e) = checked {
                    return Err(invalid(
                        file,
                        ("disturbances".into(), format!("case {i} ({case:?}) is not a valid scenario: {e}")),
                    ));
                }
                tables.push((s.file.clone(), table));
            }
        }
    }
    let refs: Vec<(&Path, &toml::Table)> = tables.iter().map(|(f, t)| (f.as_path(), t)).collect();
    super::space::check_bounds(file, &tune.params, &refs)?;
    Ok(tune)
}

/// One search's result: a scenario, a controller type.
#[derive(Debug, Clone, Serialize)]
pub struct TuneResult {
    /// Scenario name.
    pub scenario: String,
    /// Controller type searched (None: the scenario's own).
    pub controller_type: Option<String>,
    /// Best values, by key.
    pub best: BTreeMap<String, f64>,
    /// Best objective.
    pub objective: f64,
    /// Objective at the start values.
    pub start_objective: Option<f64>,
    /// The best candidate's runs: outcome, fluctuation, rise time, overshoot per case.
    pub best_detail: serde_json::Value,
    /// Evaluations used.
    pub evaluations: usize,
    /// Why the search ended.
    pub stop: String,
    /// Wall time \[s\].
    pub wall_time_s: f64,
}

/// Scores a candidate on every case of `scenario`: the mean cost; a run that ends in error fails
/// the candidate.
fn evaluate(tune: &Tune, scenario: &TuneScenario, cases: &[Vec<Override>], values: &[f64]) -> Evaluation {
    let runs: Vec<serde_json::Value> = cases
        .par_iter()
        .map(|case| {
            let mut o = case.clone();
            o.extend(tune.params.iter().zip(values).map(|(p, &v)| p.override_at(v)));
            match simulate(&scenario.table, &scenario.file, &o) {
                Ok((s, report)) if s.outcome != "error" => {
                    let cost = tune.weights.score(&s, &report, scenario.grasp_s);
                    serde_json::json!({
                        "seed": s.run.seed, "outcome": s.outcome, "drop_phase": s.drop_phase,
                        "max_fluctuation_pct": s.metrics.max_fluctuation_pct, "rise_time_90_s": s.metrics.rise_time_90_s,
                        "overshoot_pct": s.metrics.overshoot_pct, "cost": cost,
                    })
                }
                Ok((s, _)) => serde_json::json!({ "seed": s.run.seed, "outcome": "error", "error": s.error }),
                Err(e) => serde_json::json!({ "outcome": "error", "error": format!("{e:#}") }),
            }
        })
        .collect();
    let costs: Vec<f64> = runs.iter().filter_map(|r| r["cost"].as_f64()).collect();
    let failed = costs.len() < runs.len();
    let objective = if failed { FAILED } else { costs.iter().sum::<f64>() / costs.len() as f64 };
    Evaluation { objective, failed, detail: serde_json::json!({ "runs": runs }) }
}

/// One object's row of `table.toml`: its setpoint (unless tuned) and the best values of the
/// keys a table may hold (`setpoint_n`, `controller.*`), with the type that won.
fn table_row(tune: &Tune, scenario: &TuneScenario, values: &[f64], t: Option<&str>) -> toml::Table {
    let mut row = toml::Table::new();
    row.insert("setpoint_n".into(), toml::Value::Float(scenario.setpoint_n));
    for (p, &v) in tune.params.iter().zip(values) {
        if p.key == "setpoint_n" || p.key.starts_with("controller.") {
            // Six significant digits: the search's last bits (79.99999999999997) are no setting.
            let value = match p.toml_value(v) {
                toml::Value::Float(f) if f != 0.0 && f.is_finite() => {
                    let scale = 10f64.powi(5 - f.abs().log10().floor() as i32);
                    toml::Value::Float((f * scale).round() / scale)
                }
                other => other,
            };
            row.insert(p.key.clone(), value);
        }
    }
    if let Some(t) = t {
        row.insert("controller.type".into(), toml::Value::String(t.into()));
    }
    row
}

/// Runs every search of the tune into `out_dir/<scenario>/` (`out_dir/<scenario>/<type>/` with
/// `controller_types`); writes each scenario's best as `out_dir/<scenario>/overlay.toml`, a
/// landscape chart per search, `out_dir/tune.json`, and `out_dir/table.toml`, the per-object table
/// a `[detector]` chooses settings from (each object's setpoint and best keys, by its class).
pub fn run_tune(
    tune: &Tune,
    out_dir: &Path,
    threads: Option<usize>,
    resume: bool,
) -> anyhow::Result<(Vec<TuneResult>, Vec<PathBuf>)> {
    let mut results = Vec::new();
    let mut written = Vec::new();
    let mut table = toml::Table::new();
    let types: Vec<Option<&str>> =
        if tune.types.is_empty() { vec![None] } else { tune.types.iter().map(|t| Some(t.as_str())).collect() };
    for scenario in &tune.scenarios {
        let mut best_of_scenario: Option<(f64, Vec<f64>, Option<&str>)> = None;
        for &t in &types {
            if tendril_cell::interrupt::requested().is_some() {
                break;
            }
            let dir = match t {
                Some(t) => out_dir.join(&scenario.name).join(t),
                None => out_dir.join(&scenario.name),
            };
            std::fs::create_dir_all(&dir).map_err(|e| anyhow::anyhow!("{}: cannot create: {e}", dir.display()))?;
            let cases = tune.cases(t);
            let keys: Vec<String> = tune.params.iter().map(|p| p.key.clone()).collect();
            let id = fnv(&[
                format!("{:?}", tune.params).into_bytes(),
                format!("{:?}", tune.weights).into_bytes(),
                format!("{:?}", tune.budget).into_bytes(),
                format!("{cases:?}").into_bytes(),
                toml::to_string(&scenario.table).unwrap_or_default().into_bytes(),
            ]);
            let (log, previous) = EvalLog::open(&dir.join(LOG_FILE), &id, &keys, resume)?;
            let label = format!("tune {}{}", scenario.name, t.map_or(String::new(), |t| format!(" {t}")));
            let result = minimize(&tune.params, &tune.budget, threads, log, previous, &label, |x| {
                evaluate(tune, scenario, &cases, x)
            })?;
            let objective = result.best_record.as_ref().and_then(|r| r.exact_objective()).unwrap_or(FAILED);
            let start: Vec<f64> = tune.params.iter().map(|p| p.start).collect();
            let start_objective = result
                .history
                .iter()
                .find(|r| r.exact_values().is_some_and(|v| super::space::same_point(&v, &start)))
                .and_then(|r| r.exact_objective());
            // The landscape over the first two parameters (the first against the objective with one).
            let (ix, iy) = (0, usize::from(tune.params.len() > 1));
            let points = result
                .history
                .iter()
                .map(|r| {
                    let y = if tune.params.len() > 1 { r.values[iy] } else { r.exact_objective().unwrap_or(FAILED) };
                    (r.values[ix], y, r.exact_objective().unwrap_or(FAILED), r.failed)
                })
                .collect();
            let chart = tendril_plot::fit::LandscapeChart {
                title: format!("{label}: objective landscape, {} evaluations", result.history.len()),
                axes: (
                    tune.params[ix].key.clone(),
                    if tune.params.len() > 1 { tune.params[iy].key.clone() } else { "objective".into() },
                ),
                log: (
                    tune.params[ix].scale == super::space::Scale::Log,
                    tune.params.len() > 1 && tune.params[iy].scale == super::space::Scale::Log,
                ),
                points,
                best: result.best_record.as_ref().map(|r| {
                    (
                        r.values[ix],
                        if tune.params.len() > 1 { r.values[iy] } else { r.exact_objective().unwrap_or(FAILED) },
                    )
                }),
            };
            written.extend(tendril_plot::save(&chart, &dir, "landscape")?);
            if best_of_scenario.as_ref().is_none_or(|b| objective < b.0) && result.best_record.is_some() {
                best_of_scenario = Some((objective, result.best.clone(), t));
            }
            results.push(TuneResult {
                scenario: scenario.name.clone(),
                controller_type: t.map(String::from),
                best: tune.params.iter().zip(&result.best).map(|(p, &v)| (p.key.clone(), v)).collect(),
                objective,
                start_objective,
                best_detail: result.best_record.as_ref().map_or(serde_json::Value::Null, |r| r.detail.clone()),
                evaluations: result.history.len(),
                stop: result.stop.clone(),
                wall_time_s: result.wall_time_s,
            });
        }
        if let Some((objective, values, t)) = best_of_scenario {
            let path = out_dir.join(&scenario.name).join("overlay.toml");
            let which = t.map_or(String::new(), |t| format!(" ({t})"));
            super::write_overlay(
                &path,
                &format!(
                    "tendril tune {}: best for {}{which}, objective {objective:.5}",
                    tune.file.display(),
                    scenario.name
                ),
                &tune.params,
                &values,
            )?;
            if let Some(t) = t {
                let text = std::fs::read_to_string(&path)? + &format!("\"controller.type\" = \"{t}\"\n");
                super::write_text(&path, &text)?;
            }
            written.push(path);
            table.insert(scenario.object.clone(), toml::Value::Table(table_row(tune, scenario, &values, t)));
        }
    }
    if !table.is_empty() {
        let path = out_dir.join("table.toml");
        let mut file = toml::Table::new();
        file.insert("classes".into(), toml::Value::Table(table));
        let text = format!(
            "# tendril tune {}: each object's setpoint and best keys, by its class: the table a scenario's\n\
             # [detector] chooses settings from (`table = \"{}\"`).\n{}",
            tune.file.display(),
            path.display(),
            toml::to_string(&file)?
        );
        super::write_text(&path, &text)?;
        written.push(path);
    }
    let json = out_dir.join("tune.json");
    super::write_text(&json, &(serde_json::to_string_pretty(&results)? + "\n"))?;
    written.push(json);
    Ok((results, written))
}
