//! The axes of a grouped bar panel (the controllers and placement charts): one group per label
//! along x, a linear y from 0 to `top`.

use super::grid::index_label;
use super::style::{self, FONT};
use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

/// A panel's chart: groups at x = 0, 1, ... (each ±0.5 wide), y in 0..`top`.
pub type BarChart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// Draws the captioned axes of a panel on `area`, the groups named by `labels`, the y axis
/// described by `y_desc` and running to `top`; returns the chart to draw the bars on.
pub fn bar_axes<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    caption: String,
    y_desc: &str,
    labels: &[String],
    top: f64,
) -> Result<BarChart<'a, DB>, Box<dyn std::error::Error>>
where
    DB::ErrorType: 'static,
{
    let n = labels.len();
    let mut chart = ChartBuilder::on(area)
        .caption(caption, (FONT, style::CAPTION))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(64)
        .build_cartesian_2d(-0.5..n as f64 - 0.5, 0.0..top)?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_labels(n + 1)
        .x_label_formatter(&|v| index_label(*v).and_then(|i| labels.get(i).cloned()).unwrap_or_default())
        .y_desc(y_desc)
        .y_labels(6)
        .y_label_formatter(&|v| style::num(*v))
        .axis_desc_style((FONT, style::AXIS))
        .label_style((FONT, style::SMALL))
        .draw()?;
    Ok(chart)
}
