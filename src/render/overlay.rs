//! The panel under the rendered picture: the run's forces from `trace.csv` (true, estimated,
//! setpoint) over the whole run, a cursor at the frame's time, and the phase and forces at that
//! time as text. The chart is drawn once; each frame copies it and adds the cursor and the text.

use plotters::prelude::*;
use tendril_plot::style::{self, FONT};
use tendril_plot::trace::{RunTrace, TracePoint};

/// Cursor colour.
const CURSOR: RGBColor = RGBColor(200, 30, 30);

/// A plotted series: its value, colour and legend.
type Series = (fn(&TracePoint) -> f64, RGBColor, &'static str);

/// The force panel of one run at one size.
pub struct Panel {
    points: Vec<TracePoint>,
    width: u32,
    height: u32,
    /// The chart without cursor, RGB.
    base: Vec<u8>,
    /// Pixel columns of the first and last trace time.
    x_px: (f64, f64),
    /// Pixel rows of the plotting area (top, bottom).
    y_px: (i32, i32),
    /// Time span of the chart \[s\].
    t_range: (f64, f64),
    font_px: u32,
}

fn draw_error<E: std::fmt::Debug>(e: E) -> anyhow::Error {
    anyhow::anyhow!("cannot draw the force panel: {e:?}")
}

impl Panel {
    /// Draws the static chart of `run` into a `width` × `height` panel.
    pub fn new(run: &RunTrace, width: u32, height: u32) -> anyhow::Result<Panel> {
        style::register_fonts();
        let points = run.points.clone();
        let t0 = points.first().map_or(0.0, |p| p.time_s);
        let t1 = points.last().map_or(1.0, |p| p.time_s).max(t0 + 1e-3);
        // The scale follows the setpoint and the bulk of the forces, not a lone spike (the pad's
        // first touch, the release): 99th percentile of the forces, at least 1.6 × the setpoint.
        let mut forces: Vec<f64> =
            points.iter().flat_map(|p| [p.true_force_n, p.force_n]).filter(|v| v.is_finite()).collect();
        forces.sort_by(f64::total_cmp);
        let pick = |q: f64| forces.get(((forces.len() as f64 - 1.0) * q).round() as usize).copied().unwrap_or(0.0);
        let setpoint = points.iter().map(|p| p.setpoint_n).filter(|v| v.is_finite()).fold(0.0_f64, f64::max);
        let top = (pick(0.99) * 1.15).max(setpoint * 1.6).max(0.1);
        let bottom = pick(0.01).min(0.0) * 1.15;
        let font_px = (f64::from(height) * 0.11).clamp(8.0, 18.0) as u32;
        let mut base = vec![255u8; width as usize * height as usize * 3];
        let (x_px, y_px);
        {
            let root = BitMapBackend::with_buffer(&mut base, (width, height)).into_drawing_area();
            root.fill(&WHITE).map_err(draw_error)?;
            let mut chart = ChartBuilder::on(&root)
                .margin_top(font_px + 6)
                .margin_right(8)
                .margin_bottom(2)
                .x_label_area_size(font_px + 6)
                .y_label_area_size(4 * font_px)
                .build_cartesian_2d(t0..t1, bottom..top)
                .map_err(draw_error)?;
            chart
                .configure_mesh()
                .light_line_style(WHITE.mix(0.0))
                .bold_line_style(BLACK.mix(0.12))
                .x_labels(6)
                .y_labels(3)
                .label_style((FONT, font_px).into_font())
                .x_label_formatter(&|t| format!("{t:.0} s"))
                .y_label_formatter(&|f| format!("{f:.1} N"))
                .draw()
                .map_err(draw_error)?;
            let series: [Series; 3] = [
                (|p| p.setpoint_n, RGBColor(120, 120, 120), "setpoint"),
                (|p| p.true_force_n, RGBColor(20, 20, 20), "true"),
                (|p| p.force_n, style::SERIES[0], "estimate"),
            ];
            for (value, colour, name) in series {
                let line: Vec<(f64, f64)> =
                    points.iter().map(|p| (p.time_s, value(p))).filter(|(_, v)| v.is_finite()).collect();
                chart
                    .draw_series(LineSeries::new(line, colour.stroke_width(1)))
                    .map_err(draw_error)?
                    .label(name)
                    .legend(move |(x, y)| PathElement::new([(x, y), (x + 12, y)], colour.stroke_width(2)));
            }
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::UpperLeft)
                .background_style(WHITE.mix(0.8))
                .label_font((FONT, font_px).into_font())
                .margin(2)
                .draw()
                .map_err(draw_error)?;
            let (a, b) = (chart.backend_coord(&(t0, bottom)), chart.backend_coord(&(t1, top)));
            x_px = (f64::from(a.0), f64::from(b.0));
            y_px = (b.1, a.1);
            root.present().map_err(draw_error)?;
        }
        Ok(Panel { points, width, height, base, x_px, y_px, t_range: (t0, t1), font_px })
    }

    /// Draws the panel at cell time `t` into `out` (width × height × 3 bytes, RGB).
    pub fn draw(&mut self, t: f64, out: &mut [u8]) -> anyhow::Result<()> {
        if out.len() != self.base.len() {
            anyhow::bail!("the force panel is {} bytes, the frame leaves {}", self.base.len(), out.len());
        }
        out.copy_from_slice(&self.base);
        let (t0, t1) = self.t_range;
        let x = self.x_px.0 + (self.x_px.1 - self.x_px.0) * ((t - t0) / (t1 - t0)).clamp(0.0, 1.0);
        let x = x.round() as i32;
        let w = self.width as i32;
        for row in self.y_px.0.max(0)..=self.y_px.1.min(self.height as i32 - 1) {
            for col in [x - 1, x] {
                if (0..w).contains(&col) {
                    let at = (row as usize * self.width as usize + col as usize) * 3;
                    out[at..at + 3].copy_from_slice(&[CURSOR.0, CURSOR.1, CURSOR.2]);
                }
            }
        }
        let i = self.points.partition_point(|p| p.time_s <= t).saturating_sub(1);
        let Some(p) = self.points.get(i) else { return Ok(()) };
        let number = |v: f64| if v.is_finite() { format!("{v:.2} N") } else { "–".into() };
        let text = format!(
            "t = {t:.2} s   phase: {}   true {}   estimate {}   setpoint {}",
            p.phase,
            number(p.true_force_n),
            number(p.force_n),
            number(p.setpoint_n)
        );
        let root = BitMapBackend::with_buffer(out, (self.width, self.height)).into_drawing_area();
        root.draw(&Text::new(text, (4, 2), (FONT, self.font_px).into_font().color(&BLACK))).map_err(draw_error)?;
        root.present().map_err(draw_error)?;
        Ok(())
    }
}
