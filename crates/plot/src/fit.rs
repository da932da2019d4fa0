//! The charts of `tendril fit` and `tendril tune`: recorded against fitted force traces with the
//! objective over the evaluations ([`FitChart`]), and a tune's objective landscape over two of its
//! parameters ([`LandscapeChart`]).

use super::style::{self, FONT};
use super::{Chart, DrawResult};
use plotters::coord::Shift;
use plotters::prelude::*;

/// One recording and the fitted twin's run of it.
#[derive(Debug, Clone, PartialEq)]
pub struct TracePair {
    /// Panel caption.
    pub name: String,
    /// Recorded (time \[s\], force \[N\]).
    pub recorded: Vec<(f64, f64)>,
    /// Fitted twin's (time \[s\], force \[N\]); empty when its run could not start.
    pub fitted: Vec<(f64, f64)>,
}

/// A fit's chart: a panel per recording, then the objective of every evaluation (failed ones at
/// the top) and the best so far.
#[derive(Debug, Clone, PartialEq)]
pub struct FitChart {
    /// Title.
    pub title: String,
    /// The recordings and the fitted runs.
    pub traces: Vec<TracePair>,
    /// (evaluation index, objective, failed), in log order.
    pub objective: Vec<(usize, f64, bool)>,
}

/// (low, high) of the finite values, with a margin; a default span when there are none.
fn span(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) =
        values.filter(|v| v.is_finite()).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let pad = 0.05 * (hi - lo).max(1e-9);
    (lo - pad, hi + pad)
}

/// The span of the values between their 0.5 % and 99.5 % quantiles, with a 25 % margin.
fn robust_span(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let mut v: Vec<f64> = values.filter(|v| v.is_finite()).collect();
    if v.is_empty() {
        return (0.0, 1.0);
    }
    v.sort_by(f64::total_cmp);
    let q = |p: f64| v[((v.len() - 1) as f64 * p).round() as usize];
    let (lo, hi) = (q(0.005).min(0.0), q(0.995));
    let pad = 0.25 * (hi - lo).max(1e-3);
    (lo - 0.2 * pad, hi + pad)
}

impl Chart for FitChart {
    fn size(&self) -> (u32, u32) {
        (1200, 300 * self.traces.len().max(1) as u32 + 360)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        let root = root.titled(&self.title, (FONT, style::TITLE))?;
        let (_, h) = root.dim_in_pixel();
        let (traces, bottom) = root.split_vertically(h.saturating_sub(340));
        let panels = traces.split_evenly((self.traces.len().max(1), 1));
        for (pair, area) in self.traces.iter().zip(&panels) {
            let all = pair.recorded.iter().chain(&pair.fitted);
            let (t0, t1) = span(all.clone().map(|p| p.0));
            // Impacts after a drop spike to the sensor's range: the axis follows the bulk of the
            // recording (of the fitted run when there is none: a fit target), and what goes beyond
            // is drawn at the edge.
            let basis = if pair.recorded.is_empty() { &pair.fitted } else { &pair.recorded };
            let (f0, f1) = robust_span(basis.iter().map(|p| p.1));
            let clip = move |&(t, f): &(f64, f64)| (t, f.clamp(f0, f1));
            let mut c = ChartBuilder::on(area)
                .caption(&pair.name, (FONT, style::CAPTION))
                .margin(10)
                .x_label_area_size(40)
                .y_label_area_size(60)
                .build_cartesian_2d(t0..t1, f0..f1)?;
            c.configure_mesh()
                .light_line_style(RGBColor(235, 235, 235))
                .x_desc("time since activation [s]")
                .y_desc("force [N]")
                .x_label_formatter(&|v| style::num(*v))
                .y_label_formatter(&|v| style::num(*v))
                .axis_desc_style((FONT, style::AXIS))
                .label_style((FONT, style::LABEL))
                .draw()?;
            let rec = style::SERIES[6];
            let fit = style::SERIES[1];
            c.draw_series(LineSeries::new(pair.recorded.iter().map(clip), rec.stroke_width(2)))?
                .label("recorded")
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], rec.stroke_width(2)));
            c.draw_series(LineSeries::new(pair.fitted.iter().map(clip), fit.stroke_width(1)))?
                .label("fitted twin")
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], fit.stroke_width(2)));
            c.configure_series_labels()
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .label_font((FONT, style::LABEL))
                .position(SeriesLabelPosition::UpperRight)
                .draw()?;
        }
        draw_objective(&bottom, &self.objective)?;
        Ok(())
    }
}

/// Five evenly spaced ticks on a log axis from `lo` to `hi`.
fn key_points(lo: f64, hi: f64) -> Vec<f64> {
    (0..5).map(|i| lo * (hi / lo).powf(f64::from(i) / 4.0)).collect()
}

