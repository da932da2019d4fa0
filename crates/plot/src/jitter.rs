//! `jitter.csv` (`tendril chart jitter`): how far the real path's lift is from the twin's against
//! the longest stall injected into the virtual devices' links, with the tolerance and the runs a
//! watchdog stopped.

use super::input::Table;
use super::style::{self, FONT};
use super::{Chart, DrawResult, PlotError};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// One run of the jitter study.
#[derive(Debug, Clone, PartialEq)]
pub struct JitterRow {
    /// `sweep`, or the profile's name.
    pub case: String,
    /// The link the jitter was injected into, or `all`.
    pub link: String,
    /// Longest stall injected \[ms\].
    pub longest_stall_ms: f64,
    /// Seed of the injected delays.
    pub seed: u64,
    /// "held", "dropped" or "error".
    pub outcome: String,
    /// Whether a watchdog stopped the run.
    pub watchdog: bool,
    /// Largest difference of a force percentile from the twin's in the grasp \[N\] (infinite: not reached).
    pub grasp_gap_n: f64,
    /// ... in the lift \[N\].
    pub lift_gap_n: f64,
    /// Whether the run ended as the twin's (held, dropped) without an error, every phase within
    /// the tolerances of the twin's.
    pub agrees: bool,
    /// The slip detector's drop alarms (on the twin's run of the short lift: none).
    pub drop_alarms: u64,
    /// The lift's tolerance the run was judged by \[N\] (`tendril_run::compare::TOLERANCES`).
    pub tolerance_n: f64,
    /// The oldest sample any tick read, over the three streams \[ms\].
    pub oldest_sample_ms: f64,
    /// The error that ended the run, if any.
    pub error: String,
}

/// Reads `jitter.csv`.
pub fn read(path: &Path) -> Result<Vec<JitterRow>, PlotError> {
    let t = Table::read(path)?;
    let c = |name| t.column(name);
    let (case, link, stall, seed, outcome) =
        (c("case")?, c("link")?, c("longest_stall_ms")?, c("seed")?, c("outcome")?);
    let (watchdog, grasp, lift, agrees, alarms) =
        (c("watchdog")?, c("grasp_gap_n")?, c("lift_gap_n")?, c("agrees")?, c("drop_alarms")?);
    let (tolerance, oldest, error) = (c("tolerance_n")?, c("oldest_sample_ms")?, c("error")?);
    let rows = t
        .iter()
        .map(|r| {
            Ok(JitterRow {
                case: r.text(case).to_string(),
                link: r.text(link).to_string(),
                longest_stall_ms: r.plotted(stall)?,
                seed: r.f64(seed)? as u64,
                outcome: r.one_of(outcome, &["held", "dropped", "error"])?,
                watchdog: r.bool(watchdog)?,
                grasp_gap_n: r.opt_f64(grasp)?.unwrap_or(f64::INFINITY),
                lift_gap_n: r.opt_f64(lift)?.unwrap_or(f64::INFINITY),
                agrees: r.bool(agrees)?,
                drop_alarms: r.f64(alarms)? as u64,
                tolerance_n: r.positive(tolerance)?,
                oldest_sample_ms: r.plotted(oldest)?,
                error: r.text(error).to_string(),
            })
        })
        .collect::<Result<Vec<_>, PlotError>>()?;
    if rows.is_empty() {
        return Err(t.empty("no rows to plot"));
    }
    Ok(rows)
}

/// Draws `jitter.png/.svg` in `out_dir`; returns the files written.
pub fn render(rows: &[JitterRow], out_dir: &Path) -> Result<Vec<PathBuf>, PlotError> {
    super::save(&JitterChart { rows: rows.to_vec() }, out_dir, "jitter")
}

struct JitterChart {
    rows: Vec<JitterRow>,
}

/// The y axis' range \[N\]: gaps below it are drawn on its floor, runs that never reached the lift
/// or were stopped on its ceiling.
const Y_RANGE: (f64, f64) = (1e-3, 5.0);

