//! `results.csv`: one row per finished run, appended as runs finish so that a killed sweep
//! keeps everything it finished; read back for `--resume` and merged across shards.

use super::spec::{Sweep, SweepRun};
use crate::run::summary::RunSummary;
use std::collections::BTreeSet;
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

/// The header of a sweep's results file.
pub fn header(sweep: &Sweep, summary_columns: &[String]) -> Vec<String> {
    let mut h = vec!["run_id".to_string(), "scenario_file".to_string()];
    h.extend(sweep.keys.iter().cloned());
    h.extend(summary_columns.iter().cloned());
    h
}

/// One results row for `run`.
pub fn row(sweep: &Sweep, run: &SweepRun, summary: &RunSummary) -> Vec<String> {
    let mut r = vec![run.id.to_string(), run.scenario.display().to_string()];
    for key in &sweep.keys {
        r.push(run.overrides.iter().find(|o| &o.key == key).map(|o| value_text(&o.value)).unwrap_or_default());
    }
    r.extend(flatten_summary(summary).into_iter().map(|(_, v)| v));
    r
}

/// Appends rows to a results file, writing the header when the file is new, flushing each row.
pub struct ResultsWriter {
    out: csv::Writer<std::fs::File>,
}

impl ResultsWriter {
    /// Opens `path` for appending; writes `header` if the file is empty.
    pub fn open(path: &Path, header: &[String]) -> std::io::Result<ResultsWriter> {
        let file = std::fs::OpenOptions::new().create(true).append(true).open(path)?;
        let fresh = file.metadata()?.len() == 0;
        let mut out = csv::WriterBuilder::new().from_writer(file);
        if fresh {
            out.write_record(header)?;
            out.flush()?;
        }
        Ok(ResultsWriter { out })
    }

    /// Appends one row and flushes it to the file.
    pub fn append(&mut self, row: &[String]) -> std::io::Result<()> {
        self.out.write_record(row)?;
        self.out.flush()
    }
}

/// The run ids already in a results file (none if it does not exist).
pub fn finished_ids(path: &Path) -> Result<BTreeSet<usize>, csv::Error> {
    if !path.exists() {
        return Ok(BTreeSet::new());
    }
    let mut reader = csv::Reader::from_path(path)?;
    let mut ids = BTreeSet::new();
    for record in reader.records() {
        // A row cut short by a kill is skipped: its run is simply done again.
        if let Ok(record) = record
            && let Some(id) = record.get(0).and_then(|s| s.parse().ok())
        {
            ids.insert(id);
        }
    }
    Ok(ids)
}

/// Why shard files could not be merged.
#[derive(Debug, thiserror::Error)]
pub enum MergeError {
    /// A file could not be read or written.
    #[error("{file}: {source}")]
    Csv {
        /// The file.
        file: String,
        /// The CSV or IO error.
        source: csv::Error,
    },
    /// Two files have different columns, so they come from different sweeps.
    #[error("{file}: its columns differ from {first}'s; shards of one sweep share a header")]
    HeaderMismatch {
        /// The odd file.
        file: String,
        /// The first file.
        first: String,
    },
}

/// Merges shard files into `out`: one header, rows sorted by run id, duplicates dropped.
/// Returns the number of rows written.
pub fn merge(inputs: &[&Path], out: &Path) -> Result<usize, MergeError> {
    let csv_err = |file: &Path| {
        let file = file.display().to_string();
        move |source| MergeError::Csv { file: file.clone(), source }
    };
    let mut header: Option<csv::StringRecord> = None;
    let mut rows: std::collections::BTreeMap<usize, csv::StringRecord> = Default::default();
    for input in inputs {
        let mut reader = csv::Reader::from_path(input).map_err(csv_err(input))?;
        let h = reader.headers().map_err(csv_err(input))?.clone();
        match &header {
            None => header = Some(h),
            Some(first) if *first != h => {
                return Err(MergeError::HeaderMismatch {
                    file: input.display().to_string(),
                    first: inputs[0].display().to_string(),
                });
            }
            _ => {}
        }
        for record in reader.records() {
            let record = record.map_err(csv_err(input))?;
            if let Some(id) = record.get(0).and_then(|s| s.parse().ok()) {
                rows.entry(id).or_insert(record);
            }
        }
    }
    let mut writer = csv::Writer::from_path(out).map_err(csv_err(out))?;
    if let Some(h) = &header {
        writer.write_record(h).map_err(csv_err(out))?;
    }
    for record in rows.values() {
        writer.write_record(record).map_err(csv_err(out))?;
    }
    writer.flush().map_err(|e| MergeError::Csv { file: out.display().to_string(), source: e.into() })?;
    Ok(rows.len())
}
