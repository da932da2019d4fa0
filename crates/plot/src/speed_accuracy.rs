//! `speed_accuracy.csv` as accuracy against speed (both log): one colour per integrator, one
//! marker per backend, the Pareto front drawn through the non-dominated settings (faster and
//! more accurate than any other), the default settings ringed and the reference marked.

use super::grid;
use super::input::Table;
use super::style::{self, FONT};
use super::{Chart, DrawResult, PlotError};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::{Path, PathBuf};

/// One row of `speed_accuracy.csv`.
#[derive(Debug, Clone, PartialEq)]
pub struct SpeedAccuracyRow {
    /// Physics backend.
    pub backend: String,
    /// Integrator name.
    pub integrator: String,
    /// Friction cone ("pyramidal", "elliptic").
    pub cone: String,
    /// Constraint solver ("newton", "cg", "pgs"; "newton" when the file has no such column).
    pub solver: String,
    /// Physics timestep \[s\].
    pub timestep_s: f64,
    /// Finger links.
    pub segments: u32,
    /// `finger.base_refinement` (1, a uniform strip, when the file has no such column).
    pub base_refinement: u32,
    /// `finger.fine_from_m` \[m\]: where the base stretch's finer links start (0, from the base,
    /// when the file has no such column).
    pub fine_from_m: f64,
    /// Simulated seconds per CPU second of the run's thread (None if the run failed before measuring).
    pub sim_s_per_cpu_s: Option<f64>,
    /// RMSE of the sensor force against the reference run \[N\].
    pub force_rmse_n: Option<f64>,
    /// Drop-time error against the reference \[s\] (None when neither dropped).
    pub drop_time_error_s: Option<f64>,
    /// A produce item's flex: points per axis of its grid (None for a rigid object, or when the
    /// file has no such column).
    pub produce_grid: Option<u32>,
    /// A produce item's flex: its degrees of freedom ("trilinear", "quadratic"; None for a rigid
    /// object).
    pub produce_dof: Option<String>,
    /// A produce item: the peak contact pressure's difference from the reference's, in percent of
    /// the reference's (None for a rigid object).
    pub peak_pressure_error_pct: Option<f64>,
    /// "ok", "diverged" or "error".
    pub status: String,
    /// These are the scenario's default settings.
    pub is_default: bool,
    /// This is the reference run (smallest timestep, finest finger).
    pub is_reference: bool,
}

/// Reads `speed_accuracy.csv`.
pub fn read(path: &Path) -> Result<Vec<SpeedAccuracyRow>, PlotError> {
    let t = Table::read(path)?;
    let c = |n: &str| t.column(n);
    let (backend, integrator, cone, dt, segs) =
        (c("backend")?, c("integrator")?, c("cone")?, c("timestep_s")?, c("segments")?);
    let (speed, rmse, drop, status) =
        (c("sim_s_per_cpu_s")?, c("force_rmse_n")?, c("drop_time_error_s")?, c("status")?);
    let (default, reference) = (c("is_default")?, c("is_reference")?);
    let (solver, refinement) = (t.optional_column("solver"), t.optional_column("base_refinement"));
    let fine_from = t.optional_column("fine_from_m");
    let (grid, dof) = (t.optional_column("produce_grid"), t.optional_column("produce_dof"));
    let pressure = t.optional_column("peak_pressure_error_pct");
    let rows = t
        .iter()
        .map(|r| {
            let segments = r.text(segs);
            Ok(SpeedAccuracyRow {
                backend: r.text(backend).to_string(),
                integrator: r.text(integrator).to_string(),
                cone: r.text(cone).to_string(),
                solver: solver.map_or("newton", |c| r.text(c)).to_string(),
                timestep_s: r.positive(dt)?,
                segments: whole(&r, "segments", segments)?,
                base_refinement: match refinement {
                    Some(c) => whole(&r, "base_refinement", r.text(c))?,
                    None => 1,
                },
                fine_from_m: match fine_from {
                    Some(c) => r.f64(c)?,
                    None => 0.0,
                },
                sim_s_per_cpu_s: r.opt_f64(speed)?,
                force_rmse_n: r.opt_f64(rmse)?,
                drop_time_error_s: r.opt_f64(drop)?,
                produce_grid: match grid.map(|c| r.text(c)).filter(|t| !t.is_empty()) {
                    Some(text) => Some(whole(&r, "produce_grid", text)?),
                    None => None,
                },
                produce_dof: dof.map(|c| r.text(c)).filter(|t| !t.is_empty()).map(str::to_string),
                peak_pressure_error_pct: match pressure {
                    Some(c) => r.opt_f64(c)?,
                    None => None,
                },
                status: r.one_of(status, &["ok", "diverged", "error"])?,
                is_default: r.bool(default)?,
                is_reference: r.bool(reference)?,
            })
        })
        .collect::<Result<Vec<_>, PlotError>>()?;
    if rows.is_empty() {
        return Err(t.empty("no rows to plot"));
    }
    Ok(rows)
}

