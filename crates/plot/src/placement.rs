//! `placement_summary.csv` (`tendril chart placement`) and its chart: per object, the held rate
//! and the largest pad force of each sensor layout, one bar per condition (disturbance set ×
//! feedback).

use super::bar_axes::bar_axes;
use super::grid::first_seen;
use super::input::Table;
use super::style::{self, FONT};
use super::{Chart, DrawResult, PlotError};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// The sensor's range \[N\] (paper Sec. IV-B): a pad pressed harder reads its range.
pub const RANGE_N: f64 = 4.69;

/// One (layout, object, condition) of the placement study, over its seeds.
#[derive(Debug, Clone, PartialEq)]
pub struct PlacementRow {
    /// The layout's name.
    pub layout: String,
    /// The object.
    pub object: String,
    /// Disturbance set and feedback, e.g. `knock, feedback on`.
    pub condition: String,
    /// Runs (seeds).
    pub runs: usize,
    /// Runs that held the object.
    pub held: usize,
    /// Mean over the runs of the largest true force on any pad while holding \[N\].
    pub max_pad_force_mean_n: Option<f64>,
}

/// Reads `placement_summary.csv` (the columns the chart needs; the study writes more).
pub fn read(path: &Path) -> Result<Vec<PlacementRow>, PlotError> {
    let t = Table::read(path)?;
    let c = |name| t.column(name);
    let (layout, object, condition, runs, held, force) =
        (c("layout")?, c("object")?, c("condition")?, c("runs")?, c("held")?, c("max_pad_force_mean_n")?);
    t.iter()
        .map(|r| {
            let count = |col| {
                let v = r.f64(col)?;
                if v >= 0.0 && v.fract() == 0.0 {
                    Ok(v as usize)
                } else {
                    Err(r.error(format!("`{v}` is not a count of runs")))
                }
            };
            Ok(PlacementRow {
                layout: r.text(layout).to_string(),
                object: r.text(object).to_string(),
                condition: r.text(condition).to_string(),
                runs: count(runs)?,
                held: count(held)?,
                max_pad_force_mean_n: r.opt_f64(force)?,
            })
        })
        .collect()
}

/// Draws `placement.png/.svg` in `out_dir`; returns the files written.
pub fn render(rows: &[PlacementRow], out_dir: &Path) -> Result<Vec<PathBuf>, PlotError> {
    let chart = Placement {
        objects: first_seen(rows.iter().map(|r| r.object.clone())),
        layouts: first_seen(rows.iter().map(|r| r.layout.clone())),
        conditions: first_seen(rows.iter().map(|r| r.condition.clone())),
        rows: rows.to_vec(),
    };
    super::save(&chart, out_dir, "placement")
}

struct Placement {
    objects: Vec<String>,
    layouts: Vec<String>,
    conditions: Vec<String>,
    rows: Vec<PlacementRow>,
}

#[derive(Clone, Copy)]
enum Metric {
    HeldRate,
    MaxPadForce,
}

impl Placement {
    fn row(&self, layout: &str, object: &str, condition: &str) -> Option<&PlacementRow> {
        self.rows.iter().find(|r| r.layout == layout && r.object == object && r.condition == condition)
    }

    fn panel<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>, object: &str, metric: Metric) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        let n = self.layouts.len();
        let worst = self.rows.iter().filter_map(|r| r.max_pad_force_mean_n).fold(0.0, f64::max);
        let (top, caption, y_desc) = match metric {
            Metric::HeldRate => (105.0, format!("{object}: held runs"), "held [% of seeds]"),
            Metric::MaxPadForce => (
                (worst * 1.1).max(1.2 * RANGE_N),
                format!("{object}: largest force on a pad while holding"),
                "mean over seeds [N]",
            ),
        };
        let mut chart = bar_axes(area, caption, y_desc, &self.layouts, top)?;
        let k = self.conditions.len().max(1) as f64;
        let width = 0.8 / k;
        for (ci, condition) in self.conditions.iter().enumerate() {
            let color = style::SERIES[ci % style::SERIES.len()];
            for (li, layout) in self.layouts.iter().enumerate() {
                let Some(r) = self.row(layout, object, condition) else { continue };
                let x0 = li as f64 - 0.4 + ci as f64 * width;
                let x1 = x0 + width * 0.9;
                let value = match metric {
                    Metric::HeldRate => Some(100.0 * r.held as f64 / r.runs.max(1) as f64),
                    Metric::MaxPadForce => r.max_pad_force_mean_n,
                };
                match value {
                    Some(v) if v > 0.0 => {
                        chart.draw_series(std::iter::once(Rectangle::new(
                            [(x0, 0.0), (x1, v.min(top))],
                            color.filled(),
                        )))?;
                    }
                    // An empty bar reads as missing data: a cross marks a zero (or no value).
                    _ => {
                        let xm = (x0 + x1) / 2.0;
                        chart.draw_series(std::iter::once(Cross::new((xm, top * 0.02), 5, color.stroke_width(2))))?;
                    }
                }
            }
        }
        if let Metric::MaxPadForce = metric {
            chart.draw_series(std::iter::once(PathElement::new(
                vec![(-0.5, RANGE_N), (n as f64 - 0.5, RANGE_N)],
                style::BAD.stroke_width(1),
            )))?;
        }
        Ok(())
    }
}

impl Chart for Placement {
    fn size(&self) -> (u32, u32) {
        let panel = 160 + 150 * self.layouts.len().max(1) as u32;
        ((2 * panel).max(1100), 110 + 300 * self.objects.len().max(1) as u32)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        let root =
            root.titled("Where to put the FBG pads: sensor layouts on the three objects", (FONT, style::TITLE))?;
        let (_, h) = root.dim_in_pixel();
        let (panels, key) = root.split_vertically(h - 50);
        let cells = panels.split_evenly((self.objects.len().max(1), 2));
        for (i, object) in self.objects.iter().enumerate() {
            self.panel(&cells[2 * i], object, Metric::HeldRate)?;
            self.panel(&cells[2 * i + 1], object, Metric::MaxPadForce)?;
        }
        let mut x = 20;
        for (ci, condition) in self.conditions.iter().enumerate() {
            let color = style::SERIES[ci % style::SERIES.len()];
            key.draw(&Rectangle::new([(x, 15), (x + 18, 33)], color.filled()))?;
            key.draw(&Text::new(condition.clone(), (x + 26, 15), (FONT, style::LABEL).into_font()))?;
            x += 40 + 9 * condition.len() as i32;
        }
        key.draw(&PathElement::new(vec![(x, 24), (x + 24, 24)], style::BAD.stroke_width(1)))?;
        let note = format!("the sensor's range, {RANGE_N} N; ×: none held");
        key.draw(&Text::new(note, (x + 32, 15), (FONT, style::LABEL).into_font()))?;
        Ok(())
    }
}
