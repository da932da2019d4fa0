//! A sweep's `results.csv` as heatmaps over (Kp, Ki), one figure per object with four panels:
//! outcome, rise time, overshoot and fluctuation. Runs sharing a gain pair (other swept keys,
//! seeds) are pooled: the outcome cell shows the share held, the metric cells the mean.

use super::grid::{self, Cell, Key};
use super::input::{Table, file_stem};
use super::style::{self, FONT};
use super::{Chart, DrawResult, PlotError};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// The fields of one `results.csv` row that the heatmaps use.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepRow {
    /// Object name.
    pub object: String,
    /// Proportional gain [(°/s)/N].
    pub kp: f64,
    /// Integral gain [(°/s)/(N·s)].
    pub ki: f64,
    /// Force setpoint \[N\] (None if the column is absent or empty).
    pub setpoint_n: Option<f64>,
    /// "held", "dropped" or "error".
    pub outcome: String,
    /// Rise time to 90 % of the setpoint \[s\].
    pub rise_time_90_s: Option<f64>,
    /// Overshoot [% of setpoint].
    pub overshoot_pct: Option<f64>,
    /// Largest fluctuation while the arm moves, held runs only [%].
    pub max_fluctuation_pct: Option<f64>,
}

/// Reads the rows of a sweep's `results.csv` (columns `object`, `gains.kp`, `gains.ki`,
/// `outcome`, `rise_time_90_s`, `overshoot_pct`, `max_fluctuation_pct`; `setpoint_n` optional).
pub fn read(path: &Path) -> Result<Vec<SweepRow>, PlotError> {
    let t = Table::read(path)?;
    let object = t.column("object")?;
    let kp = t.column("gains.kp")?;
    let ki = t.column("gains.ki")?;
    let outcome = t.column("outcome")?;
    let rise = t.column("rise_time_90_s")?;
    let overshoot = t.column("overshoot_pct")?;
    let fluct = t.column("max_fluctuation_pct")?;
    let setpoint = t.optional_column("setpoint_n");
    let rows = t
        .iter()
        .map(|r| {
            Ok(SweepRow {
                object: r.text(object).to_string(),
                kp: r.f64(kp)?,
                ki: r.f64(ki)?,
                setpoint_n: setpoint.map(|c| r.opt_f64(c)).transpose()?.flatten(),
                outcome: r.one_of(outcome, &["held", "dropped", "error"])?,
                rise_time_90_s: r.opt_f64(rise)?,
                overshoot_pct: r.opt_f64(overshoot)?,
                max_fluctuation_pct: r.opt_f64(fluct)?,
            })
        })
        .collect::<Result<Vec<_>, PlotError>>()?;
    if rows.is_empty() {
        return Err(t.empty("no runs to plot"));
    }
    Ok(rows)
}

/// Draws one figure per object, `sweep_<object>.png/.svg` in `out_dir`; returns the files written.
pub fn render(rows: &[SweepRow], out_dir: &Path) -> Result<Vec<PathBuf>, PlotError> {
    let objects = grid::first_seen(rows.iter().map(|r| r.object.as_str()));
    let mut written = Vec::new();
    for object in objects {
        let runs: Vec<&SweepRow> = rows.iter().filter(|r| r.object == object).collect();
        let fig = SweepFigure::new(object, &runs);
        written.extend(super::save(&fig, out_dir, &format!("sweep_{}", file_stem(object)))?);
    }
    Ok(written)
}

/// Picks one metric out of a row.
type Metric = fn(&SweepRow) -> Option<f64>;

/// One object's four heatmaps.
struct SweepFigure {
    title: String,
    kp: Vec<f64>,
    ki: Vec<f64>,
    /// Runs per (kp index, ki index).
    cells: Vec<((usize, usize), Vec<SweepRow>)>,
}