/// A whole-number cell of `column`.
fn whole(r: &super::input::Row<'_>, column: &str, text: &str) -> Result<u32, PlotError> {
    text.parse().map_err(|_| r.error(format!("column `{column}`: `{text}` is not a whole number")))
}

/// Indices of the rows on the Pareto front (faster and/or more accurate than all others),
/// sorted by speed; only rows with status "ok" and a finite positive speed and error count.
pub fn pareto_front(rows: &[SpeedAccuracyRow]) -> Vec<usize> {
    let pts: Vec<(usize, f64, f64)> =
        rows.iter().enumerate().filter_map(|(i, r)| plottable(r).map(|(s, e)| (i, s, e))).collect();
    let mut front: Vec<(usize, f64, f64)> = pts
        .iter()
        .filter(|(i, s, e)| !pts.iter().any(|(j, s2, e2)| j != i && s2 >= s && e2 <= e && (s2 > s || e2 < e)))
        .copied()
        .collect();
    front.sort_by(|a, b| a.1.total_cmp(&b.1));
    front.into_iter().map(|p| p.0).collect()
}

/// (speed, error) of a row that can sit on log axes.
fn plottable(r: &SpeedAccuracyRow) -> Option<(f64, f64)> {
    let s = r.sim_s_per_cpu_s.filter(|s| s.is_finite() && *s > 0.0)?;
    let e = r.force_rmse_n.filter(|e| e.is_finite() && *e > 0.0)?;
    (r.status == "ok").then_some((s, e))
}

/// Draws `speed_accuracy.png/.svg` in `out_dir`; returns the files written.
pub fn render(rows: &[SpeedAccuracyRow], out_dir: &Path) -> Result<Vec<PathBuf>, PlotError> {
    super::save(&SpeedAccuracy { rows: rows.to_vec() }, out_dir, "speed_accuracy")
}

struct SpeedAccuracy {
    rows: Vec<SpeedAccuracyRow>,
}

/// The colour series a row belongs to: its integrator (a produce item's: its flex's degrees of
/// freedom, since its integrator is always MuJoCo's discrete one), and on MuJoCo its solver when
/// that is not the default Newton (rapier's integrator column already names its solver).
fn series(r: &SpeedAccuracyRow) -> String {
    let base = match &r.produce_dof {
        Some(dof) => format!("{dof} flex"),
        None => r.integrator.clone(),
    };
    if r.backend == "mujoco" && r.solver != "newton" { format!("{base} + {}", r.solver.to_uppercase()) } else { base }
}

