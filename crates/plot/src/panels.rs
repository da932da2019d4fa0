//! [`Panels`]: a grid of x-y panels, each with named series drawn as lines, markers or both; one
//! colour per series name across every panel. The cycle studies' charts (`tendril chart settle`,
//! `hold`, `detector`, `finger`) and the hour's history are drawn with it.

use super::style::{self, FONT};
use super::{Chart, DrawResult, PlotError};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mark {
    /// A line through the points in order.
    Line,
    /// A filled circle at each point.
    Dots,
    /// Both.
    LineDots,
}

/// One named series of a panel.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Its name, in the legend; series of the same name share a colour across panels.
    pub name: String,
    /// Its points (x, y); non-finite ones are left out.
    pub points: Vec<(f64, f64)>,
    /// How it is drawn.
    pub mark: Mark,
}

/// One panel: axes, caption and series.
#[derive(Debug, Clone, PartialEq)]
pub struct Panel {
    /// The caption above it.
    pub caption: String,
    /// The x axis' description (with its unit).
    pub x_desc: String,
    /// The y axis' description (with its unit).
    pub y_desc: String,
    /// The series.
    pub series: Vec<Series>,
    /// The y range (default: from 0, or the lowest value if negative, to 5 % above the highest).
    pub y_range: Option<(f64, f64)>,
}

/// A chart of panels in a grid `columns` wide, under one title.
#[derive(Debug, Clone, PartialEq)]
pub struct Panels {
    /// The title.
    pub title: String,
    /// The panels, row by row.
    pub panels: Vec<Panel>,
    /// Panels per row.
    pub columns: usize,
}

/// Draws `chart` as `out_dir/stem.png` and `.svg`; returns the files written.
pub fn render(chart: &Panels, out_dir: &Path, stem: &str) -> Result<Vec<PathBuf>, PlotError> {
    super::save(chart, out_dir, stem)
}

impl Panels {
    fn rows(&self) -> usize {
        self.panels.len().div_ceil(self.columns.max(1)).max(1)
    }

    /// Each series name's colour: its index among the names in the order first seen.
    fn color(&self, name: &str) -> RGBColor {
        let names = super::grid::first_seen(self.panels.iter().flat_map(|p| p.series.iter().map(|s| s.name.clone())));
        let i = names.iter().position(|n| n == name).unwrap_or(0);
        style::SERIES[i % style::SERIES.len()]
    }

    fn panel<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>, p: &Panel) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        let points = || p.series.iter().flat_map(|s| s.points.iter()).filter(|(x, y)| x.is_finite() && y.is_finite());
        let (x0, x1) = points().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), (x, _)| (a.min(*x), b.max(*x)));
        let (x0, x1) = if x0.is_finite() { (x0, x1) } else { (0.0, 1.0) };
        let pad = if x1 > x0 { 0.04 * (x1 - x0) } else { 0.5_f64.max(0.1 * x0.abs()) };
        let (y0, y1) = p.y_range.unwrap_or_else(|| {
            let (lo, hi) = points().fold((0.0_f64, f64::NEG_INFINITY), |(a, b), (_, y)| (a.min(*y), b.max(*y)));
            let hi = if hi.is_finite() && hi > lo { hi } else { lo + 1.0 };
            (lo, hi + 0.05 * (hi - lo))
        });
        let mut chart = ChartBuilder::on(area)
            .caption(&p.caption, (FONT, style::CAPTION))
            .margin(10)
            .x_label_area_size(44)
            .y_label_area_size(64)
            .build_cartesian_2d((x0 - pad)..(x1 + pad), y0..y1)?;
        chart
            .configure_mesh()
            .x_desc(&p.x_desc)
            .y_desc(&p.y_desc)
            .x_labels(8)
            .y_labels(6)
            .x_label_formatter(&|v| style::num(*v))
            .y_label_formatter(&|v| style::num(*v))
            .axis_desc_style((FONT, style::AXIS))
            .label_style((FONT, style::SMALL))
            .draw()?;
        for s in &p.series {
            let color = self.color(&s.name);
            let pts: Vec<(f64, f64)> =
                s.points.iter().copied().filter(|(x, y)| x.is_finite() && y.is_finite()).collect();
            if matches!(s.mark, Mark::Line | Mark::LineDots) {
                chart
                    .draw_series(std::iter::once(PathElement::new(pts.clone(), color.stroke_width(2))))?
                    .label(s.name.clone())
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], color.stroke_width(2)));
            }
            if matches!(s.mark, Mark::Dots | Mark::LineDots) {
                let drawn = chart.draw_series(pts.iter().map(|&(x, y)| Circle::new((x, y), 4, color.filled())))?;
                if s.mark == Mark::Dots {
                    drawn.label(s.name.clone()).legend(move |(x, y)| Circle::new((x + 9, y), 4, color.filled()));
                }
            }
        }
        if !p.series.is_empty() {
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK.mix(0.3))
                .label_font((FONT, style::SMALL))
                .position(SeriesLabelPosition::LowerRight)
                .draw()?;
        }
        Ok(())
    }
}

impl Chart for Panels {
    fn size(&self) -> (u32, u32) {
        (560 * self.columns.max(1) as u32, 70 + 380 * self.rows() as u32)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        let root = root.titled(&self.title, (FONT, style::TITLE))?;
        let cells = root.split_evenly((self.rows(), self.columns.max(1)));
        for (p, cell) in self.panels.iter().zip(cells.iter()) {
            self.panel(cell, p)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_grid_of_panels_is_written_as_png_and_svg() {
        let dir = std::env::temp_dir().join(format!("tendril-panels-{}", std::process::id()));
        let series = |name: &str, k: f64| Series {
            name: name.into(),
            points: (0..10).map(|i| (i as f64, k * i as f64)).chain([(f64::NAN, 1.0)]).collect(),
            mark: Mark::LineDots,
        };
        let panel = |caption: &str| Panel {
            caption: caption.into(),
            x_desc: "x [s]".into(),
            y_desc: "y [N]".into(),
            series: vec![series("a", 1.0), series("b", -0.5)],
            y_range: None,
        };
        let chart =
            Panels { title: "test".into(), panels: vec![panel("one"), panel("two"), panel("three")], columns: 2 };
        assert_eq!(chart.size(), (1120, 70 + 760));
        let files = render(&chart, &dir, "panels").unwrap();
        assert_eq!(files.len(), 2);
        assert!(files.iter().all(|f| std::fs::metadata(f).unwrap().len() > 1000));
        let svg = std::fs::read_to_string(&files[1]).unwrap();
        let texts: Vec<&str> = svg.lines().map(str::trim).collect();
        assert!(texts.contains(&"three") && texts.contains(&"b"), "captions and legend drawn");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
