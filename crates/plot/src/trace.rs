//! One run's `trace.csv` (and `summary.json` if present) as the paper's Fig. 9: the forces
//! (true, estimated, uncompensated, setpoint) above, the controller output below, the task
//! phases shaded and named, the drop marked when the run dropped the object.

use super::input::Table;
use super::style::{self, FONT};
use super::{Chart, DrawResult, PlotError};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// The task phases as written in traces, in task order.
pub const PHASES: [&str; 9] = ["home", "grow", "wrap", "grasp", "lift", "transfer", "lower", "release", "done"];

/// One control tick of the trace (the columns the chart uses).
#[derive(Debug, Clone, PartialEq)]
pub struct TracePoint {
    /// Cell time since activation \[s\].
    pub time_s: f64,
    /// Task phase name.
    pub phase: String,
    /// True normal force on the sensor \[N\] (NaN without ground truth).
    pub true_force_n: f64,
    /// Temperature-compensated estimate \[N\].
    pub force_n: f64,
    /// Estimate without temperature compensation \[N\].
    pub force_uncompensated_n: f64,
    /// Force setpoint \[N\].
    pub setpoint_n: f64,
    /// Whether the force controller ran.
    pub controller_on: bool,
    /// Controller output, twine motor speed [°/s].
    pub controller_output_deg_s: f64,
}

/// PID gains as in `summary.json`.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
pub struct Gains {
    /// Proportional gain [(°/s)/N].
    pub kp: f64,
    /// Integral gain [(°/s)/(N·s)].
    pub ki: f64,
    /// Derivative gain [(°/s)/(N/s)].
    pub kd: f64,
}

/// The fields of `summary.json` the chart uses (all optional: a chart of a partial run is
/// still useful; unknown fields are ignored because the summary grows).
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(default)]
pub struct SummaryInfo {
    /// Scenario name.
    pub scenario: Option<String>,
    /// Object name.
    pub object: Option<String>,
    /// Force control on while the arm moves.
    pub feedback: Option<bool>,
    /// PID gains.
    pub gains: Option<Gains>,
    /// Force setpoint \[N\].
    pub setpoint_n: Option<f64>,
    /// "held", "dropped" or "error".
    pub outcome: Option<String>,
    /// Time of the drop since activation \[s\].
    pub drop_cell_time_s: Option<f64>,
    /// Time of the drop after the arm started moving \[s\].
    pub drop_time_s: Option<f64>,
    /// Phase of the drop.
    pub drop_phase: Option<String>,
    /// When the sensor-based detector saw slip start, after the arm started moving \[s\].
    pub slip_detected_s: Option<f64>,
    /// The error that ended the run.
    pub error: Option<String>,
}

/// A run directory's trace and summary.
#[derive(Debug, Clone, PartialEq)]
pub struct RunTrace {
    /// Name for the title when the summary has none (the directory name).
    pub name: String,
    /// The ticks, in time order.
    pub points: Vec<TracePoint>,
    /// The summary, if `summary.json` exists.
    pub summary: Option<SummaryInfo>,
}

