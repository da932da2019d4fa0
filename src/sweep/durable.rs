//! Results files that survive any crash.
//!
//! A sweep appends one row per finished run; a kill, a crash or a full disk can cut the last
//! row short. So before `--resume` appends, the file is scanned ([`scan`]) and checked against
//! the sweep ([`ResultsFile::open`]):
//! - a last line without its newline is a torn row: it is cut off and its run is run again (a
//!   row is only done when its newline is on disk; rows never hold a line break, see
//!   [`super::columns::row`]);
//! - a torn or foreign header, a row of another sweep (another [`super::columns::sweep_id`]), or a
//!   complete line that is not a whole row of this sweep (a fragment glued to a row) are refused,
//!   naming the file and line: nothing is guessed;
//! - an exclusive lock on the file (`flock`, released when the process dies) stops a second
//!   process from resuming the same file.
//!
//! Each row is written with one `write` and synced; if the write fails (disk full) the file is cut
//! back to its last whole row, so what was written before is kept and nothing torn is left.

use super::columns::{SWEEP_ID_COLUMN, identity_cells, identity_columns, scenario_name};
use super::{Shard, Sweep};
use std::collections::BTreeSet;
use std::io::{Seek, Write};
use std::path::{Path, PathBuf};

/// Why a results file cannot be opened, resumed, appended to or merged.
#[derive(Debug, thiserror::Error)]
pub enum ResultsError {
    /// Reading or writing failed (a full disk, permissions).
    #[error("{}: {cause}", file.display())]
    Io {
        /// The file.
        file: PathBuf,
        /// The underlying error (not a `source`: the message holds it, and `{:#}` would repeat it).
        cause: std::io::Error,
    },
    /// A fresh sweep would overwrite an existing results file.
    #[error("{} exists: pass --resume to continue it, or choose another --out", file.display())]
    Exists {
        /// The results file.
        file: PathBuf,
    },
    /// Another process holds the file's lock.
    #[error("{} is in use by another tendril process (locked): wait for it or choose another --out", file.display())]
    Locked {
        /// The results file.
        file: PathBuf,
    },
    /// The header line has no newline: the file was cut while being created.
    #[error("{}: the header line is torn (no newline): the file was cut while being created; delete it to start over", file.display())]
    TornHeader {
        /// The results file.
        file: PathBuf,
    },
    /// The file is not a results file of this version of tendril.
    #[error("{}: not a sweep results file: {reason}", file.display())]
    NotResults {
        /// The file.
        file: PathBuf,
        /// What is missing.
        reason: String,
    },
    /// The header differs from this sweep's.
    #[error("{}: its columns differ from this sweep's (another sweep, or another tendril version): choose another --out", file.display())]
    ForeignHeader {
        /// The results file.
        file: PathBuf,
    },
    /// Two merge inputs have different columns.
    #[error("{}: its columns differ from {}'s; shards of one sweep share a header", file.display(), first.display())]
    HeaderMismatch {
        /// The odd file.
        file: PathBuf,
        /// The first file.
        first: PathBuf,
    },
    /// A row belongs to another sweep.
    #[error("{}: line {line}: a row of another sweep (sweep_id {found}, expected {expected})", file.display())]
    ForeignSweep {
        /// The file.
        file: PathBuf,
        /// 1-based line.
        line: usize,
        /// The row's sweep id.
        found: String,
        /// The sweep id expected.
        expected: String,
    },
    /// A complete line that is not a whole row of this sweep.
    #[error("{}: line {line}: not a whole row of this sweep: {reason}", file.display())]
    BadRow {
        /// The file.
        file: PathBuf,
        /// 1-based line.
        line: usize,
        /// What is wrong.
        reason: String,
    },
    /// A merge input ends in a torn row.
    #[error("{}: the last line is torn ({bytes} bytes without a newline): resume that sweep first (`tendril sweep --resume`)", file.display())]
    TornLastLine {
        /// The file.
        file: PathBuf,
        /// Length of the fragment.
        bytes: usize,
    },
}

impl ResultsError {
    /// An IO error on `file`.
    pub fn io(file: &Path, cause: std::io::Error) -> ResultsError {
        ResultsError::Io { file: file.to_path_buf(), cause }
    }
}

/// A complete row of a results file.
#[derive(Debug, Clone, PartialEq)]
pub struct ScannedRow {
    /// 1-based line number.
    pub line: usize,
    /// The `run_id` cell.
    pub run_id: usize,
    /// The `sweep_id` cell.
    pub sweep_id: String,
    /// The cells.
    pub cells: Vec<String>,
    /// The line as written, without its newline.
    pub text: String,
}

