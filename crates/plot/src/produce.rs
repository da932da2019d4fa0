//! The produce study's charts: `plates.csv` (each item squeezed between plates against Hertz) and
//! `produce.csv` (the peak contact pressure on each item against the setpoint, with its bruise
//! threshold, the outcome of every run marked).

use super::input::Table;
use super::style::{self, FONT};
use super::{Chart, DrawResult, PlotError};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// One sample of `plates.csv`.
#[derive(Debug, Clone, PartialEq)]
pub struct PlatePoint {
    /// The item.
    pub item: String,
    /// The plates' travel since first contact \[mm\].
    pub travel_mm: f64,
    /// Force on one plate \[N\].
    pub force_n: f64,
    /// Hertz's force at that travel \[N\].
    pub hertz_force_n: f64,
}

/// Reads `plates.csv` (columns `item,travel_mm,force_n,hertz_force_n`, others ignored).
pub fn read_plates(path: &Path) -> Result<Vec<PlatePoint>, PlotError> {
    let t = Table::read(path)?;
    let (item, travel, force, hertz) =
        (t.column("item")?, t.column("travel_mm")?, t.column("force_n")?, t.column("hertz_force_n")?);
    let rows = t
        .iter()
        .map(|r| {
            Ok(PlatePoint {
                item: r.text(item).to_string(),
                travel_mm: r.plotted(travel)?,
                force_n: r.plotted(force)?,
                hertz_force_n: r.plotted(hertz)?,
            })
        })
        .collect::<Result<Vec<_>, PlotError>>()?;
    if rows.is_empty() {
        return Err(t.empty("no rows to plot"));
    }
    Ok(rows)
}

/// Draws `produce_plates.png/.svg` in `out_dir`: force against travel per item, the calibrated
/// twin solid, Hertz's dashed; returns the files written.
pub fn render_plates(points: &[PlatePoint], out_dir: &Path) -> Result<Vec<PathBuf>, PlotError> {
    let items = super::grid::first_seen(points.iter().map(|p| p.item.clone()));
    super::save(&Plates { points: points.to_vec(), items }, out_dir, "produce_plates")
}

struct Plates {
    points: Vec<PlatePoint>,
    items: Vec<String>,
}

impl Chart for Plates {
    fn size(&self) -> (u32, u32) {
        (1000, 640)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        let root = root.titled(
            "Produce between two plates: the calibrated twin (solid) against Hertz (dashed)",
            (FONT, style::TITLE),
        )?;
        let x_max = self.points.iter().map(|p| p.travel_mm).fold(0.0, f64::max) * 1.05;
        let y_max =
            self.points.iter().map(|p| p.force_n.max(p.hertz_force_n.min(p.force_n * 2.0))).fold(0.0, f64::max) * 1.05;
        let mut chart = ChartBuilder::on(&root)
            .margin(20)
            .x_label_area_size(50)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..x_max.max(1e-3), 0.0..y_max.max(1e-3))?;
        chart
            .configure_mesh()
            .x_desc("travel of the two plates since first contact [mm]")
            .y_desc("force on one plate [N]")
            .axis_desc_style((FONT, style::AXIS))
            .label_style((FONT, style::LABEL))
            .draw()?;
        for (i, item) in self.items.iter().enumerate() {
            let color = style::SERIES[i % style::SERIES.len()];
            let mine: Vec<&PlatePoint> = self.points.iter().filter(|p| &p.item == item).collect();
            chart
                .draw_series(LineSeries::new(mine.iter().map(|p| (p.travel_mm, p.force_n)), color.stroke_width(3)))?
                .label(item.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], color.stroke_width(3)));
            let hertz: Vec<(f64, f64)> =
                mine.iter().filter(|p| p.hertz_force_n <= y_max).map(|p| (p.travel_mm, p.hertz_force_n)).collect();
            chart.draw_series(DashedLineSeries::new(hertz, 8, 5, color.stroke_width(2)))?;
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .label_font((FONT, style::LABEL))
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK)
            .draw()?;
        Ok(())
    }
}

/// One run of `produce.csv` (the columns the chart uses).
#[derive(Debug, Clone, PartialEq)]
pub struct RunPoint {
    /// The item.
    pub item: String,
    /// `pick` or `harvest`.
    pub task: String,
    /// Setpoint \[N\].
    pub setpoint_n: f64,
    /// Force control while the arm moved.
    pub feedback: bool,
    /// Whether the run did the task (held to the release, or harvested).
    pub succeeded: bool,
    /// Largest peak contact pressure \[kPa\] (`None` for a run that did not run).
    pub peak_pressure_kpa: Option<f64>,
    /// The bruise threshold \[kPa\].
    pub bruise_threshold_kpa: Option<f64>,
}