/// Reads `run_dir/trace.csv` and, if present, `run_dir/summary.json`.
pub fn read(run_dir: &Path) -> Result<RunTrace, PlotError> {
    let t = Table::read(&run_dir.join("trace.csv"))?;
    let c = |n: &str| t.column(n);
    let (time, phase, truth, force) = (c("time_s")?, c("phase")?, c("true_force_n")?, c("force_n")?);
    let (unc, setpoint, on, out) =
        (c("force_uncompensated_n")?, c("setpoint_n")?, c("controller_on")?, c("controller_output_deg_s")?);
    let mut points = Vec::with_capacity(t.rows.len());
    for r in t.iter() {
        let p = TracePoint {
            time_s: r.f64(time)?,
            phase: r.one_of(phase, &PHASES)?,
            true_force_n: r.plotted(truth)?,
            force_n: r.plotted(force)?,
            force_uncompensated_n: r.plotted(unc)?,
            setpoint_n: r.plotted(setpoint)?,
            controller_on: r.bool(on)?,
            controller_output_deg_s: r.plotted(out)?,
        };
        if !p.time_s.is_finite() || points.last().is_some_and(|q: &TracePoint| q.time_s > p.time_s) {
            return Err(r.error(format!("time_s {} is not finite or goes backwards", p.time_s)));
        }
        points.push(p);
    }
    if points.len() < 2 {
        return Err(t.empty("fewer than two rows: nothing to draw"));
    }
    // The estimate, the setpoint and the controller's output are always there; only the ground
    // truth may be all NaN (a real cell has none). A column without a single number is refused.
    type Column = (&'static str, fn(&TracePoint) -> f64);
    let columns: [Column; 4] = [
        ("force_n", |p| p.force_n),
        ("force_uncompensated_n", |p| p.force_uncompensated_n),
        ("setpoint_n", |p| p.setpoint_n),
        ("controller_output_deg_s", |p| p.controller_output_deg_s),
    ];
    for (name, value) in columns {
        if !points.iter().any(|p| value(p).is_finite()) {
            return Err(t.empty(&format!("column `{name}` has no finite value: nothing to draw")));
        }
    }
    let summary_path = run_dir.join("summary.json");
    let summary = if summary_path.is_file() {
        let file = summary_path.display().to_string();
        let text =
            std::fs::read_to_string(&summary_path).map_err(|e| PlotError::Io { file: file.clone(), cause: e })?;
        Some(serde_json::from_str::<SummaryInfo>(&text).map_err(|e| PlotError::Malformed {
            file,
            line: e.line() as u64,
            message: e.to_string(),
        })?)
    } else {
        None
    };
    let name = run_dir
        .canonicalize()
        .ok()
        .and_then(|p| p.file_name().map(|n| n.to_string_lossy().to_string()))
        .unwrap_or_else(|| run_dir.display().to_string());
    Ok(RunTrace { name, points, summary })
}

/// Draws `trace.png/.svg` in `out_dir`; returns the files written.
pub fn render(run: &RunTrace, out_dir: &Path) -> Result<Vec<PathBuf>, PlotError> {
    super::save(&TraceChart { run }, out_dir, "trace")
}

/// Most points per drawn line; longer traces keep each bucket's min and max so peaks survive.
const MAX_POINTS: usize = 4000;

/// `(t, v)` as polylines: split where `v` is not finite, thinned to about [`MAX_POINTS`].
fn polylines(points: &[TracePoint], v: impl Fn(&TracePoint) -> f64) -> Vec<Vec<(f64, f64)>> {
    let bucket = (points.len() / (MAX_POINTS / 2)).max(1);
    let mut lines: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut current: Vec<(f64, f64)> = Vec::new();
    for chunk in points.chunks(bucket) {
        let finite: Vec<(f64, f64)> = chunk.iter().map(|p| (p.time_s, v(p))).filter(|q| q.1.is_finite()).collect();
        if finite.len() < chunk.len() && !current.is_empty() {
            lines.push(std::mem::take(&mut current));
        }
        if bucket == 1 || finite.len() <= 2 {
            current.extend(finite);
        } else {
            let lo = finite.iter().copied().min_by(|a, b| a.1.total_cmp(&b.1)).unwrap_or(finite[0]);
            let hi = finite.iter().copied().max_by(|a, b| a.1.total_cmp(&b.1)).unwrap_or(finite[0]);
            let (a, b) = if lo.0 <= hi.0 { (lo, hi) } else { (hi, lo) };
            current.push(a);
            current.push(b);
        }
    }
    if !current.is_empty() {
        lines.push(current);
    }
    lines
}

/// Background of each phase (None: left white).
fn phase_color(phase: &str) -> Option<RGBColor> {
    match phase {
        "grow" => Some(RGBColor(214, 234, 248)),
        "wrap" => Some(RGBColor(232, 218, 239)),
        "grasp" => Some(RGBColor(213, 245, 227)),
        "lift" => Some(RGBColor(252, 243, 207)),
        "transfer" => Some(RGBColor(250, 229, 211)),
        "lower" => Some(RGBColor(252, 243, 207)),
        "release" => Some(RGBColor(229, 232, 232)),
        _ => None,
    }
}

/// (start, end, phase) of each run of equal phases.
fn phase_spans(points: &[TracePoint]) -> Vec<(f64, f64, &str)> {
    let mut spans: Vec<(f64, f64, &str)> = Vec::new();
    for (i, p) in points.iter().enumerate() {
        let end = points.get(i + 1).map_or(p.time_s, |q| q.time_s);
        match spans.last_mut() {
            Some(s) if s.2 == p.phase => s.1 = end,
            _ => spans.push((p.time_s, end, &p.phase)),
        }
    }
    spans
}

struct TraceChart<'a> {
    run: &'a RunTrace,
}