/// A torn last line: where it starts and how long it is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TornTail {
    /// Byte offset of the fragment (the length of the file's whole lines).
    pub offset: u64,
    /// Its length in bytes.
    pub len: usize,
}

/// A results file read line by line.
#[derive(Debug, Clone, PartialEq)]
pub struct Scan {
    /// The header line, without its newline.
    pub header: String,
    /// The complete rows in file order.
    pub rows: Vec<ScannedRow>,
    /// The torn last line, if any.
    pub torn_tail: Option<TornTail>,
}

fn parse_line(line: &str) -> Option<Vec<String>> {
    let mut reader = csv::ReaderBuilder::new().has_headers(false).from_reader(line.as_bytes());
    let record = reader.records().next()?.ok()?;
    Some(record.iter().map(str::to_string).collect())
}

/// Reads a results file's bytes into its header, whole rows and torn tail. Refuses a torn header,
/// a header without `run_id, sweep_id` first, and any complete line that is not a row with the
/// header's number of cells and a whole-number `run_id`.
pub fn scan(bytes: &[u8], file: &Path) -> Result<Scan, ResultsError> {
    let whole = bytes.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
    let torn_tail = (whole < bytes.len()).then_some(TornTail { offset: whole as u64, len: bytes.len() - whole });
    let text = std::str::from_utf8(&bytes[..whole]).map_err(|e| ResultsError::NotResults {
        file: file.into(),
        reason: format!("not UTF-8 text (byte {})", e.valid_up_to()),
    })?;
    let mut lines = text.split_terminator('\n');
    let Some(header) = lines.next() else {
        return Err(ResultsError::TornHeader { file: file.into() });
    };
    let columns = parse_line(header).unwrap_or_default();
    if columns.len() < 3 || columns[0] != "run_id" || columns[1] != SWEEP_ID_COLUMN {
        return Err(ResultsError::NotResults {
            file: file.into(),
            reason: format!(
                "the header must start with run_id,{SWEEP_ID_COLUMN} (files of older versions have no sweep id)"
            ),
        });
    }
    let mut rows = Vec::new();
    for (i, text) in lines.enumerate() {
        let line = i + 2;
        let bad = |reason: String| ResultsError::BadRow { file: file.into(), line, reason };
        let cells = parse_line(text).ok_or_else(|| bad("not a CSV record".into()))?;
        if cells.len() != columns.len() {
            return Err(bad(format!("{} cells where the header has {}", cells.len(), columns.len())));
        }
        let run_id = cells[0].parse().map_err(|_| bad(format!("run_id `{}` is not a whole number", cells[0])))?;
        rows.push(ScannedRow { line, run_id, sweep_id: cells[1].clone(), cells, text: text.to_string() });
    }
    Ok(Scan { header: header.to_string(), rows, torn_tail })
}

/// Reads a results file, refusing anything but a regular file (reading /dev/zero never ends).
pub fn read_regular(path: &Path) -> Result<Vec<u8>, ResultsError> {
    let meta = std::fs::metadata(path).map_err(|source| ResultsError::io(path, source))?;
    if !meta.is_file() {
        return Err(ResultsError::NotResults { file: path.into(), reason: "not a regular file".into() });
    }
    std::fs::read(path).map_err(|source| ResultsError::io(path, source))
}

/// Writes `bytes` over `path` atomically ([`tendril_config::write_atomically`]).
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), ResultsError> {
    tendril_config::write_atomically(path, bytes).map_err(|(file, cause)| ResultsError::Io { file, cause })
}

/// What opening a results file found.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Opened {
    /// Runs whose rows are whole in the file.
    pub done: BTreeSet<usize>,
    /// Bytes of a torn last line that were cut off (its run is run again).
    pub dropped_tail: Option<usize>,
}

/// A sweep's results file, locked, checked and open for appending whole rows.
pub struct ResultsFile {
    path: PathBuf,
    file: std::fs::File,
    len: u64,
}