/// Reads `produce.csv`.
pub fn read_runs(path: &Path) -> Result<Vec<RunPoint>, PlotError> {
    let t = Table::read(path)?;
    let c = |n: &str| t.column(n);
    let (item, task, sp, fb) = (c("item")?, c("task")?, c("setpoint_n")?, c("feedback")?);
    let (outcome, harvest, peak, threshold) =
        (c("outcome")?, c("harvest")?, c("peak_pressure_kpa")?, c("bruise_threshold_kpa")?);
    let rows = t
        .iter()
        .map(|r| {
            let task = r.one_of(task, &["pick", "harvest"])?;
            let succeeded = if task == "harvest" { r.text(harvest) == "harvested" } else { r.text(outcome) == "held" };
            Ok(RunPoint {
                item: r.text(item).to_string(),
                task,
                setpoint_n: r.positive(sp)?,
                feedback: r.bool(fb)?,
                succeeded,
                peak_pressure_kpa: r.opt_f64(peak)?,
                bruise_threshold_kpa: r.opt_f64(threshold)?,
            })
        })
        .collect::<Result<Vec<_>, PlotError>>()?;
    if rows.is_empty() {
        return Err(t.empty("no rows to plot"));
    }
    Ok(rows)
}

/// Draws `produce.png/.svg` in `out_dir`: a panel per item and task, the peak pressure against the
/// setpoint (filled: the task done; open: not; circles with feedback, crosses without) under the
/// item's bruise threshold; returns the files written.
pub fn render_runs(points: &[RunPoint], out_dir: &Path) -> Result<Vec<PathBuf>, PlotError> {
    let panels = super::grid::first_seen(points.iter().map(|p| (p.item.clone(), p.task.clone())));
    super::save(&Runs { points: points.to_vec(), panels }, out_dir, "produce")
}

struct Runs {
    points: Vec<RunPoint>,
    panels: Vec<(String, String)>,
}

impl Chart for Runs {
    fn size(&self) -> (u32, u32) {
        let rows = self.panels.len().div_ceil(2) as u32;
        (1200, 90 + 380 * rows)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        let root = root.titled(
            "Peak contact pressure on each item against the setpoint (filled: held or harvested; circle: feedback on, cross: off)",
            (FONT, style::CAPTION),
        )?;
        let rows = self.panels.len().div_ceil(2);
        let areas = root.split_evenly((rows, 2));
        for ((item, task), area) in self.panels.iter().zip(areas) {
            let mine: Vec<&RunPoint> = self
                .points
                .iter()
                .filter(|p| &p.item == item && &p.task == task && p.peak_pressure_kpa.is_some())
                .collect();
            let threshold = mine.iter().filter_map(|p| p.bruise_threshold_kpa).next();
            let x_max = mine.iter().map(|p| p.setpoint_n).fold(0.0, f64::max) * 1.1;
            let y_max = mine.iter().filter_map(|p| p.peak_pressure_kpa).chain(threshold).fold(0.0, f64::max) * 1.15;
            let mut chart = ChartBuilder::on(&area)
                .caption(format!("{item} ({task})"), (FONT, style::CAPTION))
                .margin(12)
                .x_label_area_size(42)
                .y_label_area_size(60)
                .build_cartesian_2d(0.0..x_max.max(0.1), 0.0..y_max.max(1.0))?;
            chart
                .configure_mesh()
                .x_desc("setpoint [N]")
                .y_desc("peak pressure [kPa]")
                .axis_desc_style((FONT, style::LABEL))
                .label_style((FONT, style::SMALL))
                .draw()?;
            if let Some(t) = threshold {
                chart.draw_series(DashedLineSeries::new(
                    vec![(0.0, t), (x_max, t)],
                    8,
                    5,
                    style::BAD.stroke_width(2),
                ))?;
            }
            for p in mine {
                let y = p.peak_pressure_kpa.unwrap_or(0.0);
                let color = if p.succeeded { style::GOOD } else { style::BAD };
                // Feedback on a little left, off a little right: the two never hide each other.
                let x = p.setpoint_n + if p.feedback { -0.02 } else { 0.02 } * x_max;
                if p.feedback {
                    let shape = if p.succeeded { color.filled() } else { color.stroke_width(2) };
                    chart.draw_series(std::iter::once(Circle::new((x, y), 6, shape)))?;
                } else {
                    chart.draw_series(std::iter::once(Cross::new((x, y), 6, color.stroke_width(2))))?;
                }
            }
        }
        Ok(())
    }
}
