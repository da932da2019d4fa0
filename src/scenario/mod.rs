//! Scenario files: TOML in, typed and validated configuration out.
//!
//! Every scenario type is read the same way ([`load`]): the file is parsed to a TOML table,
//! `--set key=value` overrides are applied at their dotted paths ([`apply_overrides`]), the table is
//! deserialised with unknown keys rejected, and the result is checked with [`Validate`]. Any
//! failure is a [`ScenarioError`] that names the file, the dotted key and the reason. An
//! [`Overlay`] (`--overlay FILE`, what `tendril fit` and `tendril tune` write) is a file of such
//! overrides, applied before the command line's.

mod backend_defaults;
mod magnitude;
mod overlay;
mod overrides;
mod paths;
pub mod seed;
mod validate;

pub use magnitude::{MAX_MAGNITUDE, check_magnitudes};
pub use overlay::Overlay;
pub use overrides::{Override, apply_overrides};
pub use validate::{Checker, Validate};

use serde::de::DeserializeOwned;
use std::path::{Path, PathBuf};

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

/// Reads, overrides, deserialises and validates a scenario of type `T` from `file`.
pub fn load<T: DeserializeOwned + Validate>(file: &Path, overrides: &[Override]) -> Result<T, ScenarioError> {
    let text = read_text(file)?;
    from_str(&text, file, overrides)
}

/// Reads `file` as UTF-8 text; invalid bytes are reported with their line and column (std's
/// `read_to_string` gives no position).
pub fn read_text(file: &Path) -> Result<String, ScenarioError> {
    let bytes = std::fs::read(file).map_err(|source| ScenarioError::Io { file: file.into(), source })?;
    String::from_utf8(bytes).map_err(|e| {
        let valid = &e.as_bytes()[..e.utf8_error().valid_up_to()];
        let line = valid.iter().filter(|&&b| b == b'\n').count() + 1;
        let column = valid.len() - valid.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1) + 1;
        ScenarioError::Encoding { file: file.into(), line, column }
    })
}

/// As [`load`], from text already in memory; `file` is only used in messages.
pub fn from_str<T: DeserializeOwned + Validate>(
    text: &str,
    file: &Path,
    overrides: &[Override],
) -> Result<T, ScenarioError> {
    let mut table: toml::Table = text
        .parse()
        .map_err(|e: toml::de::Error| ScenarioError::Syntax { file: file.into(), message: e.to_string() })?;
    apply_overrides(&mut table, overrides)?;
    from_table(table, file)
}

/// Deserialises and validates an already-parsed table (sweeps build these directly).
pub fn from_table<T: DeserializeOwned + Validate>(mut table: toml::Table, file: &Path) -> Result<T, ScenarioError> {
    if let Some((key, reason)) = check_magnitudes(&table) {
        return Err(ScenarioError::Invalid { file: file.into(), key, reason });
    }
    paths::resolve_models(&mut table, file);
    paths::resolve_object(&mut table, file);
    backend_defaults::fill_backend_defaults(&mut table);
    let value: T = serde_path_to_error::deserialize(toml::Value::Table(table)).map_err(|e| {
        let path = e.path().to_string();
        // The TOML layer appends "in `key`" lines; the key is reported separately.
        let message = e.into_inner().to_string();
        let reason = message.lines().next().unwrap_or_default().trim().to_string();
        // An error from inside a section read as a table (`deserialize_section`) carries the rest
        // of its key.
        let (path, reason) = match split_section_error(&reason) {
            Some((inner, inner_reason)) if path == "." => (inner.to_string(), inner_reason.to_string()),
            Some((inner, inner_reason)) => (format!("{path}.{inner}"), inner_reason.to_string()),
            None => (path, reason),
        };
        let key = if path == "." { "(top level)".to_string() } else { path };
        ScenarioError::Invalid { file: file.into(), key, reason }
    })?;
    let mut checker = Checker::default();
    value.validate(&mut checker);
    match checker.into_first_error() {
        None => Ok(value),
        Some((key, reason)) => Err(ScenarioError::Invalid { file: file.into(), key, reason }),
    }
}

/// Marks a [`section_error`] message: the key inside the section, then the reason.
const SECTION_ERROR_MARK: char = '\u{1f}';

/// An error on `key` inside a section that deserialises itself from a table (a tagged section such
/// as `[controller]`): reported as `section.key`, like the errors of ordinary sections.
pub fn section_error<E: serde::de::Error>(key: &str, reason: &str) -> E {
    E::custom(format!("{SECTION_ERROR_MARK}{key}{SECTION_ERROR_MARK}{reason}"))
}

/// Deserialises the rest of a section read as a table into `T`; an error keeps its key inside the
/// section (see [`section_error`]), so `[controller] kq = 1` is still refused at `controller.kq`.
pub fn deserialize_section<T: DeserializeOwned, E: serde::de::Error>(table: toml::Table) -> Result<T, E> {
    serde_path_to_error::deserialize(toml::Value::Table(table)).map_err(|e| {
        let path = e.path().to_string();
        let message = e.into_inner().to_string();
        let reason = message.lines().next().unwrap_or_default().trim().to_string();
        match split_section_error(&reason) {
            // Nested again: join the keys.
            Some((inner, inner_reason)) if path != "." => section_error(&format!("{path}.{inner}"), inner_reason),
            Some((inner, inner_reason)) => section_error(inner, inner_reason),
            None if path == "." => E::custom(reason),
            None => section_error(&path, &reason),
        }
    })
}

/// The (key, reason) of a [`section_error`] message.
fn split_section_error(message: &str) -> Option<(&str, &str)> {
    message.strip_prefix(SECTION_ERROR_MARK)?.split_once(SECTION_ERROR_MARK)
}
