//! Reading the CSV inputs with errors that name the file, the line and the column.

use super::PlotError;
use std::path::Path;

/// Largest magnitude [`Row::plotted`] accepts. Why: the trace's quantities (forces in N, motor
/// speeds in °/s) stay within a few hundred; a value of 1e308 is a fault, and drawn it would squash
/// every other value onto one line of the axis.
pub const MAX_PLOTTED: f64 = 1e6;

/// A CSV file read whole: its header and its rows with their line numbers.
#[derive(Debug, Clone)]
pub struct Table {
    /// The file, as given.
    pub file: String,
    /// Column names.
    pub header: Vec<String>,
    /// (1-based line number, cells) per data row.
    pub rows: Vec<(u64, Vec<String>)>,
}

impl Table {
    /// Reads `path`; a missing file, a ragged row or bad UTF-8 is an error naming the line.
    pub fn read(path: &Path) -> Result<Table, PlotError> {
        let file = path.display().to_string();
        let text = std::fs::read(path).map_err(|e| PlotError::Io { file: file.clone(), cause: e })?;
        let csv_err = |e: csv::Error| PlotError::Malformed {
            file: file.clone(),
            line: e.position().map_or(1, |p| p.line()),
            message: match e.kind() {
                csv::ErrorKind::UnequalLengths { expected_len, len, .. } => {
                    format!("{len} fields, but the header has {expected_len}")
                }
                _ => e.to_string(),
            },
        };
        let mut reader = csv::ReaderBuilder::new().trim(csv::Trim::All).from_reader(text.as_slice());
        let header: Vec<String> = reader.headers().map_err(csv_err)?.iter().map(str::to_string).collect();
        if header.iter().all(String::is_empty) {
            return Err(PlotError::Malformed { file, line: 1, message: "empty file: expected a header".into() });
        }
        let mut rows = Vec::new();
        for record in reader.records() {
            let record = record.map_err(csv_err)?;
            let line = record.position().map_or(0, |p| p.line());
            rows.push((line, record.iter().map(str::to_string).collect()));
        }
        Ok(Table { file, header, rows })
    }

    /// Index of column `name`, or an error naming the header line.
    pub fn column(&self, name: &str) -> Result<usize, PlotError> {
        self.optional_column(name).ok_or_else(|| PlotError::Malformed {
            file: self.file.clone(),
            line: 1,
            message: format!("missing column `{name}` in the header"),
        })
    }

    /// Index of column `name` if the header has it.
    pub fn optional_column(&self, name: &str) -> Option<usize> {
        self.header.iter().position(|h| h == name)
    }

    /// The data rows as [`Row`]s.
    pub fn iter(&self) -> impl Iterator<Item = Row<'_>> {
        self.rows.iter().map(|(line, cells)| Row { table: self, line: *line, cells })
    }

    /// An error about the whole file (e.g. no rows).
    pub fn empty(&self, message: &str) -> PlotError {
        PlotError::Empty { file: self.file.clone(), message: message.to_string() }
    }
}

/// One data row, able to parse its cells with errors naming file, line and column.
#[derive(Debug, Clone, Copy)]
pub struct Row<'a> {
    table: &'a Table,
    /// 1-based line number in the file.
    pub line: u64,
    cells: &'a [String],
}

impl Row<'_> {
    /// An error at this row.
    pub fn error(&self, message: String) -> PlotError {
        PlotError::Malformed { file: self.table.file.clone(), line: self.line, message }
    }

    /// The raw text of column `col`.
    pub fn text(&self, col: usize) -> &str {
        self.cells.get(col).map_or("", String::as_str)
    }

    /// A number; `NaN` is accepted (ground-truth columns use it), empty is an error.
    pub fn f64(&self, col: usize) -> Result<f64, PlotError> {
        self.opt_f64(col)?.ok_or_else(|| self.error(format!("column `{}` is empty", self.table.header[col])))
    }

    /// A number or nothing (empty cell = null).
    pub fn opt_f64(&self, col: usize) -> Result<Option<f64>, PlotError> {
        let t = self.text(col);
        if t.is_empty() {
            return Ok(None);
        }
        t.parse::<f64>()
            .map(Some)
            .map_err(|_| self.error(format!("column `{}`: `{t}` is not a number", self.table.header[col])))
    }

    /// A number to draw: NaN (a gap, as ground truth without a model) or finite within
    /// ±[`MAX_PLOTTED`]; infinities and larger values are errors naming the line and column.
    pub fn plotted(&self, col: usize) -> Result<f64, PlotError> {
        let v = self.f64(col)?;
        if v.is_nan() || v.abs() <= MAX_PLOTTED {
            Ok(v)
        } else {
            Err(self.error(format!(
                "column `{}`: {v:e} is beyond ±{MAX_PLOTTED:e}: not a value to draw",
                self.table.header[col]
            )))
        }
    }

    /// A finite, strictly positive number (an axis on a log scale).
    pub fn positive(&self, col: usize) -> Result<f64, PlotError> {
        let v = self.f64(col)?;
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err(self.error(format!("column `{}`: {v} must be a positive number", self.table.header[col])))
        }
    }

    /// A boolean written `true`/`false` or `1`/`0`.
    pub fn bool(&self, col: usize) -> Result<bool, PlotError> {
        match self.text(col) {
            "true" | "1" => Ok(true),
            "false" | "0" => Ok(false),
            t => Err(self.error(format!("column `{}`: `{t}` is not true/false", self.table.header[col]))),
        }
    }

    /// One of `allowed` (error lists them otherwise).
    pub fn one_of(&self, col: usize, allowed: &[&str]) -> Result<String, PlotError> {
        let t = self.text(col);
        if allowed.contains(&t) {
            Ok(t.to_string())
        } else {
            Err(self.error(format!("column `{}`: `{t}` is not one of {}", self.table.header[col], allowed.join(", "))))
        }
    }
}

/// A file-name-safe version of `name` (objects become part of chart file names).
pub fn file_stem(name: &str) -> String {
    let s: String = name.chars().map(|c| if c.is_ascii_alphanumeric() || c == '-' { c } else { '_' }).collect();
    if s.is_empty() { "unnamed".to_string() } else { s }
}
