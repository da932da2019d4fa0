//! The columns of `results.csv`: what identifies a run (its id, the sweep's id, the scenario file,
//! the swept keys) and the summary's fields after them.

use super::spec::{Sweep, SweepRun};
use std::path::Path;
use tendril_run::summary::RunSummary;

/// Renders a swept value for a cell: strings bare, everything else as TOML writes it.
fn value_text(v: &toml::Value) -> String {
    match v {
        toml::Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

/// Name of the column that holds [`sweep_id`] on every row.
pub const SWEEP_ID_COLUMN: &str = "sweep_id";

/// Columns at the start of every row that identify its run: `run_id`, `sweep_id`, `scenario_file`,
/// then the swept keys (see [`header`]).
pub fn identity_columns(sweep: &Sweep) -> usize {
    3 + sweep.keys.len()
}

/// The sweep's identity: 16 hex digits of a 64-bit FNV-1a hash of its expanded run list (each
/// run's id, scenario file name and overrides, and the `--overlay`'s keys and values when there is
/// one). Every row carries it, so `--resume` and `merge`
/// refuse rows from another sweep whose columns happen to match. Scenario files are named by
/// file name only, so resuming from another working directory is the same sweep.
pub fn sweep_id(sweep: &Sweep) -> String {
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    let mut feed = |bytes: &[u8]| {
        for b in bytes.iter().chain([&0u8]) {
            hash ^= u64::from(*b);
            hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
        }
    };
    for run in &sweep.runs {
        feed(run.id.to_string().as_bytes());
        feed(scenario_name(&run.scenario).as_bytes());
        for o in &run.overrides {
            feed(o.key.as_bytes());
            feed(o.value.to_string().as_bytes());
        }
    }
    for o in &sweep.overlay.overrides {
        feed(o.key.as_bytes());
        feed(o.value.to_string().as_bytes());
    }
    format!("{hash:016x}")
}

/// A scenario file as compared between rows: its file name.
pub fn scenario_name(path: &Path) -> String {
    path.file_name().map_or_else(|| path.display().to_string(), |n| n.to_string_lossy().to_string())
}

/// The header of a sweep's results file.
pub fn header(sweep: &Sweep, summary_columns: &[String]) -> Vec<String> {
    let mut h = vec!["run_id".to_string(), SWEEP_ID_COLUMN.to_string(), "scenario_file".to_string()];
    h.extend(sweep.keys.iter().cloned());
    h.extend(summary_columns.iter().cloned());
    h
}

/// The identity cells of `run`'s row (the first [`identity_columns`]).
pub fn identity_cells(sweep: &Sweep, id: &str, run: &SweepRun) -> Vec<String> {
    let mut r = vec![run.id.to_string(), id.to_string(), run.scenario.display().to_string()];
    for key in &sweep.keys {
        r.push(run.overrides.iter().find(|o| &o.key == key).map(|o| value_text(&o.value)).unwrap_or_default());
    }
    r.into_iter().map(one_line).collect()
}

/// A cell on one line: line breaks become spaces (see [`row`]).
fn one_line(cell: String) -> String {
    if cell.contains(['\n', '\r']) { cell.replace(['\n', '\r'], " ") } else { cell }
}

/// One results row for `run` of the sweep whose [`sweep_id`] is `id`. Line breaks inside cells
/// (an error message's) become spaces, so every row is exactly one line: a torn row is then
/// always recognisable as a last line without its newline.
pub fn row(sweep: &Sweep, id: &str, run: &SweepRun, summary: &RunSummary) -> Vec<String> {
    let mut r = identity_cells(sweep, id, run);
    r.extend(summary.cells());
    r.into_iter().map(one_line).collect()
}