/// The objective of every evaluation (log scale) and the best so far.
fn draw_objective<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, points: &[(usize, f64, bool)]) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let ok: Vec<(f64, f64)> =
        points.iter().filter(|p| !p.2 && p.1 > 0.0 && p.1.is_finite()).map(|p| (p.0 as f64, p.1)).collect();
    let (lo, hi) = ok.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| (a.min(p.1), b.max(p.1)));
    let (lo, hi) = if lo.is_finite() { (lo * 0.8, hi * 1.25) } else { (1e-3, 1.0) };
    let n = points.len().max(2) as f64;
    // Ticks placed by hand: plotters labels none on a log axis shorter than a decade.
    let y = (lo..hi).log_scale().with_key_points(key_points(lo, hi));
    let mut c = ChartBuilder::on(area)
        .caption(
            "objective over evaluations (dots; failed runs on top, red), best so far (line)",
            (FONT, style::CAPTION),
        )
        .margin(10)
        .x_label_area_size(44)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..n, y)?;
    c.configure_mesh()
        .light_line_style(RGBColor(235, 235, 235))
        .x_desc("evaluation")
        .y_desc("objective")
        .x_label_formatter(&|v| style::num(*v))
        .y_label_formatter(&|v| style::num(*v))
        .axis_desc_style((FONT, style::AXIS))
        .label_style((FONT, style::LABEL))
        .draw()?;
    c.draw_series(ok.iter().map(|&p| Circle::new(p, 3, style::SERIES[0].filled())))?;
    c.draw_series(
        points.iter().filter(|p| p.2).map(|p| Cross::new((p.0 as f64, hi / 1.1), 4, style::BAD.stroke_width(2))),
    )?;
    let mut best = f64::INFINITY;
    let line: Vec<(f64, f64)> = ok
        .iter()
        .map(|&(x, y)| {
            best = best.min(y);
            (x, best)
        })
        .collect();
    c.draw_series(LineSeries::new(line, style::SERIES[1].stroke_width(2)))?;
    Ok(())
}

/// A tune's objective landscape: every evaluation at its values of two parameters, coloured by its
/// objective (dark: better), the best ringed.
#[derive(Debug, Clone, PartialEq)]
pub struct LandscapeChart {
    /// Title.
    pub title: String,
    /// Axis names (the parameters' keys).
    pub axes: (String, String),
    /// Log axes.
    pub log: (bool, bool),
    /// (x, y, objective, failed).
    pub points: Vec<(f64, f64, f64, bool)>,
    /// The best point.
    pub best: Option<(f64, f64)>,
}

/// [`span`], with a margin by factor on a log axis of positive values (an additive one could go
/// below zero).
fn axis_span(values: impl Iterator<Item = f64> + Clone, log: bool) -> (f64, f64) {
    let (lo, hi) = values
        .clone()
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
    if log && lo > 0.0 && hi.is_finite() {
        let pad = (hi / lo).max(1.0 + 1e-9).powf(0.05);
        (lo / pad, hi * pad)
    } else {
        span(values)
    }
}

impl Chart for LandscapeChart {
    fn size(&self) -> (u32, u32) {
        (900, 760)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        let root = root.titled(&self.title, (FONT, style::TITLE))?;
        let (x0, x1) = axis_span(self.points.iter().map(|p| p.0), self.log.0);
        let (y0, y1) = axis_span(self.points.iter().map(|p| p.1), self.log.1);
        let ok: Vec<f64> = self.points.iter().filter(|p| !p.3 && p.2.is_finite()).map(|p| p.2).collect();
        let (olo, ohi) = ok.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
        let shade = |v: f64| {
            let t = if ohi > olo { ((v - olo) / (ohi - olo)).sqrt() } else { 0.0 };
            style::blend(RGBColor(20, 40, 120), RGBColor(235, 235, 160), t)
        };
        let caption = format!(
            "objective {} (dark) to {} (light); failed: red crosses; best: ringed",
            style::num(olo),
            style::num(ohi)
        );
        macro_rules! body {
            ($c:expr) => {{
                let mut c = $c;
                c.configure_mesh()
                    .light_line_style(RGBColor(235, 235, 235))
                    .x_desc(self.axes.0.as_str())
                    .y_desc(self.axes.1.as_str())
                    .x_label_formatter(&|v| style::num(*v))
                    .y_label_formatter(&|v| style::num(*v))
                    .axis_desc_style((FONT, style::AXIS))
                    .label_style((FONT, style::LABEL))
                    .draw()?;
                c.draw_series(
                    self.points.iter().filter(|p| !p.3).map(|p| Circle::new((p.0, p.1), 5, shade(p.2).filled())),
                )?;
                c.draw_series(
                    self.points.iter().filter(|p| p.3).map(|p| Cross::new((p.0, p.1), 5, style::BAD.stroke_width(2))),
                )?;
                if let Some(b) = self.best {
                    c.draw_series(std::iter::once(Circle::new(b, 10, style::BAD.stroke_width(3))))?;
                }
            }};
        }
        macro_rules! build {
            ($x:expr, $y:expr) => {
                ChartBuilder::on(&root)
                    .caption(&caption, (FONT, style::LABEL))
                    .margin(12)
                    .x_label_area_size(50)
                    .y_label_area_size(80)
                    .build_cartesian_2d($x, $y)?
            };
        }
        match (self.log.0 && x0 > 0.0, self.log.1 && y0 > 0.0) {
            (true, true) => body!(build!((x0..x1).log_scale(), (y0..y1).log_scale())),
            (true, false) => body!(build!((x0..x1).log_scale(), y0..y1)),
            (false, true) => body!(build!(x0..x1, (y0..y1).log_scale())),
            (false, false) => body!(build!(x0..x1, y0..y1)),
        }
        Ok(())
    }
}