/// Short description of a row's settings, for labels.
fn settings(r: &SpeedAccuracyRow) -> String {
    let graded = match (r.base_refinement > 1, r.fine_from_m > 0.0) {
        (true, true) => format!(" (base x{} from {:.1} mm)", r.base_refinement, r.fine_from_m * 1e3),
        (true, false) => format!(" (base x{})", r.base_refinement),
        _ => String::new(),
    };
    let flex = match (r.produce_grid, &r.produce_dof) {
        (Some(n), Some(dof)) => format!(", {n} pts {dof}"),
        (Some(n), None) => format!(", {n} pts"),
        _ => String::new(),
    };
    format!("{}, {} links{graded}, {}{flex}", style::timestep(r.timestep_s), r.segments, r.cone)
}

impl SpeedAccuracy {
    /// (row, speed, |drop-time error|) of the settled runs with a drop-time error.
    fn drop_errors(&self) -> Vec<(&SpeedAccuracyRow, f64, f64)> {
        self.rows
            .iter()
            .filter(|r| r.status == "ok")
            .filter_map(|r| {
                let s = r.sim_s_per_cpu_s.filter(|s| s.is_finite() && *s > 0.0)?;
                let e = r.drop_time_error_s.filter(|e| e.is_finite())?;
                Some((r, s, e.abs()))
            })
            .collect()
    }

    /// The second accuracy measure: |drop-time error| against speed; zero errors on the bottom edge.
    fn draw_drop_panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        drops: &[(&SpeedAccuracyRow, f64, f64)],
        x: std::ops::Range<f64>,
    ) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        let nonzero = drops.iter().map(|d| d.2).filter(|e| *e > 0.0);
        let (lo, hi) = nonzero.fold((f64::INFINITY, 0.0f64), |(a, b), e| (a.min(e), b.max(e)));
        let (lo, hi) = if lo.is_finite() { (lo, hi) } else { (1e-3, 1.0) };
        let (y_lo, y_hi) = (lo / 4.0, hi * 2.0);
        let mut chart = ChartBuilder::on(area)
            .caption("Drop-time error (exact drops on the bottom edge)", (FONT, style::CAPTION))
            .margin(16)
            .margin_right(30)
            .x_label_area_size(56)
            .y_label_area_size(80)
            .build_cartesian_2d(x.log_scale(), (y_lo..y_hi).log_scale())?;
        chart
            .configure_mesh()
            .x_desc("speed [simulated s per CPU s, one core] (log)")
            .y_desc("|drop-time error| [s] (log)")
            .axis_desc_style((FONT, style::AXIS))
            .label_style((FONT, style::LABEL))
            .x_label_formatter(&|v| style::num(*v))
            .y_label_formatter(&|v| style::num(*v))
            .draw()?;
        let keys: Vec<String> = self.rows.iter().map(series).collect();
        let integrators = grid::first_seen(keys.iter().map(String::as_str));
        let backends = grid::first_seen(self.rows.iter().map(|r| r.backend.as_str()));
        chart.draw_series(drops.iter().map(|(r, s, e)| {
            let k = integrators.iter().position(|i| *i == series(r)).unwrap_or(0);
            let m = backends.iter().position(|b| *b == r.backend).unwrap_or(0);
            let y = if *e > 0.0 { *e } else { y_lo * 1.3 };
            marker(m, (*s, y), style::SERIES[k % style::SERIES.len()])
        }))?;
        for (_, s, e) in drops.iter().filter(|d| d.0.is_default) {
            let y = if *e > 0.0 { *e } else { y_lo * 1.3 };
            chart.plotting_area().draw(&Circle::new((*s, y), 15, BLACK.stroke_width(3)))?;
        }
        Ok(())
    }
}

