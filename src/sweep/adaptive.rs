//! A sweep refined over two of its grid keys: each combination of the other keys (and scenario
//! and list entry) is a two-key map that [`refine`] runs from a coarse grid down to the points
//! where the outcome changes. `results.csv` holds the runs made; `map.csv` every point, run or
//! filled in from its cell.

use super::columns::{identity_cells, identity_columns};
use super::contour::{Class, Contour, class_of};
use super::refine::{Point, refine};
use super::{Sweep, SweepRun};
use std::collections::BTreeMap;
use tendril_config::ScenarioError;
use tendril_run::summary::RunSummary;

/// `--refine KEY1,KEY2`: the two keys, the coarse stride and a figure's contour.
#[derive(Debug, Clone)]
pub struct RefineOptions {
    /// The two grid keys the maps span.
    pub keys: [String; 2],
    /// The coarse grid's stride \[points\]; 1 runs every point.
    pub stride: usize,
    /// A figure's contour to follow besides the outcome and oscillation.
    pub contour: Option<Contour>,
}

/// The file `map.csv`'s columns after the sweep's identity columns.
pub const MAP_COLUMNS: [&str; 4] = ["outcome", "oscillating", "beyond_contour", "ran"];

/// One map of a sweep: the runs of one combination of the other keys, by their two indices.
struct Group<'a> {
    nx: usize,
    ny: usize,
    at: BTreeMap<Point, &'a SweepRun>,
}

/// The values a grid key takes, in the sweep file's order.
fn axis(sweep: &Sweep, key: &str) -> Vec<String> {
    let mut values: Vec<String> = Vec::new();
    for run in &sweep.runs {
        if let Some(o) = run.overrides.iter().find(|o| o.key == key) {
            let v = o.value.to_string();
            if !values.contains(&v) {
                values.push(v);
            }
        }
    }
    values
}

/// Checks the keys (two different grid keys, each with two values or more, set by no `[[list]]`
/// entry) and splits the sweep into its maps.
fn groups<'a>(sweep: &'a Sweep, keys: &[String; 2]) -> Result<Vec<Group<'a>>, ScenarioError> {
    let invalid = |key: &str, reason: &str| ScenarioError::Invalid {
        file: sweep.file.clone(),
        key: format!("grid.\"{key}\""),
        reason: format!("--refine: {reason}"),
    };
    if keys[0] == keys[1] {
        return Err(invalid(&keys[0], "give two different keys"));
    }
    let mut axes = Vec::new();
    for key in keys {
        if sweep.list_keys.iter().any(|set| set.contains(key)) {
            return Err(invalid(key, "a [[list]] entry sets it; refine over grid keys only"));
        }
        let values = axis(sweep, key);
        if values.len() < 2 {
            let why = if values.is_empty() { "the sweep's grid has no such key" } else { "needs two values or more" };
            return Err(invalid(key, why));
        }
        axes.push(values);
    }
    let mut maps: BTreeMap<String, Group> = BTreeMap::new();
    for run in &sweep.runs {
        let index = |k: usize| {
            let v = run.overrides.iter().find(|o| o.key == keys[k]).map(|o| o.value.to_string()).unwrap_or_default();
            axes[k].iter().position(|a| *a == v).expect("every run has a value of each grid key")
        };
        let others: Vec<String> =
            run.overrides.iter().filter(|o| !keys.contains(&o.key)).map(|o| format!("{}={}", o.key, o.value)).collect();
        let name = format!("{}|{:?}|{}", run.scenario.display(), run.list_index, others.join("|"));
        let group =
            maps.entry(name).or_insert_with(|| Group { nx: axes[0].len(), ny: axes[1].len(), at: BTreeMap::new() });
        group.at.insert((index(0), index(1)), run);
    }
    Ok(maps.into_values().collect())
}

/// Refines each of the sweep's maps; `run` runs a batch of the sweep's runs (appending their rows
/// to `results.csv`) and returns their summaries in order. Returns `map.csv`'s rows (the identity
/// cells and [`MAP_COLUMNS`]) in run order, and how many runs were made.
pub fn refine_sweep(
    sweep: &Sweep,
    id: &str,
    options: &RefineOptions,
    mut run: impl FnMut(&[&SweepRun]) -> anyhow::Result<Vec<RunSummary>>,
) -> anyhow::Result<(Vec<Vec<String>>, usize)> {
    let mut rows: BTreeMap<usize, Vec<String>> = BTreeMap::new();
    let mut runs = 0;
    for group in groups(sweep, &options.keys)? {
        let map = refine(group.nx, group.ny, options.stride, |points| {
            let batch: Vec<&SweepRun> = points.iter().map(|p| group.at[p]).collect();
            run(&batch)?.iter().map(|s| class_of(s, options.contour.as_ref())).collect::<anyhow::Result<Vec<Class>>>()
        })?;
        runs += map.runs();
        for (&p, sweep_run) in &group.at {
            let known = map.get(p);
            let (outcome, oscillating, beyond) = &known.class;
            let mut cells = identity_cells(sweep, id, sweep_run);
            debug_assert_eq!(cells.len(), identity_columns(sweep));
            cells.extend([
                outcome.clone(),
                oscillating.to_string(),
                beyond.map_or(String::new(), |b| b.to_string()),
                known.ran.to_string(),
            ]);
            rows.insert(sweep_run.id, cells);
        }
    }
    Ok((rows.into_values().collect(), runs))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sweep(text: &str) -> (tempfile::TempDir, Sweep) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sweep.toml");
        std::fs::write(&path, text).unwrap();
        let sweep = super::super::load_sweep(&path).unwrap();
        (dir, sweep)
    }

    #[test]
    fn a_sweep_splits_into_one_map_per_other_combination() {
        let (_d, s) = sweep("scenarios = ['a.toml', 'b.toml']\n[grid]\nkp = [1, 2, 3]\nki = [0, 1]\nseed = [1, 2]\n");
        let maps = groups(&s, &["kp".into(), "ki".into()]).unwrap();
        assert_eq!(maps.len(), 4, "two scenarios × two seeds");
        assert!(maps.iter().all(|g| g.nx == 3 && g.ny == 2 && g.at.len() == 6));
    }

    #[test]
    fn bad_keys_are_named() {
        let (_d, s) = sweep("scenarios = ['a.toml']\n[grid]\nkp = [1, 2]\nki = [0]\n[[list]]\nfeedback = true\n");
        let err = |keys: [&str; 2]| groups(&s, &keys.map(String::from)).err().unwrap().to_string();
        assert!(err(["kp", "kp"]).contains("two different keys"));
        assert!(err(["kp", "ki"]).contains("grid.\"ki\"") && err(["kp", "ki"]).contains("two values"));
        assert!(err(["kp", "nope"]).contains("no such key"));
        assert!(err(["kp", "feedback"]).contains("[[list]]"));
    }
}
