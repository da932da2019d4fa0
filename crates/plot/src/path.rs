//! `tendril plot PATH`: every chart a run, sweep or study folder (or one of its files) holds.

use super::error::PlotError;
use super::{controllers, convergence, gain_map, jitter, placement, speed_accuracy, stability, sweep, trace};
use std::path::{Path, PathBuf};

/// `tendril plot PATH [--out DIR]`: draws every chart the path holds and returns the files written.
///
/// PATH is a run directory (`trace.csv`, optional `summary.json`), a sweep directory
/// (`results.csv`), a directory holding any of `speed_accuracy.csv`, `stability.csv`,
/// `gain_map.csv`, `controllers.csv`, `jitter.csv`, `placement_summary.csv`, or one of those files. Charts go to `out` (default: the directory of the input).
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
    if wanted("placement_summary.csv") {
        written.extend(placement::render(&placement::read(&dir.join("placement_summary.csv"))?, &out_dir)?);
    }
    if written.is_empty() {
        return Err(PlotError::NothingToPlot(path.display().to_string()));
    }
    Ok(written)
}