impl Chart for SpeedAccuracy {
    fn size(&self) -> (u32, u32) {
        if self.drop_errors().is_empty() { (1200, 820) } else { (1200, 1160) }
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        let ok: Vec<(&SpeedAccuracyRow, f64, f64)> =
            self.rows.iter().filter_map(|r| plottable(r).map(|(s, e)| (r, s, e))).collect();
        let speeds = self.rows.iter().filter_map(|r| r.sim_s_per_cpu_s).filter(|s| s.is_finite() && *s > 0.0);
        let (s_lo, s_hi) = speeds.fold((f64::INFINITY, 0.0f64), |(a, b), s| (a.min(s), b.max(s)));
        let (s_lo, s_hi) = if s_lo.is_finite() { (s_lo, s_hi) } else { (0.1, 10.0) };
        let (e_lo, e_hi) = ok.iter().fold((f64::INFINITY, 0.0f64), |(a, b), p| (a.min(p.2), b.max(p.2)));
        let (e_lo, e_hi) = if e_lo.is_finite() { (e_lo, e_hi) } else { (1e-3, 1.0) };
        // Room below for the reference (zero error) and above for failed runs.
        let (y_lo, y_hi) = (e_lo / 4.0, e_hi * 4.0);
        let root = root.titled("Speed against accuracy of the simulation settings", (FONT, style::TITLE))?;
        let drops = self.drop_errors();
        let (top, bottom) = if drops.is_empty() {
            (root.clone(), None)
        } else {
            let (_, h) = root.dim_in_pixel();
            let (a, b) = root.split_vertically(h - 330);
            (a, Some(b))
        };
        if let Some(area) = &bottom {
            self.draw_drop_panel(area, &drops, (s_lo / 2.0)..(s_hi * 2.0))?;
        }
        let mut chart = ChartBuilder::on(&top)
            .margin(16)
            .margin_right(30)
            .x_label_area_size(56)
            .y_label_area_size(80)
            .build_cartesian_2d(((s_lo / 2.0)..(s_hi * 2.0)).log_scale(), (y_lo..y_hi).log_scale())?;
        chart
            .configure_mesh()
            .x_desc("speed [simulated s per CPU s, one core] (log)")
            .y_desc("sensor-force RMSE against the reference [N] (log)")
            .axis_desc_style((FONT, style::AXIS))
            .label_style((FONT, style::LABEL))
            .x_label_formatter(&|v| style::num(*v))
            .y_label_formatter(&|v| style::num(*v))
            .draw()?;

        let front = pareto_front(&self.rows);
        let front_pts: Vec<(f64, f64)> = front.iter().filter_map(|i| plottable(&self.rows[*i])).collect();
        chart
            .draw_series(LineSeries::new(front_pts.clone(), RGBColor(60, 60, 60).stroke_width(2)))?
            .label("Pareto front")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RGBColor(60, 60, 60).stroke_width(2)));

        let keys: Vec<String> = self.rows.iter().map(series).collect();
        let integrators = grid::first_seen(keys.iter().map(String::as_str));
        let backends = grid::first_seen(self.rows.iter().map(|r| r.backend.as_str()));
        for (k, integrator) in integrators.iter().enumerate() {
            let color = style::SERIES[k % style::SERIES.len()];
            for (m, backend) in backends.iter().enumerate() {
                let pts: Vec<(f64, f64)> = ok
                    .iter()
                    .filter(|(r, _, _)| series(r) == *integrator && r.backend == *backend)
                    .map(|(_, s, e)| (*s, *e))
                    .collect();
                if pts.is_empty() {
                    continue;
                }
                let label =
                    if backends.len() > 1 { format!("{backend} / {integrator}") } else { integrator.to_string() };
                chart
                    .draw_series(pts.into_iter().map(move |p| marker(m, p, color)))?
                    .label(label)
                    .legend(move |(x, y)| marker_px(m, (x + 10, y), color));
            }
        }

        // Failed settings along the top edge, at their speed.
        let failed: Vec<f64> = self
            .rows
            .iter()
            .filter(|r| r.status != "ok")
            .filter_map(|r| r.sim_s_per_cpu_s)
            .filter(|s| s.is_finite() && *s > 0.0)
            .collect();
        if !failed.is_empty() {
            let y = y_hi / 1.5;
            chart
                .draw_series(failed.iter().map(|s| Cross::new((*s, y), 7, style::BAD.stroke_width(2))))?
                .label("diverged / error (drawn at the top)")
                .legend(|(x, y)| Cross::new((x + 10, y), 6, style::BAD.stroke_width(2)));
        }

        // A label goes right of its point in the chart's left 60 % (log speed) and left of it
        // beyond, so that the fastest points' labels stay inside the plot; `gap` is the factor in
        // speed between the point and the label's near end.
        let (x_lo, x_hi) = ((s_lo / 2.0).ln(), (s_hi * 2.0).ln());
        let note = |text: String, (s, e): (f64, f64), gap: f64, v: VPos| -> DrawResult {
            let left_side = (s.ln() - x_lo) / (x_hi - x_lo) < 0.6;
            let (h, at, text) = if left_side {
                (HPos::Left, s * gap, format!("  {text}"))
            } else {
                (HPos::Right, s / gap, format!("{text}  "))
            };
            let font = TextStyle::from((FONT, style::SMALL).into_font()).pos(Pos::new(h, v));
            chart.plotting_area().draw(&Text::new(text, (at, e), font))?;
            Ok(())
        };
        for i in &front {
            let r = &self.rows[*i];
            if r.is_default {
                continue; // labelled below as the default
            }
            if let Some((s, e)) = plottable(r) {
                note(settings(r), (s, e), 1.08, VPos::Top)?;
            }
        }
        for r in self.rows.iter().filter(|r| r.is_reference) {
            let Some(s) = r.sim_s_per_cpu_s.filter(|s| s.is_finite() && *s > 0.0) else { continue };
            // The reference has zero error against itself; it sits on the bottom edge then.
            let e = plottable(r).map_or(y_lo * 1.4, |p| p.1);
            chart.plotting_area().draw(&TriangleMarker::new((s, e), 10, BLACK.filled()))?;
            let zero = if plottable(r).is_none() { ", zero error by definition" } else { "" };
            let text = format!("reference: {} ({}){zero}", settings(r), r.integrator);
            note(text, (s, e), 1.05, VPos::Center)?;
        }
        for r in self.rows.iter().filter(|r| r.is_default) {
            if let Some((s, e)) = plottable(r) {
                chart.plotting_area().draw(&Circle::new((s, e), 15, BLACK.stroke_width(3)))?;
                note(format!("default: {} ({})", settings(r), r.integrator), (s, e), 1.12, VPos::Bottom)?;
            }
        }
        chart
            .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())?
            .label("default settings (ringed)")
            .legend(|(x, y)| Circle::new((x + 10, y), 8, BLACK.stroke_width(2)));
        chart
            .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())?
            .label("reference run (triangle)")
            .legend(|(x, y)| TriangleMarker::new((x + 10, y), 8, BLACK.filled()));
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

/// The marker of backend number `m` at a data point: circle, cross, then triangle (the black
/// triangle is the reference run's, so the second backend gets the cross).
fn marker<DB: DrawingBackend>(m: usize, at: (f64, f64), color: RGBColor) -> DynElement<'static, DB, (f64, f64)> {
    match m % 3 {
        0 => Circle::new(at, 6, color.filled()).into_dyn(),
        1 => Cross::new(at, 7, color.stroke_width(4)).into_dyn(),
        _ => TriangleMarker::new(at, 7, color.filled()).into_dyn(),
    }
}

/// The same marker in the legend (pixel coordinates).
fn marker_px<DB: DrawingBackend>(m: usize, at: (i32, i32), color: RGBColor) -> DynElement<'static, DB, (i32, i32)> {
    match m % 3 {
        0 => Circle::new(at, 6, color.filled()).into_dyn(),
        1 => Cross::new(at, 7, color.stroke_width(4)).into_dyn(),
        _ => TriangleMarker::new(at, 7, color.filled()).into_dyn(),
    }
}