const TRUE_C: RGBColor = RGBColor(0, 0, 0);
const EST_C: RGBColor = style::SERIES[0];
const UNC_C: RGBColor = style::SERIES[1];
const SET_C: RGBColor = style::SERIES[2];
const OUT_C: RGBColor = style::SERIES[3];
const DROP_C: RGBColor = style::BAD;
const MOVE_C: RGBColor = RGBColor(60, 60, 60);
const SLIP_C: RGBColor = style::OTHER;

impl TraceChart<'_> {
    fn title(&self) -> String {
        let s = self.run.summary.clone().unwrap_or_default();
        let mut t = format!("Force trace: {}", s.scenario.unwrap_or_else(|| self.run.name.clone()));
        if let Some(o) = s.object {
            t += &format!(", {o}");
        }
        if let Some(g) = s.gains {
            t += &format!(", Kp {} Ki {} Kd {}", style::num(g.kp), style::num(g.ki), style::num(g.kd));
        }
        if s.feedback == Some(false) {
            t += ", no feedback while moving";
        }
        if let Some(o) = s.outcome {
            t += &format!(": {o}");
        }
        t
    }

    /// Cell time when the arm starts moving the object (first `lift` tick), the paper's Fig. 9 origin.
    fn motion_start(&self) -> Option<f64> {
        self.run.points.iter().find(|p| p.phase == "lift").map(|p| p.time_s)
    }

    /// Cell time when the sensor saw slip start (the summary counts it from the motion start).
    fn slip(&self) -> Option<f64> {
        Some(self.motion_start()? + self.run.summary.as_ref()?.slip_detected_s?)
    }

    /// The drop to mark: (cell time, label).
    fn drop(&self) -> Option<(f64, String)> {
        let s = self.run.summary.as_ref()?;
        if s.outcome.as_deref() != Some("dropped") {
            return None;
        }
        let t = s.drop_cell_time_s?;
        let mut label = format!("drop at {} s", style::num(t));
        if let Some(p) = &s.drop_phase {
            label += &format!(" ({p})");
        }
        Some((t, label))
    }
}

