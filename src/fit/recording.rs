//! A recording: a run directory as `tendril run --out` writes it (`trace.csv` and `summary.json`
//! with the effective scenario), made by the twin or by the real cell.

use std::path::{Path, PathBuf};
use tendril_run::scenario::PickPlaceScenario;

/// Columns `trace.csv` must have, as `tendril run` writes them (the order may differ).
pub const REQUIRED_COLUMNS: [&str; 4] = ["time_s", "phase", "force_n", "twine_motor_rad"];

/// Why a recording cannot be used.
#[derive(Debug, thiserror::Error)]
#[error("{}: {reason}", file.display())]
pub struct RecordingError {
    /// The file at fault (`trace.csv`, `summary.json`, or the folder).
    pub file: PathBuf,
    /// What is wrong.
    pub reason: String,
}

/// One tick of a recorded trace, as far as a fit compares it.
#[derive(Debug, Clone, PartialEq)]
pub struct Tick {
    /// Cell time \[s\].
    pub time_s: f64,
    /// Task phase name.
    pub phase: String,
    /// Force estimate \[N\].
    pub force_n: f64,
    /// Twine motor position \[rad\] (the tendon wound in).
    pub twine_motor_rad: f64,
}

/// What happened in a run, as its summary says.
#[derive(Debug, Clone, PartialEq)]
pub struct Events {
    /// "held", "dropped" or "error".
    pub outcome: String,
    /// Time of the drop since activation \[s\].
    pub drop_cell_time_s: Option<f64>,
    /// Time of the drop after the arm started moving \[s\].
    pub drop_time_s: Option<f64>,
    /// Phase of the drop.
    pub drop_phase: Option<String>,
    /// Cell time covered \[s\].
    pub sim_time_s: f64,
}

impl Events {
    /// The events of a run's summary.
    pub fn of(s: &tendril_run::summary::RunSummary) -> Events {
        Events {
            outcome: s.outcome.clone(),
            drop_cell_time_s: s.drop_cell_time_s,
            drop_time_s: s.drop_time_s,
            drop_phase: s.drop_phase.clone(),
            sim_time_s: s.sim_time_s,
        }
    }
}

/// A recording read and checked.
#[derive(Debug, Clone)]
pub struct Recording {
    /// The run directory (or the bag).
    pub dir: PathBuf,
    /// The file its scenario came from (`summary.json`, or a bag's scenario file): what errors in
    /// its scenario name.
    pub source: PathBuf,
    /// A short name (the folder's name).
    pub name: String,
    /// The effective scenario, as a table that overrides apply to.
    pub table: toml::Table,
    /// The effective scenario, parsed.
    pub scenario: PickPlaceScenario,
    /// The recorded trace.
    pub ticks: Vec<Tick>,
    /// The recorded outcome.
    pub events: Events,
}

impl Recording {
    /// Reads `dir`/summary.json and `dir`/trace.csv and checks them against each other: the trace
    /// has the columns a run writes, its ticks come at the scenario's control rate, and the summary's
    /// setpoint, feedback and seed are the effective scenario's.
    pub fn read(dir: &Path) -> Result<Recording, RecordingError> {
        let err = |file: PathBuf, reason: String| RecordingError { file, reason };
        if !dir.is_dir() {
            return Err(err(dir.into(), "not a run directory (expected trace.csv and summary.json in it)".into()));
        }
        let summary_path = dir.join("summary.json");
        let text = std::fs::read_to_string(&summary_path)
            .map_err(|e| err(summary_path.clone(), format!("cannot read: {e}")))?;
        let mut json: serde_json::Value =
            serde_json::from_str(&text).map_err(|e| err(summary_path.clone(), format!("not valid JSON: {e}")))?;
        let effective = json.as_object_mut().and_then(|o| o.remove("effective_scenario")).ok_or_else(|| {
            err(summary_path.clone(), "no `effective_scenario`: not a summary `tendril run` wrote".into())
        })?;
        let summary: tendril_run::summary::RunSummary =
            serde_json::from_value(json).map_err(|e| err(summary_path.clone(), format!("not a run summary: {e}")))?;
        let scenario: PickPlaceScenario = serde_json::from_value(effective)
            .map_err(|e| err(summary_path.clone(), format!("`effective_scenario`: {e}")))?;
        let table = match toml::Value::try_from(&scenario) {
            Ok(toml::Value::Table(t)) => t,
            _ => return Err(err(summary_path.clone(), "`effective_scenario` cannot be written as TOML".into())),
        };
        // The effective scenario must itself be valid (a hand-edited summary may not be).
        let scenario: PickPlaceScenario = tendril_config::from_table(table.clone(), &summary_path)
            .map_err(|e| err(summary_path.clone(), format!("`effective_scenario`: {e}")))?;
        let mismatch = |what: &str, recorded: String, effective: String| {
            err(
                summary_path.clone(),
                format!(
                    "`{what}` is {recorded} but the effective scenario's is {effective}: the scenario does not match the run"
                ),
            )
        };
        if summary.run.setpoint_n != scenario.setpoint_n {
            return Err(mismatch("setpoint_n", summary.run.setpoint_n.to_string(), scenario.setpoint_n.to_string()));
        }
        if summary.run.feedback != scenario.feedback {
            return Err(mismatch("feedback", summary.run.feedback.to_string(), scenario.feedback.to_string()));
        }
        if summary.run.seed != scenario.seed {
            return Err(mismatch("seed", summary.run.seed.to_string(), scenario.seed.to_string()));
        }
        let ticks = read_trace(&dir.join("trace.csv"), scenario.control_rate_hz)?;
        let name = dir.file_name().map_or_else(|| dir.display().to_string(), |n| n.to_string_lossy().to_string());
        Ok(Recording {
            dir: dir.into(),
            source: summary_path,
            name,
            table,
            scenario,
            ticks,
            events: Events::of(&summary),
        })
    }
}

