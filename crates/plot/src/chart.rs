//! [`Chart`]: a chart drawn once per backend, so the PNG and the SVG agree ([`save`]).

use super::error::PlotError;
use super::style;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// Result of drawing on one backend.
pub type DrawResult = Result<(), Box<dyn std::error::Error>>;

/// A chart that can draw itself on any plotters backend.
pub trait Chart {
    /// Pixel size (width, height) of the image.
    fn size(&self) -> (u32, u32);
    /// Draws the whole chart on `root` (already filled white).
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB::ErrorType: 'static;
}

/// Writes `chart` as `out_dir/stem.png` and `out_dir/stem.svg` (creating `out_dir`); returns both paths.
pub fn save<C: Chart>(chart: &C, out_dir: &Path, stem: &str) -> Result<Vec<PathBuf>, PlotError> {
    style::register_fonts();
    std::fs::create_dir_all(out_dir).map_err(|e| PlotError::Io { file: out_dir.display().to_string(), cause: e })?;
    let size = chart.size();
    let png = out_dir.join(format!("{stem}.png"));
    let svg = out_dir.join(format!("{stem}.svg"));
    let draw_err = |file: &Path| {
        let file = file.display().to_string();
        move |e: Box<dyn std::error::Error>| PlotError::Draw { file: file.clone(), message: e.to_string() }
    };
    {
        let root = BitMapBackend::new(&png, size).into_drawing_area();
        root.fill(&WHITE).map_err(|e| draw_err(&png)(e.into()))?;
        chart.draw(&root).map_err(draw_err(&png))?;
        root.present().map_err(|e| draw_err(&png)(e.into()))?;
    }
    {
        let root = SVGBackend::new(&svg, size).into_drawing_area();
        root.fill(&WHITE).map_err(|e| draw_err(&svg)(e.into()))?;
        chart.draw(&root).map_err(draw_err(&svg))?;
        root.present().map_err(|e| draw_err(&svg)(e.into()))?;
    }
    Ok(vec![png, svg])
}