impl Chart for TraceChart<'_> {
    fn size(&self) -> (u32, u32) {
        (1400, 900)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        let pts = &self.run.points;
        let root = root.titled(&self.title(), (FONT, style::TITLE))?;
        let (w, h) = root.dim_in_pixel();
        let (plots, key) = root.split_horizontally(w - 260);
        let (top, bottom) = plots.split_vertically((h as f64 * 0.64) as u32);
        let (t0, t1) = (pts[0].time_s, pts[pts.len() - 1].time_s);
        let forces = pts.iter().flat_map(|p| [p.true_force_n, p.force_n, p.force_uncompensated_n, p.setpoint_n]);
        let (f_lo, f_hi) = forces.filter(|v| v.is_finite()).fold((0.0f64, 0.0f64), |(a, b), v| (a.min(v), b.max(v)));
        let f_hi = if f_hi > f_lo { f_hi } else { f_lo + 1.0 };
        // Headroom on top for the phase names.
        let f_range = (f_lo - 0.05 * (f_hi - f_lo))..(f_hi + 0.22 * (f_hi - f_lo));
        let outs = pts.iter().map(|p| p.controller_output_deg_s).filter(|v| v.is_finite());
        let (o_lo, o_hi) = outs.fold((0.0f64, 0.0f64), |(a, b), v| (a.min(v), b.max(v)));
        let pad = 0.1 * (o_hi - o_lo).max(1.0);
        let o_range = (o_lo - pad)..(o_hi + pad);
        let drop = self.drop();

        let mut fc = ChartBuilder::on(&top)
            .margin(12)
            .x_label_area_size(30)
            .y_label_area_size(70)
            .build_cartesian_2d(t0..t1, f_range.clone())?;
        fc.configure_mesh()
            .light_line_style(RGBColor(235, 235, 235))
            .y_desc("force [N]")
            .y_label_formatter(&|v| style::num(*v))
            .axis_desc_style((FONT, style::AXIS))
            .label_style((FONT, style::LABEL))
            .x_label_formatter(&|v| style::num(*v))
            .draw()?;
        let mut oc = ChartBuilder::on(&bottom)
            .margin(12)
            .x_label_area_size(52)
            .y_label_area_size(70)
            .build_cartesian_2d(t0..t1, o_range.clone())?;
        oc.configure_mesh()
            .light_line_style(RGBColor(235, 235, 235))
            .x_desc("time since activation [s]")
            .y_desc("twine speed [°/s]")
            .y_label_formatter(&|v| style::num(*v))
            .axis_desc_style((FONT, style::AXIS))
            .label_style((FONT, style::LABEL))
            .x_label_formatter(&|v| style::num(*v))
            .draw()?;

        // Phases behind the data, named at the top of the force panel where they fit.
        for (a, b, phase) in phase_spans(pts) {
            if let Some(c) = phase_color(phase) {
                fc.draw_series(std::iter::once(Rectangle::new([(a, f_range.start), (b, f_range.end)], c.filled())))?;
                oc.draw_series(std::iter::once(Rectangle::new([(a, o_range.start), (b, o_range.end)], c.filled())))?;
            }
            let px = |t: f64| fc.backend_coord(&(t, f_range.end)).0;
            let text_px = phase.len() as i32 * 8 + 6;
            // Centre the name in the span, or in the wider side of it when the drop line crosses it.
            let mut span = (a, b);
            if let Some((t, _)) = &drop
                && *t > a
                && *t < b
                && (px((a + b) / 2.0) - px(*t)).abs() < text_px / 2 + 4
            {
                span = if *t - a > b - *t { (a, *t) } else { (*t, b) };
            }
            if px(span.1) - px(span.0) > text_px {
                let font = TextStyle::from((FONT, style::SMALL).into_font()).pos(Pos::new(HPos::Center, VPos::Top));
                let y = f_range.end - 0.015 * (f_range.end - f_range.start);
                fc.plotting_area().draw(&Text::new(phase.to_string(), ((span.0 + span.1) / 2.0, y), font))?;
            }
        }

        for line in polylines(pts, |p| p.force_uncompensated_n) {
            fc.draw_series(LineSeries::new(line, UNC_C.stroke_width(1)))?;
        }
        fc.draw_series(DashedLineSeries::new(
            pts.iter().filter(|p| p.setpoint_n.is_finite()).map(|p| (p.time_s, p.setpoint_n)),
            8,
            5,
            SET_C.stroke_width(2),
        ))?;
        let has_truth = pts.iter().any(|p| p.true_force_n.is_finite());
        // Dense, noisy series are drawn one pixel wide: the bitmap backend joins thick lines with
        // mitres, which at the sharp reversals of a noisy trace shoot spikes across the chart.
        for line in polylines(pts, |p| p.true_force_n) {
            fc.draw_series(LineSeries::new(line, TRUE_C.stroke_width(1)))?;
        }
        for line in polylines(pts, |p| p.force_n) {
            fc.draw_series(LineSeries::new(line, EST_C.stroke_width(1)))?;
        }
        oc.draw_series(LineSeries::new([(t0, 0.0), (t1, 0.0)], RGBColor(150, 150, 150).stroke_width(1)))?;
        for line in polylines(pts, |p| p.controller_output_deg_s) {
            oc.draw_series(LineSeries::new(line, OUT_C.stroke_width(1)))?;
        }

        // Arm start and slip detection: solid lines, named near the bottom of the force panel.
        // Names go left of their line (the force is high there while held; a drop's fall fills the
        // right side), at two heights so that close lines do not overwrite each other.
        let span = f_range.end - f_range.start;
        let marks =
            [(self.motion_start(), MOVE_C, "arm starts moving", 0.03), (self.slip(), SLIP_C, "slip detected", 0.10)];
        for (t, c, text, dy) in marks {
            let Some(t) = t else { continue };
            fc.draw_series(LineSeries::new([(t, f_range.start), (t, f_range.end)], c.stroke_width(2)))?;
            oc.draw_series(LineSeries::new([(t, o_range.start), (t, o_range.end)], c.stroke_width(2)))?;
            let font =
                TextStyle::from((FONT, style::SMALL).into_font()).color(&c).pos(Pos::new(HPos::Right, VPos::Bottom));
            fc.plotting_area().draw(&Text::new(
                text.to_string(),
                (t - 0.005 * (t1 - t0), f_range.start + dy * span),
                font,
            ))?;
        }

        if let Some((t, label)) = &drop {
            let f_line = [(*t, f_range.start), (*t, f_range.end)];
            fc.draw_series(DashedLineSeries::new(f_line, 10, 6, DROP_C.stroke_width(3)))?;
            let o_line = [(*t, o_range.start), (*t, o_range.end)];
            oc.draw_series(DashedLineSeries::new(o_line, 10, 6, DROP_C.stroke_width(3)))?;
            // Label to the right of the line unless it would run off the panel.
            let right = (t1 - t) / (t1 - t0) > 0.25;
            let hpos = if right { HPos::Left } else { HPos::Right };
            let font = (FONT, style::LABEL).into_font().color(&DROP_C).pos(Pos::new(hpos, VPos::Top));
            let y = f_range.end - 0.09 * (f_range.end - f_range.start);
            let x = if right { t + 0.01 * (t1 - t0) } else { t - 0.01 * (t1 - t0) };
            fc.plotting_area().draw(&Text::new(label.clone(), (x, y), font))?;
        }

        // The key, outside the data so it hides nothing.
        let mut entries: Vec<(RGBColor, bool, &str)> = Vec::new();
        if has_truth {
            entries.push((TRUE_C, false, "true force"));
        }
        entries.push((EST_C, false, "estimate (compensated)"));
        entries.push((UNC_C, false, "uncompensated estimate"));
        entries.push((SET_C, true, "setpoint"));
        if self.motion_start().is_some() {
            entries.push((MOVE_C, false, "arm starts moving"));
        }
        if self.slip().is_some() {
            entries.push((SLIP_C, false, "slip detected (sensor)"));
        }
        if drop.is_some() {
            entries.push((DROP_C, true, "object dropped"));
        }
        for (i, (c, dashed, text)) in entries.iter().enumerate() {
            let y = 40 + 26 * i as i32;
            if *dashed {
                key.draw(&PathElement::new(vec![(10, y), (18, y)], c.stroke_width(2)))?;
                key.draw(&PathElement::new(vec![(24, y), (34, y)], c.stroke_width(2)))?;
            } else {
                key.draw(&PathElement::new(vec![(10, y), (34, y)], c.stroke_width(2)))?;
            }
            key.draw(&Text::new(text.to_string(), (42, y - 8), (FONT, style::LABEL).into_font()))?;
        }
        let y = (h as f64 * 0.64) as i32 + 40;
        key.draw(&PathElement::new(vec![(10, y), (34, y)], OUT_C.stroke_width(2)))?;
        key.draw(&Text::new("controller output", (42, y - 8), (FONT, style::LABEL).into_font()))?;
        key.draw(&Text::new("(twine motor speed)", (42, y + 10), (FONT, style::LABEL).into_font()))?;
        let on: Vec<&TracePoint> = pts.iter().filter(|p| p.controller_on).collect();
        if let (Some(a), Some(b)) = (on.first(), on.last()) {
            let text = format!("force control on {}–{} s", style::num(a.time_s), style::num(b.time_s));
            key.draw(&Text::new(text, (10, y + 36), (FONT, style::SMALL).into_font()))?;
        }
        Ok(())
    }
}
