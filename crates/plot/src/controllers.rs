//! `controllers.csv` (one row per run of `tendril chart controllers`) and its chart: per object,
//! grouped bars of the held rate and of the largest fluctuation while moving, one group per
//! disturbance set and one bar per controller.

use super::bar_axes::bar_axes;
pub use super::controller_runs::{COLUMNS, ControllerRow, read};
use super::controllers_summary::{GOAL_FLUCTUATION_PCT, SummaryRow, aggregate};
use super::grid::first_seen;
use super::style::{self, FONT};
use super::{Chart, DrawResult, PlotError};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// Draws `controllers.png/.svg` in `out_dir`; returns the files written.
pub fn render(rows: &[ControllerRow], out_dir: &Path) -> Result<Vec<PathBuf>, PlotError> {
    let chart = Controllers {
        objects: first_seen(rows.iter().map(|r| r.object.clone())),
        sets: first_seen(rows.iter().map(|r| r.disturbance.clone())),
        controllers: first_seen(rows.iter().map(|r| r.controller.clone())),
        seeds: first_seen(rows.iter().map(|r| r.seed)).len(),
        summary: aggregate(rows),
    };
    super::save(&chart, out_dir, "controllers")
}

struct Controllers {
    objects: Vec<String>,
    sets: Vec<String>,
    controllers: Vec<String>,
    seeds: usize,
    summary: Vec<SummaryRow>,
}

/// What a panel row shows.
#[derive(Clone, Copy)]
enum Metric {
    HeldRate,
    Fluctuation,
}

impl Controllers {
    fn row(&self, controller: &str, object: &str, set: &str) -> Option<&SummaryRow> {
        self.summary.iter().find(|r| r.controller == controller && r.object == object && r.disturbance == set)
    }

    /// The fluctuation axis' top: the worst value with room, at least twice the goal.
    fn fluctuation_top(&self) -> f64 {
        let worst = self.summary.iter().filter_map(|r| r.fluctuation_worst_pct).fold(0.0, f64::max);
        (worst * 1.1).max(2.0 * GOAL_FLUCTUATION_PCT)
    }

    fn panel<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>, object: &str, metric: Metric) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        let n = self.sets.len();
        let top = match metric {
            Metric::HeldRate => 105.0,
            Metric::Fluctuation => self.fluctuation_top(),
        };
        let (caption, y_desc) = match metric {
            Metric::HeldRate => (format!("{object}: held runs"), "held [% of seeds]"),
            Metric::Fluctuation => {
                (format!("{object}: largest fluctuation while moving"), "bar: mean, tick: worst [%]")
            }
        };
        let mut chart = bar_axes(area, caption, y_desc, &self.sets, top)?;
        let k = self.controllers.len().max(1) as f64;
        let width = 0.8 / k;
        for (ci, controller) in self.controllers.iter().enumerate() {
            let color = style::SERIES[ci % style::SERIES.len()];
            for (si, set) in self.sets.iter().enumerate() {
                let Some(r) = self.row(controller, object, set) else { continue };
                let x0 = si as f64 - 0.4 + ci as f64 * width;
                let x1 = x0 + width * 0.9;
                let xm = (x0 + x1) / 2.0;
                match metric {
                    Metric::HeldRate => {
                        let v = 100.0 * r.held_rate;
                        chart.draw_series(std::iter::once(Rectangle::new([(x0, 0.0), (x1, v)], color.filled())))?;
                        if r.held == 0 {
                            // An empty bar reads as missing data: mark a zero held rate.
                            chart.draw_series(std::iter::once(Cross::new((xm, 2.0), 5, color.stroke_width(2))))?;
                        }
                    }
                    Metric::Fluctuation => match (r.fluctuation_mean_pct, r.fluctuation_worst_pct) {
                        (Some(mean), Some(worst)) => {
                            chart.draw_series(std::iter::once(Rectangle::new(
                                [(x0, 0.0), (x1, mean.min(top))],
                                color.filled(),
                            )))?;
                            chart.draw_series(std::iter::once(PathElement::new(
                                vec![(x0, worst.min(top)), (x1, worst.min(top))],
                                BLACK.stroke_width(2),
                            )))?;
                        }
                        // Nothing held: no fluctuation to show, a cross says so.
                        _ => {
                            chart.draw_series(std::iter::once(Cross::new(
                                (xm, top * 0.02),
                                5,
                                color.stroke_width(2),
                            )))?;
                        }
                    },
                }
            }
        }
        if let Metric::Fluctuation = metric {
            chart.draw_series(std::iter::once(PathElement::new(
                vec![(-0.5, GOAL_FLUCTUATION_PCT), (n as f64 - 0.5, GOAL_FLUCTUATION_PCT)],
                style::BAD.stroke_width(1),
            )))?;
        }
        Ok(())
    }
}

impl Chart for Controllers {
    fn size(&self) -> (u32, u32) {
        // Each set's group needs room for its label ("limits + 0.3 N·s knock") under its bars.
        let panel = 160 + 160 * self.sets.len().max(1) as u32;
        ((2 * panel).max(1100), 110 + 300 * self.objects.len().max(1) as u32)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        let title = format!(
            "Force controllers under disturbances ({} seed{} each)",
            self.seeds,
            if self.seeds == 1 { "" } else { "s" }
        );
        let root = root.titled(&title, (FONT, style::TITLE))?;
        let (_, h) = root.dim_in_pixel();
        let (panels, key) = root.split_vertically(h - 50);
        // A row per object: its held rate on the left, its fluctuation on the right.
        let cells = panels.split_evenly((self.objects.len().max(1), 2));
        for (i, object) in self.objects.iter().enumerate() {
            self.panel(&cells[2 * i], object, Metric::HeldRate)?;
            self.panel(&cells[2 * i + 1], object, Metric::Fluctuation)?;
        }
        let mut x = 20;
        for (ci, controller) in self.controllers.iter().enumerate() {
            let color = style::SERIES[ci % style::SERIES.len()];
            key.draw(&Rectangle::new([(x, 15), (x + 18, 33)], color.filled()))?;
            key.draw(&Text::new(controller.clone(), (x + 26, 15), (FONT, style::LABEL).into_font()))?;
            x += 40 + 10 * controller.len() as i32;
        }
        key.draw(&PathElement::new(vec![(x, 24), (x + 24, 24)], style::BAD.stroke_width(1)))?;
        let goal = format!("goal: ≤ {GOAL_FLUCTUATION_PCT} % while moving; ×: nothing held");
        key.draw(&Text::new(goal, (x + 32, 15), (FONT, style::LABEL).into_font()))?;
        Ok(())
    }
}
