//! The bench record: what a bench run produces, simulated or recorded, and its CSV form.
//!
//! CSV columns (header required, in this order, comma-separated; `#` lines are comments):
//!
//! | column          | unit | meaning                                                       |
//! |-----------------|------|---------------------------------------------------------------|
//! | `time_s`        | s    | time since the start of the run, non-decreasing               |
//! | `load_cell_n`   | N    | reference force (load cell); empty when there is none         |
//! | `fbg1_nm`       | nm   | FBG1 peak wavelength as the interrogator reports it           |
//! | `fbg2_nm`       | nm   | FBG2 peak wavelength                                           |
//! | `temperature_c` | °C   | reference temperature (thermometer); empty when there is none |
//!
//! The first 0.5 s must be unloaded: the procedures take their tare there.

use std::path::{Path, PathBuf};

/// The column header a bench CSV must start with.
pub const CSV_HEADER: &str = "time_s,load_cell_n,fbg1_nm,fbg2_nm,temperature_c";

/// Accepted range of each column, in the column's unit, and why. A value outside is a recording
/// fault (or a hostile file), and refusing it here keeps the fits well scaled: values of 1e160
/// once made the least-squares SVD spin.
pub const COLUMN_BOUNDS: [(&str, f64, f64); 5] = [
    // A bench run of up to a week (the paper's longest is minutes).
    ("time_s", 0.0, 7.0 * 86_400.0),
    // Twenty times the sensor's 4.69 N range (paper Sec. IV-B): a load cell pressing the soft pad
    // harder than that has torn it; negative to -100 N for a load cell's offset or pull.
    ("load_cell_n", -100.0, 100.0),
    // Well outside every interrogator's band (HYPERION si255: 1460-1620 nm).
    ("fbg1_nm", 1000.0, 2000.0),
    ("fbg2_nm", 1000.0, 2000.0),
    // The fibre's acrylate coating fails above ~85 °C; -100 to 300 °C spans every bench.
    ("temperature_c", -100.0, 300.0),
];

/// One recorded sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BenchRow {
    /// Time since the start \[s\].
    pub time_s: f64,
    /// Load-cell force \[N\], if the bench has one.
    pub load_cell_n: Option<f64>,
    /// FBG1 peak wavelength \[nm\].
    pub fbg1_nm: f64,
    /// FBG2 peak wavelength \[nm\].
    pub fbg2_nm: f64,
    /// Thermometer reading [°C], if the bench has one.
    pub temperature_c: Option<f64>,
}

/// A bench run: rows in time order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BenchRecord {
    /// The samples.
    pub rows: Vec<BenchRow>,
}

/// Why a bench CSV could not be read.
#[derive(Debug, thiserror::Error)]
pub enum CsvError {
    /// The file could not be read.
    #[error("{file}: cannot read: {source}")]
    Io {
        /// The CSV file.
        file: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The header is missing or differs from [`CSV_HEADER`].
    #[error("{file}: line {line}: expected the header `{CSV_HEADER}`, got `{got}`")]
    Header {
        /// The CSV file.
        file: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What was found.
        got: String,
    },
    /// A data row is malformed.
    #[error("{file}: line {line}: {reason}")]
    Row {
        /// The CSV file.
        file: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        reason: String,
    },
    /// The file has a header but no data.
    #[error("{file}: no data rows")]
    Empty {
        /// The CSV file.
        file: PathBuf,
    },
}

impl BenchRecord {
    /// Reads a bench CSV (see the module docs for the columns).
    pub fn read_csv(file: &Path) -> Result<BenchRecord, CsvError> {
        let bytes = std::fs::read(file).map_err(|source| CsvError::Io { file: file.into(), source })?;
        let text = String::from_utf8(bytes).map_err(|e| {
            let valid = &e.as_bytes()[..e.utf8_error().valid_up_to()];
            let line = valid.iter().filter(|&&b| b == b'\n').count() + 1;
            let column = valid.len() - valid.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1) + 1;
            CsvError::Row { file: file.into(), line, reason: format!("column {column}: not UTF-8 text") }
        })?;
        BenchRecord::parse_csv(&text, file)
    }

