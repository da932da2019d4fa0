//! Charts (PNG and SVG) from files on disk: a run's trace, a sweep's heatmaps, the
//! speed-against-accuracy scatter, the convergence panels, the stability dot matrix, the gain maps and
//! the controller study's bars, the real path under jitter.
//!
//! Every chart is drawn once per backend by a [`Chart`] so the PNG and the SVG agree. Text uses
//! DejaVu Sans embedded in the binary, so PNGs render on a machine without system fonts.

pub mod controllers;
pub mod controllers_summary;
pub mod convergence;
pub mod fit;
pub mod gain_map;
pub mod grid;
pub mod input;
pub mod jitter;
pub mod speed_accuracy;
pub mod stability;
pub mod style;
pub mod sweep;
pub mod trace;

use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// Why a chart could not be made.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// A file could not be read or written.
    #[error("{file}: {cause}")]
    Io {
        /// The file.
        file: String,
        /// The IO error (not a `source`: the message already holds it, and `{:#}` would repeat it).
        cause: std::io::Error,
    },
    /// A file is not in the expected format; `line` is 1-based (the header is line 1).
    #[error("{file}:{line}: {message}")]
    Malformed {
        /// The file.
        file: String,
        /// The line at fault.
        line: u64,
        /// What is wrong.
        message: String,
    },
    /// A file holds nothing to draw.
    #[error("{file}: {message}")]
    Empty {
        /// The file.
        file: String,
        /// What is missing.
        message: String,
    },
    /// The path holds none of the files `tendril plot` knows.
    #[error(
        "{0}: no trace.csv, results.csv, speed_accuracy.csv, convergence.csv, stability.csv, gain_map.csv, \
         controllers.csv or jitter.csv here"
    )]
    NothingToPlot(String),
    /// Drawing failed (plotters backend error).
    #[error("{file}: drawing failed: {message}")]
    Draw {
        /// The output file.
        file: String,
        /// The backend's message.
        message: String,
    },
}

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

/// `tendril plot PATH [--out DIR]`: draws every chart the path holds and returns the files written.
///
/// PATH is a run directory (`trace.csv`, optional `summary.json`), a sweep directory
/// (`results.csv`), a directory holding any of `speed_accuracy.csv`, `stability.csv`,
/// `gain_map.csv`, `controllers.csv`, `jitter.csv`, or one of those files. Charts go to `out` (default: the directory of the input).
pub fn plot_path(path: &Path, out: Option<&Path>) -> Result<Vec<PathBuf>, PlotError> {
    let (dir, only) = if path.is_file() {
        (
            path.parent().unwrap_or(Path::new(".")).to_path_buf(),
            path.file_name().map(|n| n.to_string_lossy().to_string()),
        )
    } else if path.is_dir() {
        (path.to_path_buf(), None)
    } else {
        return Err(PlotError::Io {
            file: path.display().to_string(),
            cause: std::io::Error::new(std::io::ErrorKind::NotFound, "no such file or directory"),
        });
    };
    let out_dir = out.map(Path::to_path_buf).unwrap_or_else(|| dir.clone());
    let wanted = |name: &str| dir.join(name).is_file() && only.as_deref().is_none_or(|o| o == name);
    let mut written = Vec::new();
    if wanted("trace.csv") {
        written.extend(trace::render(&trace::read(&dir)?, &out_dir)?);
    }
    if wanted("results.csv") {
        written.extend(sweep::render(&sweep::read(&dir.join("results.csv"))?, &out_dir)?);
    }
    if wanted("speed_accuracy.csv") {
        written.extend(speed_accuracy::render(&speed_accuracy::read(&dir.join("speed_accuracy.csv"))?, &out_dir)?);
    }
    if wanted("stability.csv") {
        written.extend(stability::render(&stability::read(&dir.join("stability.csv"))?, &out_dir)?);
    }
    if wanted("convergence.csv") {
        written.extend(convergence::render(&convergence::read(&dir.join("convergence.csv"))?, &out_dir)?);
    }
    if wanted("gain_map.csv") {
        written.extend(gain_map::render(&gain_map::read(&dir.join("gain_map.csv"))?, &out_dir)?);
    }
    if wanted("jitter.csv") {
        written.extend(jitter::render(&jitter::read(&dir.join("jitter.csv"))?, &out_dir)?);
    }
    if wanted("controllers.csv") {
        written.extend(controllers::render(&controllers::read(&dir.join("controllers.csv"))?, &out_dir)?);
    }
    if written.is_empty() {
        return Err(PlotError::NothingToPlot(path.display().to_string()));
    }
    Ok(written)
}