impl SweepFigure {
    fn new(object: &str, runs: &[&SweepRow]) -> SweepFigure {
        let kp = grid::distinct(runs.iter().map(|r| r.kp));
        let ki = grid::distinct(runs.iter().map(|r| r.ki));
        let mut cells: Vec<((usize, usize), Vec<SweepRow>)> = Vec::new();
        for r in runs {
            let at = (grid::index_of(&kp, r.kp), grid::index_of(&ki, r.ki));
            match cells.iter_mut().find(|(k, _)| *k == at) {
                Some((_, v)) => v.push((*r).clone()),
                None => cells.push((at, vec![(*r).clone()])),
            }
        }
        let setpoints = grid::distinct(runs.iter().filter_map(|r| r.setpoint_n));
        let per_cell = cells.iter().map(|(_, v)| v.len()).max().unwrap_or(1);
        let mut title = format!("Gain sweep: {object}");
        if setpoints.len() == 1 {
            title += &format!(", setpoint {} N", style::num(setpoints[0]));
        }
        if per_cell > 1 {
            title += &format!(" (up to {per_cell} runs per cell: share held, mean metrics)");
        }
        SweepFigure { title, kp, ki, cells }
    }

    fn outcome_cells(&self) -> Vec<Cell> {
        self.cells
            .iter()
            .map(|((x, y), runs)| {
                let n = runs.len();
                let held = runs.iter().filter(|r| r.outcome == "held").count();
                let errors = runs.iter().filter(|r| r.outcome == "error").count();
                let (color, label) = if errors == n {
                    (style::NONE, "error".to_string())
                } else if held == n {
                    (style::GOOD, "held".to_string())
                } else if held == 0 && errors == 0 {
                    (style::BAD, "dropped".to_string())
                } else {
                    let share = held as f64 / (n - errors) as f64;
                    (style::blend(style::BAD, style::GOOD, share), format!("{held}/{n} held"))
                };
                Cell { kp: *x, ki: *y, color, label }
            })
            .collect()
    }

    fn metric_cells(&self, f: Metric) -> (Vec<Cell>, f64, f64) {
        let means: Vec<((usize, usize), Option<f64>)> = self
            .cells
            .iter()
            .map(|(at, runs)| {
                let v: Vec<f64> = runs.iter().filter_map(f).filter(|v| v.is_finite()).collect();
                (*at, (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64))
            })
            .collect();
        let min = means.iter().filter_map(|m| m.1).fold(f64::INFINITY, f64::min);
        let max = means.iter().filter_map(|m| m.1).fold(f64::NEG_INFINITY, f64::max);
        let (min, max) = if min.is_finite() { (min, max) } else { (0.0, 1.0) };
        let cells = means
            .into_iter()
            .map(|((x, y), m)| match m {
                Some(v) => Cell { kp: x, ki: y, color: grid::viridis(v, min, max), label: style::num(v) },
                None => Cell { kp: x, ki: y, color: style::NONE, label: "–".to_string() },
            })
            .collect();
        (cells, min, max)
    }
}

impl Chart for SweepFigure {
    fn size(&self) -> (u32, u32) {
        (1600, 1200)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        let root = root.titled(&self.title, (FONT, style::TITLE))?;
        let panels = root.split_evenly((2, 2));
        let swatches = Key::Swatches(vec![
            (style::GOOD, "held".into()),
            (style::blend(style::BAD, style::GOOD, 0.5), "partly held".into()),
            (style::BAD, "dropped".into()),
            (style::NONE, "error".into()),
        ]);
        grid::panel(&panels[0], "Outcome", &self.kp, &self.ki, &self.outcome_cells(), &swatches)?;
        let metrics: [(&str, &str, Metric); 3] = [
            ("Rise time to 90 % of setpoint", "rise time [s]", |r| r.rise_time_90_s),
            ("Overshoot during the grasp", "overshoot [%]", |r| r.overshoot_pct),
            ("Largest fluctuation while moving (held runs)", "fluctuation [%]", |r| r.max_fluctuation_pct),
        ];
        for (area, (caption, unit, f)) in panels[1..].iter().zip(metrics) {
            let (cells, min, max) = self.metric_cells(f);
            let key = Key::ColorBar { min, max, label: unit.to_string() };
            grid::panel(area, caption, &self.kp, &self.ki, &cells, &key)?;
        }
        Ok(())
    }
}
