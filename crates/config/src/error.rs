//! [`ScenarioError`]: why a file could not be loaded, naming the file, the key and the reason.

use std::path::PathBuf;

/// Why a scenario could not be loaded. Every variant names the file it came from.
#[derive(Debug, thiserror::Error)]
pub enum ScenarioError {
    /// The file could not be read.
    #[error("{file}: cannot read: {source}")]
    Io {
        /// The scenario file.
        file: PathBuf,
        /// The underlying IO error.
        source: std::io::Error,
    },
    /// The file is not UTF-8 text (TOML must be).
    #[error("{file}: line {line}, column {column}: not UTF-8 text (a TOML file must be UTF-8)")]
    Encoding {
        /// The scenario file.
        file: PathBuf,
        /// 1-based line of the first invalid byte.
        line: usize,
        /// 1-based byte column of the first invalid byte.
        column: usize,
    },
    /// The file is not valid TOML.
    #[error("{file}: not valid TOML: {message}")]
    Syntax {
        /// The scenario file.
        file: PathBuf,
        /// The parser's message, with line and column.
        message: String,
    },
    /// A key is unknown, missing, of the wrong type or out of range.
    #[error("{file}: key `{key}`: {reason}")]
    Invalid {
        /// The scenario file.
        file: PathBuf,
        /// Dotted path of the key at fault (`physics.timestep`), or `(top level)`.
        key: String,
        /// What is wrong and what is expected.
        reason: String,
    },
    /// A `--set` argument is malformed or targets something that is not a table.
    #[error("--set {arg}: {reason}")]
    BadOverride {
        /// The argument as given.
        arg: String,
        /// What is wrong with it.
        reason: String,
    },
}