/// Reads the ticks of `trace.csv`, checking its columns and that its ticks are `1 / rate_hz` apart.
fn read_trace(path: &Path, rate_hz: f64) -> Result<Vec<Tick>, RecordingError> {
    let ticks = read_trace_columns(path)?;
    check_ticks(path, ticks, rate_hz)
}

/// The ticks of `trace.csv`'s columns.
fn read_trace_columns(path: &Path) -> Result<Vec<Tick>, RecordingError> {
    let err = |reason: String| RecordingError { file: path.into(), reason };
    let table = tendril_plot::input::Table::read(path).map_err(|e| err(e.to_string()))?;
    let mut cols = [0usize; 4];
    for (c, name) in cols.iter_mut().zip(REQUIRED_COLUMNS) {
        *c = table.header.iter().position(|h| h == name).ok_or_else(|| {
            err(format!(
                "no column `{name}`: the columns do not match a trace `tendril run` writes ({})",
                table.header.join(",")
            ))
        })?;
    }
    let mut ticks = Vec::with_capacity(table.rows.len());
    for (line, cells) in &table.rows {
        let number = |c: usize, name: &str| {
            cells[c]
                .parse::<f64>()
                .map_err(|_| err(format!("line {line}: column `{name}`: `{}` is not a number", cells[c])))
        };
        let time_s = number(cols[0], "time_s")?;
        let force_n = number(cols[2], "force_n")?;
        let twine_motor_rad = number(cols[3], "twine_motor_rad")?;
        if !time_s.is_finite() {
            return Err(err(format!("line {line}: column `time_s` is not finite")));
        }
        ticks.push(Tick { time_s, phase: cells[cols[1]].clone(), force_n, twine_motor_rad });
    }
    Ok(ticks)
}

/// `ticks` (read from `path`), checked: at least two, `1 / rate_hz` apart, time increasing.
pub fn check_ticks(path: &Path, ticks: Vec<Tick>, rate_hz: f64) -> Result<Vec<Tick>, RecordingError> {
    let err = |reason: String| RecordingError { file: path.into(), reason };
    if ticks.len() < 2 {
        return Err(err("fewer than two ticks: nothing to fit".into()));
    }
    // Ticks at the control rate: the median spacing within 1 % of 1 / rate.
    let mut steps: Vec<f64> = ticks.windows(2).map(|w| w[1].time_s - w[0].time_s).collect();
    steps.sort_by(f64::total_cmp);
    let median = steps[steps.len() / 2];
    let expected = 1.0 / rate_hz;
    if (median - expected).abs() > 0.01 * expected {
        return Err(err(format!(
            "ticks are {median} s apart but the effective scenario's control_rate_hz = {rate_hz} means {expected} s: the rates do not match"
        )));
    }
    if steps[0] <= 0.0 {
        return Err(err("time_s does not increase from row to row".into()));
    }
    Ok(ticks)
}
