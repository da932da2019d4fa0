//! Sweep files: which scenarios, which keys, which values.
//!
//! ```toml
//! # scenarios/sweep-gains.toml
//! scenarios = ["crimper.toml", "hammer.toml", "shampoo.toml"]  # relative to this file
//! [grid]                       # cartesian product over these dotted keys
//! "controller.kp" = [5, 10, 20, 40]
//! "controller.ki" = [0.0, 0.05, 0.5]
//! [[list]]                     # optional: extra override sets, each crossed with the grid
//! feedback = false
//! ```

use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use tendril_config::{Override, ScenarioError};

/// A sweep as written in its file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepFile {
    /// Scenario files, relative to the sweep file.
    pub scenarios: Vec<PathBuf>,
    /// Dotted key → values; every combination is run.
    #[serde(default)]
    pub grid: BTreeMap<String, Vec<toml::Value>>,
    /// Override sets, each crossed with the grid (none: the grid alone).
    #[serde(default)]
    pub list: Vec<BTreeMap<String, toml::Value>>,
}

/// One run of a sweep: a scenario file and the overrides applied to it.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepRun {
    /// Position in the expanded sweep; stable for a given sweep file (used by resume and shards).
    pub id: usize,
    /// The scenario file.
    pub scenario: PathBuf,
    /// Overrides, in key order.
    pub overrides: Vec<Override>,
    /// Which `[[list]]` entry this run takes its list keys from (`None` without a list), so a
    /// bad value is reported at its place in the sweep file.
    pub list_index: Option<usize>,
}

/// Most runs one sweep may expand to. Why: a run of the 60 s task takes seconds of CPU, so 100 000
/// runs are already days on a cluster; a grid of 10⁶ runs only sat expanding (and checking) in
/// memory with no output. Split a larger study into several sweeps.
pub const MAX_RUNS: usize = 100_000;

/// A loaded sweep: where it came from and its runs in order.
#[derive(Debug, Clone)]
pub struct Sweep {
    /// The sweep file.
    pub file: PathBuf,
    /// Every dotted key that varies, in column order.
    pub keys: Vec<String>,
    /// The keys each `[[list]]` entry sets, in list order.
    pub list_keys: Vec<Vec<String>>,
    /// The runs, in id order.
    pub runs: Vec<SweepRun>,
    /// `--overlay`: applied to every run before its own overrides (empty by default).
    pub overlay: tendril_config::Overlay,
}

fn invalid(file: &Path, key: &str, reason: impl Into<String>) -> ScenarioError {
    ScenarioError::Invalid { file: file.into(), key: key.into(), reason: reason.into() }
}

/// Reads a sweep file and expands it into runs. Scenario contents are not checked here; see
/// [`super::execute::check_runs`].
pub fn load_sweep(file: &Path) -> Result<Sweep, ScenarioError> {
    let text = tendril_config::read_text(file)?;
    let table: toml::Table = text
        .parse()
        .map_err(|e: toml::de::Error| ScenarioError::Syntax { file: file.into(), message: e.to_string() })?;
    let spec: SweepFile = serde_path_to_error::deserialize(toml::Value::Table(table)).map_err(|e| {
        let key = e.path().to_string();
        invalid(file, &key, e.into_inner().to_string())
    })?;
    if spec.scenarios.is_empty() {
        return Err(invalid(file, "scenarios", "lists no scenario"));
    }
    for (key, values) in &spec.grid {
        if values.is_empty() {
            return Err(invalid(file, &format!("grid.{key}"), "is an empty range: give at least one value"));
        }
    }
    let base = file.parent().unwrap_or(Path::new("."));
    let mut keys: Vec<String> = spec.grid.keys().cloned().collect();
    for set in &spec.list {
        for k in set.keys() {
            if !keys.contains(k) {
                keys.push(k.clone());
            }
        }
    }
    // Counted before anything is expanded, saturating: a hostile grid cannot allocate.
    let count = spec
        .grid
        .values()
        .map(Vec::len)
        .chain([spec.scenarios.len(), spec.list.len().max(1)])
        .fold(1usize, usize::saturating_mul);
    if count > MAX_RUNS {
        return Err(invalid(file, "grid", format!("expands to {count} runs, more than {MAX_RUNS}: split the sweep")));
    }
    let list = if spec.list.is_empty() { vec![BTreeMap::new()] } else { spec.list.clone() };
    let mut runs = Vec::new();
    for scenario in &spec.scenarios {
        for (index, set) in list.iter().enumerate() {
            let list_index = (!spec.list.is_empty()).then_some(index);
            for combo in cartesian(&spec.grid) {
                let mut overrides: Vec<Override> = Vec::new();
                for (key, value) in combo.into_iter().chain(set.iter().map(|(k, v)| (k.clone(), v.clone()))) {
                    overrides.retain(|o| o.key != key);
                    overrides.push(Override { key, value });
                }
                runs.push(SweepRun { id: runs.len(), scenario: base.join(scenario), overrides, list_index });
            }
        }
    }
    let list_keys = spec.list.iter().map(|set| set.keys().cloned().collect()).collect();
    Ok(Sweep { file: file.into(), keys, list_keys, runs, overlay: Default::default() })
}

