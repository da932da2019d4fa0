//! A (Kp, Ki) grid panel shared by the sweep heatmaps and the gain maps: one coloured cell per
//! gain pair (evenly spaced whatever the gain values, so log-spaced sweeps read well), an
//! optional text in the cell, and a key (colour bar or swatches) at the right.

use super::DrawResult;
use super::style::{self, FONT};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::colors::colormaps::ViridisRGB;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// Axis description of the proportional gain.
pub const KP_AXIS: &str = "Kp [(°/s)/N]";
/// Axis description of the integral gain.
pub const KI_AXIS: &str = "Ki [(°/s)/(N·s)]";

/// One cell of the grid.
#[derive(Debug, Clone)]
pub struct Cell {
    /// Index into the Kp values.
    pub kp: usize,
    /// Index into the Ki values.
    pub ki: usize,
    /// Fill colour.
    pub color: RGBColor,
    /// Text written in the cell (may be empty).
    pub label: String,
}

/// What explains the colours, drawn at the right of the grid.
#[derive(Debug, Clone)]
pub enum Key {
    /// A continuous colour bar (viridis) from `min` to `max`, titled `label`.
    ColorBar {
        /// Value at the bottom.
        min: f64,
        /// Value at the top.
        max: f64,
        /// Quantity and unit.
        label: String,
    },
    /// Colour swatches with their meaning.
    Swatches(Vec<(RGBColor, String)>),
}

/// The viridis colour of `v` on the scale `min..max`.
pub fn viridis(v: f64, min: f64, max: f64) -> RGBColor {
    let t = if max > min { ((v - min) / (max - min)).clamp(0.0, 1.0) } else { 0.5 };
    ViridisRGB.get_color(t as f32)
}

/// Sorted distinct values (exact float equality: gains come from the same sweep grid).
pub fn distinct(values: impl Iterator<Item = f64>) -> Vec<f64> {
    let mut v: Vec<f64> = values.collect();
    v.sort_by(f64::total_cmp);
    v.dedup();
    v
}

/// The distinct values in the order they first appear (objects, integrators, groups).
pub fn first_seen<T: PartialEq>(values: impl Iterator<Item = T>) -> Vec<T> {
    let mut out: Vec<T> = Vec::new();
    for v in values {
        if !out.contains(&v) {
            out.push(v);
        }
    }
    out
}

/// Index of `v` in sorted distinct `values`.
pub fn index_of(values: &[f64], v: f64) -> usize {
    values.iter().position(|x| *x == v).unwrap_or(0)
}

/// The cell index at axis value `v` when `v` is a cell centre (a whole number), for tick labels.
pub fn index_label(v: f64) -> Option<usize> {
    ((v - v.round()).abs() < 1e-6 && v >= -1e-6).then(|| v.round() as usize)
}