impl ResultsFile {
    /// Opens `path` for `sweep` (rows carry `sweep_id`). A fresh sweep creates it (refusing an
    /// existing one) and writes `header`; `resume` checks and repairs it (see the module docs).
    /// Either way the file is locked for as long as the [`ResultsFile`] lives.
    pub fn open(
        path: &Path,
        sweep: &Sweep,
        sweep_id: &str,
        header: &[String],
        resume: bool,
        shard: Option<Shard>,
    ) -> Result<(ResultsFile, Opened), ResultsError> {
        let io = |source| ResultsError::io(path, source);
        let mut options = std::fs::OpenOptions::new();
        options.read(true).write(true);
        if resume {
            options.create(true)
        } else {
            options.create_new(true)
        };
        let file = options.open(path).map_err(|e| match e.kind() {
            std::io::ErrorKind::AlreadyExists => ResultsError::Exists { file: path.into() },
            _ => io(e),
        })?;
        // Only a regular file: reading a device (/dev/full, /dev/zero) would never end.
        if !file.metadata().map_err(io)?.is_file() {
            return Err(ResultsError::NotResults { file: path.into(), reason: "not a regular file".into() });
        }
        file.try_lock().map_err(|e| match e {
            std::fs::TryLockError::WouldBlock => ResultsError::Locked { file: path.into() },
            std::fs::TryLockError::Error(e) => io(e),
        })?;
        let bytes = std::fs::read(path).map_err(io)?;
        let mut results = ResultsFile { path: path.into(), file, len: bytes.len() as u64 };
        let header_line = csv_line(header).map_err(io)?;
        if bytes.is_empty() {
            results.append_bytes(&header_line)?;
            return Ok((results, Opened::default()));
        }
        let scan = scan(&bytes, path)?;
        if scan.header.as_bytes() != &header_line[..header_line.len() - 1] {
            return Err(ResultsError::ForeignHeader { file: path.into() });
        }
        let mut opened = Opened::default();
        for row in &scan.rows {
            check_row(row, sweep, sweep_id, shard, path)?;
            opened.done.insert(row.run_id);
        }
        if let Some(torn) = scan.torn_tail {
            results.file.set_len(torn.offset).map_err(io)?;
            results.file.sync_data().map_err(io)?;
            results.len = torn.offset;
            opened.dropped_tail = Some(torn.len);
        }
        Ok((results, opened))
    }

    /// Appends one whole row (one `write`, then synced). On failure the file is cut back to its
    /// previous length, so no torn row is left behind.
    pub fn append(&mut self, cells: &[String]) -> Result<(), ResultsError> {
        let line = csv_line(cells).map_err(|e| ResultsError::io(&self.path, e))?;
        self.append_bytes(&line)
    }

    fn append_bytes(&mut self, line: &[u8]) -> Result<(), ResultsError> {
        let write = |f: &mut std::fs::File, at: u64| -> std::io::Result<()> {
            f.seek(std::io::SeekFrom::Start(at))?;
            f.write_all(line)?;
            f.sync_data()
        };
        if let Err(e) = write(&mut self.file, self.len) {
            let _ = self.file.set_len(self.len);
            return Err(ResultsError::io(&self.path, e));
        }
        self.len += line.len() as u64;
        Ok(())
    }
}

/// One CSV line, newline included.
fn csv_line(cells: &[String]) -> std::io::Result<Vec<u8>> {
    let mut w = csv::WriterBuilder::new().terminator(csv::Terminator::Any(b'\n')).from_writer(Vec::new());
    w.write_record(cells)?;
    w.into_inner().map_err(|e| std::io::Error::other(e.to_string()))
}

/// A scanned row must be a whole row of this sweep and shard: its sweep id, a run id in range, and
/// the identity cells that run writes (a fragment glued to a row changes them: "10" + "40,…"
/// reads as run 1040, or as another run whose swept values differ).
fn check_row(
    row: &ScannedRow,
    sweep: &Sweep,
    sweep_id: &str,
    shard: Option<Shard>,
    file: &Path,
) -> Result<(), ResultsError> {
    let bad = |reason: String| ResultsError::BadRow { file: file.into(), line: row.line, reason };
    if row.sweep_id != sweep_id {
        return Err(ResultsError::ForeignSweep {
            file: file.into(),
            line: row.line,
            found: row.sweep_id.clone(),
            expected: sweep_id.into(),
        });
    }
    let run = sweep.runs.get(row.run_id).ok_or_else(|| {
        bad(format!("run_id {} is not in this sweep (0 to {})", row.run_id, sweep.runs.len().saturating_sub(1)))
    })?;
    if shard.is_some_and(|s| !s.owns(run.id)) {
        return Err(bad(format!("run {} belongs to another shard", run.id)));
    }
    let expected = identity_cells(sweep, sweep_id, run);
    let n = identity_columns(sweep);
    let same = |i: usize| {
        if i == 2 {
            scenario_name(Path::new(&row.cells[i])) == scenario_name(&run.scenario)
        } else {
            row.cells[i] == expected[i]
        }
    };
    if let Some(i) = (0..n).find(|&i| !same(i)) {
        return Err(bad(format!(
            "cell {} is `{}` where run {} writes `{}` (a torn row glued to another?); remove the line or start a new --out",
            i + 1,
            row.cells[i],
            run.id,
            expected[i]
        )));
    }
    Ok(())
}
