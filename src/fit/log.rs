//! `evaluations.jsonl`: every evaluation of a fit or a tune, one JSON line each, written and synced
//! as it finishes, so a kill loses at most the evaluations running then; `--resume` reads it back.
//!
//! The first line identifies the search (a hash of the spec, the recordings and the parameters):
//! a log of another search is refused, never mixed in. A last line without its newline is a torn
//! write: it is cut off and that candidate is evaluated again. Values are kept with their exact
//! bits, so a resumed search, re-driven with the same seed, meets the same candidates and takes
//! their results from the log instead of running them.

use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Why the log cannot be opened or written.
#[derive(Debug, thiserror::Error)]
pub enum LogError {
    /// Reading or writing failed.
    #[error("{}: {cause}", file.display())]
    Io {
        /// The log.
        file: PathBuf,
        /// The error.
        cause: std::io::Error,
    },
    /// A fresh search would overwrite an earlier one's log.
    #[error("{} exists: pass --resume to continue that search, or choose another --out", file.display())]
    Exists {
        /// The log.
        file: PathBuf,
    },
    /// The log is of another search, or not a log.
    #[error("{}: line {line}: {reason}", file.display())]
    Foreign {
        /// The log.
        file: PathBuf,
        /// 1-based line.
        line: usize,
        /// What does not match.
        reason: String,
    },
}

/// The log's first line.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct Header {
    /// The search's identity.
    search_id: String,
    /// The parameters' keys, in order.
    keys: Vec<String>,
}

/// One evaluation as logged.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EvalRecord {
    /// Position in the log (0-based), the order evaluations finished in.
    pub index: usize,
    /// The parameters' values, in key order.
    pub values: Vec<f64>,
    /// The values' bits as hex, exact (the decimal values are for reading).
    pub bits: Vec<String>,
    /// The objective (a failed candidate has [`super::optimizer::FAILED`]).
    pub objective: f64,
    /// The objective's bits as hex.
    pub objective_bits: String,
    /// A run failed (diverged, or could not start).
    pub failed: bool,
    /// What the search reports per candidate (residuals per recording, run metrics...).
    pub detail: serde_json::Value,
}

/// The hex bits of each value.
pub fn bits_of(values: &[f64]) -> Vec<String> {
    values.iter().map(|v| format!("{:016x}", v.to_bits())).collect()
}

impl EvalRecord {
    /// The exact values (from their bits).
    pub fn exact_values(&self) -> Option<Vec<f64>> {
        self.bits.iter().map(|b| u64::from_str_radix(b, 16).ok().map(f64::from_bits)).collect()
    }

    /// The exact objective.
    pub fn exact_objective(&self) -> Option<f64> {
        u64::from_str_radix(&self.objective_bits, 16).ok().map(f64::from_bits)
    }
}

/// The open log, appended to one line at a time.
#[derive(Debug)]
pub struct EvalLog {
    path: PathBuf,
    file: std::fs::File,
    next_index: usize,
}

impl EvalLog {
    /// Opens `path` for search `search_id` over `keys`. Fresh (`resume` false): the file must not
    /// exist. Resumed: its evaluations are returned (a torn last line cut off); a missing file
    /// starts fresh.
    pub fn open(
        path: &Path,
        search_id: &str,
        keys: &[String],
        resume: bool,
    ) -> Result<(EvalLog, Vec<EvalRecord>), LogError> {
        let io = |cause| LogError::Io { file: path.into(), cause };
        let header = Header { search_id: search_id.into(), keys: keys.to_vec() };
        if resume && path.exists() {
            let mut bytes = std::fs::read(path).map_err(io)?;
            let whole = bytes.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
            bytes.truncate(whole);
            let text = String::from_utf8(bytes).map_err(|_| LogError::Foreign {
                file: path.into(),
                line: 1,
                reason: "not UTF-8 text: not an evaluations log".into(),
            })?;
            let foreign = |line: usize, reason: String| LogError::Foreign { file: path.into(), line, reason };
            let mut lines = text.lines();
            let Some(first) = lines.next() else {
                // Cut before its header was whole: nothing was evaluated.
                return EvalLog::create(path, &header);
            };
            let found: Header =
                serde_json::from_str(first).map_err(|e| foreign(1, format!("not an evaluations log header: {e}")))?;
            if found != header {
                return Err(foreign(
                    1,
                    format!(
                        "the log of another search (id {}, keys {:?}; this one is {search_id}, {keys:?}): choose another --out",
                        found.search_id, found.keys
                    ),
                ));
            }
            let mut records = Vec::new();
            for (i, line) in lines.enumerate() {
                let r: EvalRecord =
                    serde_json::from_str(line).map_err(|e| foreign(i + 2, format!("not an evaluation: {e}")))?;
                if r.values.len() != keys.len() || r.exact_values().is_none() || r.exact_objective().is_none() {
                    return Err(foreign(i + 2, "not an evaluation of these parameters".into()));
                }
                records.push(r);
            }
            let file = std::fs::OpenOptions::new().write(true).open(path).map_err(io)?;
            file.set_len(whole as u64).map_err(io)?;
            let mut log = EvalLog { path: path.into(), file, next_index: records.len() };
            use std::io::Seek;
            log.file.seek(std::io::SeekFrom::End(0)).map_err(io)?;
            return Ok((log, records));
        }
        if path.exists() {
            return Err(LogError::Exists { file: path.into() });
        }
        EvalLog::create(path, &header)
    }

