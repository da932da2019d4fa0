//! Loading: the file read, parsed, overridden, prepared, deserialised and validated.

use super::error::ScenarioError;
use super::magnitude::check_magnitudes;
use super::overrides::{Override, apply_overrides};
use super::validate::{Checker, Validate};
use serde::de::DeserializeOwned;
use std::path::Path;

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
    T::prepare(&mut table, file);
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