    /// Parses CSV text; `file` is only used in messages.
    pub fn parse_csv(text: &str, file: &Path) -> Result<BenchRecord, CsvError> {
        let mut lines = text
            .lines()
            .enumerate()
            .map(|(i, l)| (i + 1, l.trim()))
            .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
        let (hline, header) = lines.next().ok_or_else(|| CsvError::Empty { file: file.into() })?;
        let normalized: String = header.split(',').map(str::trim).collect::<Vec<_>>().join(",");
        if normalized != CSV_HEADER {
            return Err(CsvError::Header { file: file.into(), line: hline, got: header.to_string() });
        }
        let mut rows: Vec<BenchRow> = Vec::new();
        let mut last_time = f64::NEG_INFINITY;
        for (line, text) in lines {
            let row_err = |reason: String| CsvError::Row { file: file.into(), line, reason };
            let cells: Vec<&str> = text.split(',').map(str::trim).collect();
            if cells.len() != 5 {
                return Err(row_err(format!("expected 5 columns, got {}", cells.len())));
            }
            let num = |i: usize| -> Result<f64, CsvError> {
                let (name, lo, hi) = COLUMN_BOUNDS[i];
                let v: f64 =
                    cells[i].parse().map_err(|_| row_err(format!("`{name}`: `{}` is not a number", cells[i])))?;
                if !v.is_finite() {
                    return Err(row_err(format!("`{name}`: {v} is not finite")));
                }
                if !(lo..=hi).contains(&v) {
                    return Err(row_err(format!("`{name}`: {v} is outside [{lo}, {hi}]")));
                }
                Ok(v)
            };
            let opt = |i: usize| -> Result<Option<f64>, CsvError> {
                if cells[i].is_empty() { Ok(None) } else { num(i).map(Some) }
            };
            let row = BenchRow {
                time_s: num(0)?,
                load_cell_n: opt(1)?,
                fbg1_nm: num(2)?,
                fbg2_nm: num(3)?,
                temperature_c: opt(4)?,
            };
            if row.time_s < last_time {
                return Err(row_err(format!("`time_s` goes back in time ({} after {last_time})", row.time_s)));
            }
            // A reference column is recorded on every row or on none: a single empty cell is a
            // lost reading, not a bench without that instrument.
            if let Some(first) = rows.first() {
                for (name, had, has) in [
                    ("load_cell_n", first.load_cell_n.is_some(), row.load_cell_n.is_some()),
                    ("temperature_c", first.temperature_c.is_some(), row.temperature_c.is_some()),
                ] {
                    if had != has {
                        let state = if has { "has a value" } else { "is empty" };
                        return Err(row_err(format!(
                            "`{name}` {state} here but not on the first data row: the column must be filled on every row or on none"
                        )));
                    }
                }
            }
            last_time = row.time_s;
            rows.push(row);
        }
        let (Some(first), Some(last)) = (rows.first(), rows.last()) else {
            return Err(CsvError::Empty { file: file.into() });
        };
        if rows.len() > 1 && last.time_s <= first.time_s {
            return Err(CsvError::Row {
                file: file.into(),
                line: hline + 1,
                reason: format!("`time_s` never advances (every row at {} s): not a recording over time", first.time_s),
            });
        }
        Ok(BenchRecord { rows })
    }

    /// Writes the record as CSV text (the format [`BenchRecord::parse_csv`] reads).
    pub fn to_csv(&self) -> String {
        let mut out = format!("{CSV_HEADER}\n");
        let opt = |v: Option<f64>| v.map(|x| format!("{x:.6}")).unwrap_or_default();
        for r in &self.rows {
            out += &format!(
                "{:.4},{},{:.4},{:.4},{}\n",
                r.time_s,
                opt(r.load_cell_n),
                r.fbg1_nm,
                r.fbg2_nm,
                opt(r.temperature_c)
            );
        }
        out
    }