/// Draws one grid panel with its caption and key into `area`.
pub fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    caption: &str,
    kp: &[f64],
    ki: &[f64],
    cells: &[Cell],
    key: &Key,
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let (w, _) = area.dim_in_pixel();
    // Same width for a colour bar and short swatch texts, so panels side by side line up.
    let key_w = match key {
        Key::ColorBar { .. } => 130,
        Key::Swatches(items) => {
            items.iter().map(|(_, t)| 40 + 9 * t.chars().count() as u32).max().unwrap_or(0).max(130)
        }
    };
    let (main, side) = area.split_horizontally(w.saturating_sub(key_w));
    let nx = kp.len().max(1);
    let ny = ki.len().max(1);
    let mut chart = ChartBuilder::on(&main)
        .caption(caption, (FONT, style::CAPTION))
        .margin(8)
        .x_label_area_size(48)
        .y_label_area_size(70)
        .build_cartesian_2d(-0.5..nx as f64 - 0.5, -0.5..ny as f64 - 0.5)?;
    let label_of = |values: &[f64], v: f64| index_label(v).and_then(|i| values.get(i)).map(|x| style::num(*x));
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(KP_AXIS)
        .y_desc(KI_AXIS)
        .axis_desc_style((FONT, style::AXIS))
        .label_style((FONT, style::LABEL))
        // At most one label per ~60 px across and ~24 px up; plotters then labels every 2nd or 5th cell.
        .x_labels((nx + 1).min(main.dim_in_pixel().0 as usize / 60))
        .y_labels((ny + 1).min(main.dim_in_pixel().1 as usize / 24))
        .x_label_formatter(&|v| label_of(kp, *v).unwrap_or_default())
        .y_label_formatter(&|v| label_of(ki, *v).unwrap_or_default())
        .draw()?;
    chart.draw_series(cells.iter().map(|c| {
        let (x, y) = (c.kp as f64, c.ki as f64);
        Rectangle::new([(x - 0.5, y - 0.5), (x + 0.5, y + 0.5)], c.color.filled())
    }))?;
    // Thin white gaps between cells.
    chart.draw_series(cells.iter().map(|c| {
        let (x, y) = (c.kp as f64, c.ki as f64);
        Rectangle::new([(x - 0.5, y - 0.5), (x + 0.5, y + 0.5)], WHITE.stroke_width(1))
    }))?;
    let (pw, ph) = chart.plotting_area().dim_in_pixel();
    let cell_px = (pw as f64 / nx as f64).min(ph as f64 * 2.5 / ny as f64);
    let size = (cell_px / 4.2).clamp(0.0, f64::from(style::LABEL)) as u32;
    if size >= 9 {
        for c in cells.iter().filter(|c| !c.label.is_empty()) {
            let font = (FONT, size).into_font().color(&style::text_on(c.color));
            let anchored = font.pos(Pos::new(HPos::Center, VPos::Center));
            chart.plotting_area().draw(&Text::new(c.label.clone(), (c.kp as f64, c.ki as f64), anchored))?;
        }
    }
    draw_key(&side, key)
}

fn draw_key<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, key: &Key) -> DrawResult
where
    DB::ErrorType: 'static,
{
    match key {
        Key::ColorBar { min, max, label } => {
            let (lo, hi) = if max > min { (*min, *max) } else { (*min - 0.5, *max + 0.5) };
            let mut bar = ChartBuilder::on(area)
                .margin_top(50)
                .margin_bottom(56)
                .margin_right(8)
                .y_label_area_size(62)
                .build_cartesian_2d(0.0..1.0, lo..hi)?;
            bar.configure_mesh()
                .disable_mesh()
                .disable_x_axis()
                .y_labels(6)
                .y_label_formatter(&|v| style::num(*v))
                .label_style((FONT, style::SMALL))
                .draw()?;
            let steps = 100;
            bar.draw_series((0..steps).map(|i| {
                let a = lo + (hi - lo) * i as f64 / steps as f64;
                let b = lo + (hi - lo) * (i + 1) as f64 / steps as f64;
                Rectangle::new([(0.0, a), (1.0, b)], viridis((a + b) / 2.0, lo, hi).filled())
            }))?;
            area.draw(&Text::new(label.clone(), (4, 22), (FONT, style::SMALL).into_font()))?;
            let (_, h) = area.dim_in_pixel();
            area.draw(&Rectangle::new([(6, h as i32 - 40), (20, h as i32 - 26)], style::NONE.filled()))?;
            area.draw(&Text::new("no value", (24, h as i32 - 40), (FONT, style::SMALL).into_font()))?;
        }
        Key::Swatches(items) => {
            for (i, (color, text)) in items.iter().enumerate() {
                let y = 60 + 28 * i as i32;
                area.draw(&Rectangle::new([(6, y), (24, y + 18)], color.filled()))?;
                area.draw(&Rectangle::new([(6, y), (24, y + 18)], BLACK.stroke_width(1)))?;
                area.draw(&Text::new(text.clone(), (32, y + 2), (FONT, style::LABEL).into_font()))?;
            }
        }
    }
    Ok(())
}
