//! `gain_map.csv` as one map per object: the (Kp, Ki) cells where the closed loop holds the
//! object, oscillates, or loses it.

use super::grid::{self, Cell, Key};
use super::input::{Table, file_stem};
use super::style::{self, FONT};
use super::{Chart, DrawResult, PlotError};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// One row of `gain_map.csv`.
#[derive(Debug, Clone, PartialEq)]
pub struct GainMapRow {
    /// Object name.
    pub object: String,
    /// Proportional gain [(°/s)/N].
    pub kp: f64,
    /// Integral gain [(°/s)/(N·s)].
    pub ki: f64,
    /// "held", "dropped" or "error".
    pub outcome: String,
    /// Whether the force oscillated under control.
    pub oscillating: bool,
}

/// Reads `gain_map.csv` (columns `object,kp,ki,outcome,oscillating`).
pub fn read(path: &Path) -> Result<Vec<GainMapRow>, PlotError> {
    let t = Table::read(path)?;
    let (object, kp, ki) = (t.column("object")?, t.column("kp")?, t.column("ki")?);
    let (outcome, osc) = (t.column("outcome")?, t.column("oscillating")?);
    let rows = t
        .iter()
        .map(|r| {
            Ok(GainMapRow {
                object: r.text(object).to_string(),
                kp: r.f64(kp)?,
                ki: r.f64(ki)?,
                outcome: r.one_of(outcome, &["held", "dropped", "error"])?,
                oscillating: r.bool(osc)?,
            })
        })
        .collect::<Result<Vec<_>, PlotError>>()?;
    if rows.is_empty() {
        return Err(t.empty("no rows to plot"));
    }
    Ok(rows)
}

/// The classes of the map, worst last, with their colour and legend text.
const CLASSES: [(RGBColor, &str); 5] = [
    (style::GOOD, "held"),
    (style::WARN, "held, oscillating"),
    (style::BAD, "dropped"),
    (style::OTHER, "dropped, oscillating"),
    (style::NONE, "error"),
];

fn class(r: &GainMapRow) -> usize {
    match (r.outcome.as_str(), r.oscillating) {
        ("held", false) => 0,
        ("held", true) => 1,
        ("dropped", false) => 2,
        ("dropped", true) => 3,
        _ => 4,
    }
}

/// Draws `gain_map_<object>.png/.svg` per object in `out_dir`; returns the files written.
pub fn render(rows: &[GainMapRow], out_dir: &Path) -> Result<Vec<PathBuf>, PlotError> {
    let objects = grid::first_seen(rows.iter().map(|r| r.object.as_str()));
    let mut written = Vec::new();
    for object in objects {
        let runs: Vec<&GainMapRow> = rows.iter().filter(|r| r.object == object).collect();
        let kp = grid::distinct(runs.iter().map(|r| r.kp));
        let ki = grid::distinct(runs.iter().map(|r| r.ki));
        // Several rows for one gain pair (seeds): the worst class wins.
        let mut worst: Vec<((usize, usize), usize)> = Vec::new();
        for r in &runs {
            let at = (grid::index_of(&kp, r.kp), grid::index_of(&ki, r.ki));
            match worst.iter_mut().find(|(k, _)| *k == at) {
                Some((_, c)) => *c = (*c).max(class(r)),
                None => worst.push((at, class(r))),
            }
        }
        let cells = worst
            .into_iter()
            .map(|((x, y), c)| Cell { kp: x, ki: y, color: CLASSES[c].0, label: String::new() })
            .collect();
        let map = GainMap { title: format!("Closed-loop map over the PID gains: {object}"), kp, ki, cells };
        written.extend(super::save(&map, out_dir, &format!("gain_map_{}", file_stem(object)))?);
    }
    Ok(written)
}

struct GainMap {
    title: String,
    kp: Vec<f64>,
    ki: Vec<f64>,
    cells: Vec<Cell>,
}

impl Chart for GainMap {
    fn size(&self) -> (u32, u32) {
        (1000, 760)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        let root = root.titled(&self.title, (FONT, style::TITLE))?;
        let key = Key::Swatches(CLASSES.iter().map(|(c, s)| (*c, s.to_string())).collect());
        grid::panel(&root, "", &self.kp, &self.ki, &self.cells, &key)
    }
}