    fn create(path: &Path, header: &Header) -> Result<(EvalLog, Vec<EvalRecord>), LogError> {
        let io = |cause| LogError::Io { file: path.into(), cause };
        let file = std::fs::File::create(path).map_err(io)?;
        let mut log = EvalLog { path: path.into(), file, next_index: 0 };
        let line = serde_json::to_string(header).map_err(|e| io(std::io::Error::other(e)))?;
        log.write_line(&line)?;
        Ok((log, Vec::new()))
    }

    fn write_line(&mut self, line: &str) -> Result<(), LogError> {
        let io = |cause| LogError::Io { file: self.path.clone(), cause };
        let mut bytes = line.as_bytes().to_vec();
        bytes.push(b'\n');
        self.file.write_all(&bytes).map_err(io)?;
        self.file.sync_data().map_err(|cause| LogError::Io { file: self.path.clone(), cause })
    }

    /// Appends an evaluation (its index is set here) and syncs it to disk.
    pub fn append(
        &mut self,
        values: &[f64],
        objective: f64,
        failed: bool,
        detail: serde_json::Value,
    ) -> Result<EvalRecord, LogError> {
        let record = EvalRecord {
            index: self.next_index,
            values: values.to_vec(),
            bits: bits_of(values),
            objective,
            objective_bits: format!("{:016x}", objective.to_bits()),
            failed,
            detail,
        };
        let line = serde_json::to_string(&record)
            .map_err(|e| LogError::Io { file: self.path.clone(), cause: std::io::Error::other(e) })?;
        self.write_line(&line)?;
        self.next_index += 1;
        Ok(record)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_torn_line_is_cut_and_the_rest_read_back_exactly() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("evaluations.jsonl");
        let keys = vec!["a".to_string()];
        let (mut log, old) = EvalLog::open(&path, "id1", &keys, false).unwrap();
        assert!(old.is_empty());
        log.append(&[0.1 + 0.2], 1.0 / 3.0, false, serde_json::Value::Null).unwrap();
        drop(log);
        let mut f = std::fs::OpenOptions::new().append(true).open(&path).unwrap();
        f.write_all(b"{\"index\":1,\"val").unwrap();
        drop(f);
        assert!(matches!(EvalLog::open(&path, "id1", &keys, false), Err(LogError::Exists { .. })));
        let (mut log, old) = EvalLog::open(&path, "id1", &keys, true).unwrap();
        assert_eq!(old.len(), 1);
        assert_eq!(old[0].exact_values().unwrap(), vec![0.1 + 0.2]);
        assert_eq!(old[0].exact_objective().unwrap(), 1.0 / 3.0);
        assert_eq!(log.append(&[2.0], 2.0, true, serde_json::Value::Null).unwrap().index, 1);
        drop(log);
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(text.lines().count(), 3, "{text}");
        let err = EvalLog::open(&path, "id2", &keys, true).unwrap_err().to_string();
        assert!(err.contains("another search"), "{err}");
    }
}