impl Chart for JitterChart {
    fn size(&self) -> (u32, u32) {
        (1100, 640)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        let root =
            root.titled("The real path under injected jitter: the lift against the twin's", (FONT, style::TITLE))?;
        let (w, _) = root.dim_in_pixel();
        let (plot, key) = root.split_horizontally(w - 260);
        let x_max = self.rows.iter().map(|r| r.longest_stall_ms).fold(10.0, f64::max) * 1.08;
        let mut chart = ChartBuilder::on(&plot)
            .margin(16)
            .x_label_area_size(56)
            .y_label_area_size(80)
            .build_cartesian_2d(-0.03 * x_max..x_max, (Y_RANGE.0..Y_RANGE.1).log_scale())?;
        chart
            .configure_mesh()
            .x_desc("longest stall injected [ms] (stalls twice a second; profiles at their longest)")
            .y_desc("largest lift force-percentile gap [N]")
            .axis_desc_style((FONT, style::AXIS))
            .label_style((FONT, style::LABEL))
            .x_label_formatter(&|v| format!("{v:.0}"))
            .y_label_formatter(&|v| style::num(*v))
            .draw()?;
        let tol = self.rows[0].tolerance_n;
        chart.draw_series(DashedLineSeries::new(
            [(-0.03 * x_max, tol), (x_max, tol)],
            8,
            5,
            style::GOOD.stroke_width(2),
        ))?;
        let y = |r: &JitterRow| r.lift_gap_n.clamp(Y_RANGE.0, Y_RANGE.1);
        let series: [(&str, &str, RGBColor, &str); 2] = [
            ("sweep", "all", style::SERIES[0], "stalls on every link"),
            ("sweep", "rtde-in", style::SERIES[1], "stalls on the arm's commands"),
        ];
        let mut ky = 40;
        for (case, link, color, text) in series {
            let pts: Vec<&JitterRow> =
                self.rows.iter().filter(|r| r.case == case && r.link == link && !r.watchdog).collect();
            if pts.is_empty() {
                continue;
            }
            chart.draw_series(pts.iter().map(|r| Circle::new((r.longest_stall_ms, y(r)), 7, color.filled())))?;
            key.draw(&Circle::new((20, ky), 7, color.filled()))?;
            key.draw(&Text::new(text, (36, ky - 8), (FONT, style::LABEL).into_font()))?;
            ky += 28;
        }
        let profiles: Vec<&JitterRow> = self.rows.iter().filter(|r| r.case != "sweep" && !r.watchdog).collect();
        if !profiles.is_empty() {
            let color = style::OTHER;
            chart.draw_series(
                profiles.iter().map(|r| TriangleMarker::new((r.longest_stall_ms, y(r)), 9, color.filled())),
            )?;
            let font = (FONT, style::SMALL).into_font();
            for name in super::grid::first_seen(profiles.iter().map(|r| r.case.clone())) {
                if let Some(r) = profiles.iter().find(|r| r.case == name) {
                    chart.draw_series(std::iter::once(Text::new(
                        name,
                        (r.longest_stall_ms, y(r) * 1.5),
                        font.clone(),
                    )))?;
                }
            }
            key.draw(&TriangleMarker::new((20, ky), 9, color.filled()))?;
            key.draw(&Text::new("a named profile", (36, ky - 8), (FONT, style::LABEL).into_font()))?;
            ky += 28;
        }
        let stopped: Vec<&JitterRow> = self.rows.iter().filter(|r| r.watchdog).collect();
        if !stopped.is_empty() {
            chart.draw_series(
                stopped
                    .iter()
                    .map(|r| Cross::new((r.longest_stall_ms, Y_RANGE.1 * 0.8), 8, style::BAD.stroke_width(3))),
            )?;
            key.draw(&Cross::new((20, ky), 8, style::BAD.stroke_width(3)))?;
            key.draw(&Text::new("stopped by a watchdog", (36, ky - 8), (FONT, style::LABEL).into_font()))?;
            ky += 28;
        }
        key.draw(&PathElement::new(vec![(8, ky), (32, ky)], style::GOOD.stroke_width(2)))?;
        key.draw(&Text::new(format!("tolerance ({tol} N)"), (36, ky - 8), (FONT, style::LABEL).into_font()))?;
        Ok(())
    }
}
