//! `--overlay FILE`: scenario keys from a file (what `tendril fit` and `tendril tune` write),
//! applied after the scenario file and before `--set`.
//!
//! An overlay is TOML whose leaves are scenario keys, in sections or as quoted dotted keys:
//! ```toml
//! "finger.relaxation_time_s" = 14.2
//! [object]
//! friction = 1.1
//! ```
//! It becomes a list of [`Override`]s placed before the command line's `--set` ones, so it goes
//! through exactly the checks of the file and `--set`; a bad value is reported against the overlay
//! file ([`Overlay::attribute`]).

use super::error::ScenarioError;
use super::load::{load, read_text};
use super::overrides::Override;
use super::validate::Validate;
use std::path::{Path, PathBuf};

/// An overlay file read into overrides.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Overlay {
    /// The overlay file (`None`: no overlay, nothing changes).
    pub file: Option<PathBuf>,
    /// Its keys and values, in key order (distinct keys: the order does not matter).
    pub overrides: Vec<Override>,
}

impl Overlay {
    /// Reads `file` (`None`: the empty overlay). Errors name the file (and the key for a key that
    /// is not a dotted path).
    pub fn load(file: Option<&Path>) -> Result<Overlay, ScenarioError> {
        let Some(file) = file else { return Ok(Overlay::default()) };
        let text = read_text(file)?;
        let table: toml::Table = text
            .parse()
            .map_err(|e: toml::de::Error| ScenarioError::Syntax { file: file.into(), message: e.to_string() })?;
        let mut overrides = Vec::new();
        flatten("", &table, &mut overrides);
        for o in &overrides {
            if o.key.split('.').any(str::is_empty) {
                return Err(ScenarioError::Invalid {
                    file: file.into(),
                    key: o.key.clone(),
                    reason: "not a dotted scenario key such as finger.relaxation_time_s".into(),
                });
            }
        }
        Ok(Overlay { file: Some(file.into()), overrides })
    }

    /// The overlay's overrides followed by `set` (the command line's, which win).
    pub fn then(&self, set: &[Override]) -> Vec<Override> {
        self.overrides.iter().chain(set).cloned().collect()
    }

    /// Reports an invalid key that came from this overlay (and not from a later `--set` of the
    /// same key) against the overlay file instead of the scenario file.
    pub fn attribute(&self, error: ScenarioError, set: &[Override]) -> ScenarioError {
        match (&self.file, error) {
            (Some(overlay), ScenarioError::Invalid { file, key, reason })
                if self.overrides.iter().any(|o| o.key == key) && !set.iter().any(|o| o.key == key) =>
            {
                ScenarioError::Invalid {
                    file: overlay.clone(),
                    key,
                    reason: format!("{reason} (applied to {})", file.display()),
                }
            }
            (_, e) => e,
        }
    }

    /// Loads scenario `file` of type `T` with this overlay, then `set`.
    pub fn load_scenario<T: serde::de::DeserializeOwned + Validate>(
        &self,
        file: &Path,
        set: &[Override],
    ) -> Result<T, ScenarioError> {
        load(file, &self.then(set)).map_err(|e| self.attribute(e, set))
    }
}

/// Every leaf of `table` as an override at its dotted path (a quoted key's dots are path
/// separators too); arrays are values.
fn flatten(prefix: &str, table: &toml::Table, out: &mut Vec<Override>) {
    for (key, value) in table {
        let path = if prefix.is_empty() { key.clone() } else { format!("{prefix}.{key}") };
        match value {
            toml::Value::Table(inner) => flatten(&path, inner, out),
            v => out.push(Override { key: path, value: v.clone() }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sections_and_quoted_keys_flatten_to_dotted_overrides() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("o.toml");
        std::fs::write(&file, "\"finger.relaxation_time_s\" = 20.0\nseed = 3\n[object]\nfriction = 1.1\n").unwrap();
        let o = Overlay::load(Some(&file)).unwrap();
        let keys: Vec<&str> = o.overrides.iter().map(|o| o.key.as_str()).collect();
        assert_eq!(keys, ["finger.relaxation_time_s", "object.friction", "seed"]);
        let set: Override = "seed=4".parse().unwrap();
        let all = o.then(std::slice::from_ref(&set));
        assert_eq!(all.last(), Some(&set));
    }

    #[test]
    fn a_bad_value_is_reported_against_the_overlay_unless_set_overrides_it() {
        let o = Overlay {
            file: Some("fit/overlay.toml".into()),
            overrides: vec!["finger.relaxation_time_s=-1".parse().unwrap()],
        };
        let err = || ScenarioError::Invalid {
            file: "crimper.toml".into(),
            key: "finger.relaxation_time_s".into(),
            reason: "must be > 0".into(),
        };
        let e = o.attribute(err(), &[]).to_string();
        assert!(e.starts_with("fit/overlay.toml: key `finger.relaxation_time_s`") && e.contains("crimper.toml"), "{e}");
        let e = o.attribute(err(), &["finger.relaxation_time_s=-1".parse().unwrap()]).to_string();
        assert!(e.starts_with("crimper.toml"), "{e}");
    }

    #[test]
    fn empty_key_parts_and_missing_files_are_named() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("o.toml");
        std::fs::write(&file, "\"finger..x\" = 1\n").unwrap();
        let e = Overlay::load(Some(&file)).unwrap_err().to_string();
        assert!(e.contains("o.toml") && e.contains("finger..x"), "{e}");
        let e = Overlay::load(Some(&dir.path().join("none.toml"))).unwrap_err().to_string();
        assert!(e.contains("none.toml"), "{e}");
    }
}