/// Every combination of the grid's values, keys in order.
fn cartesian(grid: &BTreeMap<String, Vec<toml::Value>>) -> Vec<Vec<(String, toml::Value)>> {
    let mut combos = vec![Vec::new()];
    for (key, values) in grid {
        combos = combos
            .into_iter()
            .flat_map(|prefix| {
                values.iter().map(move |v| {
                    let mut next = prefix.clone();
                    next.push((key.clone(), v.clone()));
                    next
                })
            })
            .collect();
    }
    combos
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(dir: &Path, text: &str) -> PathBuf {
        let path = dir.join("sweep.toml");
        std::fs::write(&path, text).unwrap();
        path
    }

    #[test]
    fn grid_is_crossed_with_scenarios_and_list() {
        let dir = tempfile::tempdir().unwrap();
        let file = write(
            dir.path(),
            "scenarios = ['a.toml', 'b.toml']\n[grid]\n'controller.kp' = [1, 2, 3]\nseed = [7, 8]\n[[list]]\nfeedback = true\n[[list]]\nfeedback = false\n",
        );
        let sweep = load_sweep(&file).unwrap();
        assert_eq!(sweep.runs.len(), 2 * 2 * 3 * 2);
        assert_eq!(sweep.keys, ["controller.kp", "seed", "feedback"]);
        assert_eq!(sweep.runs[0].scenario, dir.path().join("a.toml"));
        assert_eq!(sweep.runs[5].overrides.len(), 3);
        assert!(sweep.runs.iter().enumerate().all(|(i, r)| r.id == i));
    }

    #[test]
    fn empty_range_and_unknown_key_are_named() {
        let dir = tempfile::tempdir().unwrap();
        let err = load_sweep(&write(dir.path(), "scenarios = ['a.toml']\n[grid]\n'controller.kp' = []\n")).unwrap_err();
        assert!(err.to_string().contains("grid.controller.kp") && err.to_string().contains("empty"), "{err}");
        let err = load_sweep(&write(dir.path(), "scenarios = ['a.toml']\ngird = 1\n")).unwrap_err();
        assert!(err.to_string().contains("gird"), "{err}");
    }

    #[test]
    fn a_million_runs_are_refused_before_expanding() {
        let dir = tempfile::tempdir().unwrap();
        let values = (0..100).map(|i| i.to_string()).collect::<Vec<_>>().join(",");
        let text = format!("scenarios = ['a.toml']\n[grid]\na = [{values}]\nb = [{values}]\nc = [{values}]\n");
        let started = std::time::Instant::now();
        let err = load_sweep(&write(dir.path(), &text)).unwrap_err().to_string();
        assert!(err.contains("sweep.toml") && err.contains("1000000 runs"), "{err}");
        assert!(started.elapsed().as_secs_f64() < 2.0);
    }
}