    /// The tare: mean wavelengths over the first `window_s` seconds (the run starts unloaded).
    pub fn tare(&self, window_s: f64) -> Option<crate::signals::Wavelengths> {
        let t0 = self.rows.first()?.time_s;
        let head: Vec<&BenchRow> = self.rows.iter().take_while(|r| r.time_s <= t0 + window_s).collect();
        let n = head.len() as f64;
        Some(crate::signals::Wavelengths {
            fbg1_nm: head.iter().map(|r| r.fbg1_nm).sum::<f64>() / n,
            fbg2_nm: head.iter().map(|r| r.fbg2_nm).sum::<f64>() / n,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_through_csv() {
        let rec = BenchRecord {
            rows: vec![
                BenchRow {
                    time_s: 0.0,
                    load_cell_n: Some(0.01),
                    fbg1_nm: 1540.001,
                    fbg2_nm: 1550.0,
                    temperature_c: Some(25.25),
                },
                BenchRow {
                    time_s: 0.01,
                    load_cell_n: Some(1.5),
                    fbg1_nm: 1540.5,
                    fbg2_nm: 1550.002,
                    temperature_c: Some(25.5),
                },
            ],
        };
        let back = BenchRecord::parse_csv(&rec.to_csv(), Path::new("x.csv")).unwrap();
        assert_eq!(back, rec);
    }

    #[test]
    fn malformed_rows_name_their_line() {
        let text = format!("# comment\n{CSV_HEADER}\n0,0,1540,1550,\n0.1,abc,1540,1550,\n");
        let err = BenchRecord::parse_csv(&text, Path::new("bench.csv")).unwrap_err().to_string();
        assert!(err.contains("bench.csv: line 4") && err.contains("load_cell_n"), "{err}");
        let err = BenchRecord::parse_csv(&format!("{CSV_HEADER}\n0,1,2\n"), Path::new("b.csv")).unwrap_err();
        assert!(err.to_string().contains("line 2: expected 5 columns"), "{err}");
        let err = BenchRecord::parse_csv("a,b\n", Path::new("b.csv")).unwrap_err();
        assert!(matches!(err, CsvError::Header { line: 1, .. }));
    }

    #[test]
    fn huge_frozen_and_gappy_records_are_refused() {
        let parse = |body: &str| BenchRecord::parse_csv(&format!("{CSV_HEADER}\n{body}"), Path::new("b.csv"));
        let err = parse("0,0,1540,1550,\n0.1,1e160,1540,1550,\n").unwrap_err().to_string();
        assert!(err.contains("line 3") && err.contains("load_cell_n") && err.contains("outside"), "{err}");
        let err = parse("0,0,1540,1550,\n0,1,1540,1550,\n0,2,1540,1550,\n").unwrap_err().to_string();
        assert!(err.contains("never advances"), "{err}");
        let err = parse("0,0,1540,1550,\n0.1,,1540,1550,\n").unwrap_err().to_string();
        assert!(err.contains("line 3") && err.contains("`load_cell_n` is empty"), "{err}");
        let err = parse("0,0,1540,1e9,\n").unwrap_err().to_string();
        assert!(err.contains("fbg2_nm"), "{err}");
        assert!(parse("0,,1540,1550,\n0.1,,1540,1550,\n").is_ok());
        let dir = tempfile::tempdir().unwrap();
        let f = dir.path().join("b.csv");
        let mut bytes = format!("{CSV_HEADER}\n0,0,15").into_bytes();
        bytes.extend_from_slice(b"\xff40,1550,\n");
        std::fs::write(&f, bytes).unwrap();
        let err = BenchRecord::read_csv(&f).unwrap_err().to_string();
        assert!(err.contains("b.csv: line 2") && err.contains("column 7: not UTF-8"), "{err}");
    }
}
