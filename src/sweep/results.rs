//! `results.csv`: one row per finished run, appended as runs finish so that a killed sweep
//! keeps everything it finished; read back for `--resume` and merged across shards.

use super::durable::ResultsError;
use super::spec::{Sweep, SweepRun};
use crate::run::summary::RunSummary;
use std::path::Path;

/// The summary's fields as flat (column, value) pairs; nested objects become dotted columns.
pub fn flatten_summary(summary: &RunSummary) -> Vec<(String, String)> {
    fn walk(prefix: &str, value: &serde_json::Value, out: &mut Vec<(String, String)>) {
        match value {
            serde_json::Value::Object(map) => {
                for (k, v) in map {
                    let name = if prefix.is_empty() { k.clone() } else { format!("{prefix}.{k}") };
                    walk(&name, v, out);
                }
            }
            serde_json::Value::Null => out.push((prefix.to_string(), String::new())),
            serde_json::Value::String(s) => out.push((prefix.to_string(), s.clone())),
            // A list of messages (the MuJoCo warnings) is one cell.
            serde_json::Value::Array(items) => out.push((
                prefix.to_string(),
                items
                    .iter()
                    .map(|v| v.as_str().map_or_else(|| v.to_string(), str::to_string))
                    .collect::<Vec<_>>()
                    .join("; "),
            )),
            other => out.push((prefix.to_string(), other.to_string())),
        }
    }
    let mut out = Vec::new();
    walk("", &serde_json::to_value(summary).expect("summaries serialise"), &mut out);
    out
}

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
    r.extend(flatten_summary(summary).into_iter().map(|(_, v)| v));
    r.into_iter().map(one_line).collect()
}

/// Merges shard files into `out`: one header, rows sorted by run id, duplicates dropped.
/// Every input is checked as `--resume` checks it ([`super::durable::scan`]): a torn header or last
/// line, a row that is not whole, or rows of another sweep (another `sweep_id`) refuse the merge.
/// The merged file is written beside `out` and renamed over it, so a failed merge leaves no
/// half-written `out`. Returns the number of rows written.
pub fn merge(inputs: &[&Path], out: &Path) -> Result<usize, ResultsError> {
    let mut header: Option<(String, &Path)> = None;
    let mut sweep: Option<(String, &Path)> = None;
    let mut rows: std::collections::BTreeMap<usize, String> = Default::default();
    for input in inputs {
        let bytes = super::durable::read_regular(input)?;
        let scan = super::durable::scan(&bytes, input)?;
        if let Some(torn) = scan.torn_tail {
            return Err(ResultsError::TornLastLine { file: input.to_path_buf(), bytes: torn.len });
        }
        match &header {
            None => header = Some((scan.header.clone(), input)),
            Some((first, first_file)) if *first != scan.header => {
                return Err(ResultsError::HeaderMismatch {
                    file: input.to_path_buf(),
                    first: first_file.to_path_buf(),
                });
            }
            _ => {}
        }
        for r in scan.rows {
            match &sweep {
                None => sweep = Some((r.sweep_id.clone(), input)),
                Some((id, first_file)) if *id != r.sweep_id => {
                    return Err(ResultsError::ForeignSweep {
                        file: input.to_path_buf(),
                        line: r.line,
                        found: r.sweep_id,
                        expected: format!("{id} (the sweep of {})", first_file.display()),
                    });
                }
                _ => {}
            }
            rows.entry(r.run_id).or_insert(r.text);
        }
    }
    let mut text = header.map(|(h, _)| h + "\n").unwrap_or_default();
    for line in rows.values() {
        text += line;
        text.push('\n');
    }
    super::durable::write_atomically(out, text.as_bytes())?;
    Ok(rows.len())
}
