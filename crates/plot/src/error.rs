//! [`PlotError`]: why a chart could not be made, naming the file and line.

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
         controllers.csv, jitter.csv or placement_summary.csv here"
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
