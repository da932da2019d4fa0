//! FIT.toml: which recordings, which scenario keys within which bounds, how to weigh the error,
//! how many evaluations.
//!
//! ```toml
//! recordings = ["runs/crimper-off", "runs/crimper-on"]   # run folders, relative to this file
//! [[bags]]               # rosbag2 recordings (a lab's, or a run's bag/): fit::bag
//! path = "../bags/crimper-on"
//! scenario = "../crimper.toml"
//! [[targets]]            # published figures instead of (or beside) recordings: fit::target
//! scenario = "../crimper.toml"
//! feedback = false
//! drop_phase = "lift"
//! drop_time_s = 10.0
//! [parameters."finger.relaxation_time_s"]
//! min = 5.0
//! max = 60.0
//! scale = "log"          # or "linear" (the default)
//! start = 15.0           # default: the middle of the range
//! [parameters."crimper:object.friction"]   # NAME:KEY: only the runs of targets or recordings so named
//! min = 0.6
//! max = 1.6
//! [objective]            # optional; these are the defaults
//! force_rmse = 1.0       # [1/N]
//! twine_motor = 2.0      # [1/rad]
//! drop_time = 0.05       # [1/s]
//! drop_phase = 0.05
//! phases = ["grasp", "lift", "transfer", "lower"]
//! smooth_s = 0.5         # [s] moving average both traces are compared through
//! drop_margin_s = 1.0    # [s] not compared from this long before the first drop on
//! [budget]               # optional; these are the defaults
//! evaluations = 300
//! step = 0.3
//! seed = 1
//! prescreen = 0          # points spread over the whole range first; the search starts at the best
//! ```
//! A fit needs recordings, targets, or both. The objective is the mean of every run's score: each
//! recording's ([`super::objective`], in N) and each target seed's ([`super::target`], in
//! tolerances). Everything is checked before anything runs ([`load_fit`]).

use super::bag::{BagSpec, read_bag_recording};
use super::objective::Weights;
use super::optimizer::Budget;
use super::recording::Recording;
use super::space::{Parameter, ParameterSpec};
use super::target::{Target, TargetSpec};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use tendril_config::ScenarioError;

/// FIT.toml as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FitFile {
    /// Run folders, relative to the fit file.
    #[serde(default)]
    pub recordings: Vec<PathBuf>,
    /// rosbag2 recordings ([`super::bag`]), each with the scenario its cell ran.
    #[serde(default)]
    pub bags: Vec<BagSpec>,
    /// Published figures to match.
    #[serde(default)]
    pub targets: Vec<TargetSpec>,
    /// Scenario key → bounds.
    pub parameters: BTreeMap<String, ParameterSpec>,
    /// Weights of the objective's terms.
    #[serde(default)]
    pub objective: Weights,
    /// The search's budget.
    #[serde(default)]
    pub budget: Budget,
}

/// A fit, loaded and checked.
#[derive(Debug, Clone)]
pub struct Fit {
    /// The fit file.
    pub file: PathBuf,
    /// The recordings, read and checked.
    pub recordings: Vec<Recording>,
    /// The targets, read and checked.
    pub targets: Vec<Target>,
    /// The parameters, in key order.
    pub params: Vec<Parameter>,
    /// The objective's weights.
    pub weights: Weights,
    /// The budget.
    pub budget: Budget,
}

/// Why a fit (or a tune) cannot start.
#[derive(Debug, thiserror::Error)]
pub enum SpecError {
    /// The spec file, or a value in it.
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// A recording.
    #[error("{file}: recordings[{index}]: {source}")]
    Recording {
        /// The fit file.
        file: PathBuf,
        /// Position in `recordings`.
        index: usize,
        /// What is wrong with it.
        source: super::recording::RecordingError,
    },
    /// A bag.
    #[error("{file}: bags[{index}]: {source}")]
    Bag {
        /// The fit file.
        file: PathBuf,
        /// Position in `bags`.
        index: usize,
        /// What is wrong with it.
        source: super::recording::RecordingError,
    },
}

/// Reads a TOML spec file into `T`, errors naming the file and the dotted key.
pub fn read_spec<T: serde::de::DeserializeOwned>(file: &Path) -> Result<T, ScenarioError> {
    let text = tendril_config::read_text(file)?;
    let table: toml::Table = text
        .parse()
        .map_err(|e: toml::de::Error| ScenarioError::Syntax { file: file.into(), message: e.to_string() })?;
    serde_path_to_error::deserialize(toml::Value::Table(table)).map_err(|e| {
        let key = e.path().to_string();
        let reason = e.into_inner().to_string().lines().next().unwrap_or_default().trim().to_string();
        ScenarioError::Invalid { file: file.into(), key: if key == "." { "(top level)".into() } else { key }, reason }
    })
}

/// The error for `key` of `file`.
pub fn invalid(file: &Path, (key, reason): (String, String)) -> ScenarioError {
    ScenarioError::Invalid { file: file.into(), key, reason }
}

/// Reads and checks a fit file: every recording read and matched, every target's scenario read
/// and its figures checked, every parameter a scenario key whose bounds are valid values in every
/// scenario it applies to (a scoped one's scope a target's or recording's name), the weights and
/// budget sane.
pub fn load_fit(file: &Path) -> Result<Fit, SpecError> {
    let spec: FitFile = read_spec(file)?;
    if spec.recordings.is_empty() && spec.bags.is_empty() && spec.targets.is_empty() {
        return Err(invalid(
            file,
            (
                "recordings".into(),
                "lists no recording, and there is no [[bags]] or [[targets]] entry: nothing to fit".into(),
            ),
        )
        .into());
    }
    if let Some(bad) = spec.objective.check() {
        return Err(invalid(file, bad).into());
    }
    if let Some(bad) = spec.budget.check() {
        return Err(invalid(file, bad).into());
    }
    let params = super::space::parameters(file, &spec.parameters)?;
    let base = file.parent().unwrap_or(Path::new(""));
    let mut recordings = spec
        .recordings
        .iter()
        .enumerate()
        .map(|(index, dir)| {
            Recording::read(&base.join(dir)).map_err(|source| SpecError::Recording { file: file.into(), index, source })
        })
        .collect::<Result<Vec<_>, _>>()?;
    for (index, bag) in spec.bags.iter().enumerate() {
        let recording =
            read_bag_recording(base, bag).map_err(|source| SpecError::Bag { file: file.into(), index, source })?;
        recordings.push(recording);
    }
    let targets = spec
        .targets
        .iter()
        .enumerate()
        .map(|(index, t)| Target::load(file, base, index, t))
        .collect::<Result<Vec<_>, _>>()?;
    // Every run the fit makes: (name, where its scenario came from, the scenario).
    let runs: Vec<(&str, &Path, &toml::Table)> = recordings
        .iter()
        .map(|r| (r.name.as_str(), r.source.as_path(), &r.table))
        .chain(targets.iter().map(|t| (t.name.as_str(), t.file.as_path(), &t.table)))
        .collect();
    if let Some(p) = params.iter().find(|p| p.scope().is_some_and(|s| !runs.iter().any(|r| r.0 == s))) {
        let names: Vec<&str> = runs.iter().map(|r| r.0).collect();
        return Err(invalid(
            file,
            (
                format!("parameters.\"{}\"", p.key),
                format!(
                    "no target or recording is named `{}` (names: {})",
                    p.scope().unwrap_or_default(),
                    names.join(", ")
                ),
            ),
        )
        .into());
    }
    for &(name, path, table) in &runs {
        let applying: Vec<Parameter> = params.iter().filter(|p| p.applies_to(name)).cloned().collect();
        super::space::check_bounds(file, &applying, &[(path, table)])?;
    }
    Ok(Fit { file: file.into(), recordings, targets, params, weights: spec.objective, budget: spec.budget })
}

impl Fit {
    /// Starts the search from the values `overlay` gives for the fit's parameters (a previous fit's
    /// `overlay.toml`); with `evaluations = 1` the fit only scores those values against its
    /// recordings, which is how held-out recordings are predicted. A value that is not a number
    /// or lies outside the parameter's bounds is an error naming the overlay and the key.
    pub fn start_from(&mut self, overlay: &tendril_config::Overlay) -> Result<(), ScenarioError> {
        let Some(file) = &overlay.file else { return Ok(()) };
        for p in &mut self.params {
            let Some(o) = overlay.overrides.iter().rev().find(|o| o.key == p.key) else { continue };
            let v = match &o.value {
                toml::Value::Float(v) => *v,
                toml::Value::Integer(v) => *v as f64,
                other => return Err(invalid(file, (p.key.clone(), format!("must be a number, got {other}")))),
            };
            if !(p.min..=p.max).contains(&v) {
                return Err(invalid(
                    file,
                    (p.key.clone(), format!("{v} is outside the fit's bounds [{}, {}]", p.min, p.max)),
                ));
            }
            p.start = v;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fit file in a fresh folder whose targets name the repository's short lift.
    fn fit_with(text: &str) -> (tempfile::TempDir, PathBuf) {
        let dir = tempfile::tempdir().unwrap();
        let scenario = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/short-lift.toml");
        std::fs::copy(scenario, dir.path().join("short-lift.toml")).unwrap();
        let file = dir.path().join("fit.toml");
        std::fs::write(&file, text).unwrap();
        (dir, file)
    }

    const GOOD: &str = "[[targets]]\nscenario = \"short-lift.toml\"\nfeedback = false\noutcome = \"held\"\n\
        [[targets]]\nscenario = \"short-lift.toml\"\nname = \"other\"\nfeedback = true\nseeds = [1, 2]\n\
        max_fluctuation_pct = 20.0\n\
        [parameters.\"short-lift:object.friction\"]\nmin = 0.5\nmax = 1.5\n\
        [parameters.\"finger.relaxed_fraction\"]\nmin = 0.01\nmax = 0.5\n";

    /// The error `text` gives, as a message.
    fn error(text: &str) -> String {
        let (_dir, file) = fit_with(text);
        load_fit(&file).unwrap_err().to_string()
    }

    #[test]
    fn a_fit_of_targets_alone_loads_with_its_names_modes_and_seeds() {
        let (_dir, file) = fit_with(GOOD);
        let fit = load_fit(&file).unwrap();
        assert!(fit.recordings.is_empty());
        let names: Vec<(&str, bool, &[u64])> =
            fit.targets.iter().map(|t| (t.name.as_str(), t.spec.feedback, t.spec.seeds.as_slice())).collect();
        assert_eq!(names, [("short-lift", false, &[1][..]), ("other", true, &[1, 2][..])]);
        assert_eq!(fit.targets[0].table["feedback"], toml::Value::Boolean(false));
        assert_eq!(fit.targets[0].grasp_s, 3.0);
        let scoped: Vec<Option<&str>> = fit.params.iter().map(|p| p.scope()).collect();
        assert_eq!(scoped, [None, Some("short-lift")]);
    }

    #[test]
    fn bad_targets_are_named_with_the_file_and_key() {
        let e = error(&GOOD.replace("outcome = \"held\"", "outcome = \"held\"\nwobble = 1"));
        assert!(e.contains("fit.toml") && e.contains("targets[0]") && e.contains("wobble"), "{e}");
        let e = error(&GOOD.replace("outcome = \"held\"", "drop_phase = \"liftt\""));
        assert!(e.contains("targets[0].drop_phase") && e.contains("liftt"), "{e}");
        let e = error(&GOOD.replacen("scenario = \"short-lift.toml\"", "scenario = \"nowhere.toml\"", 1));
        assert!(e.contains("fit.toml") && e.contains("targets[0].scenario") && e.contains("nowhere.toml"), "{e}");
        let e = error(&GOOD.replace("short-lift:object", "shortlift:object"));
        assert!(e.contains("parameters.\"shortlift:object.friction\"") && e.contains("no target"), "{e}");
        let e = error(&GOOD.replace("short-lift:object.friction", "short-lift:object.frction"));
        assert!(e.contains("not a scenario key"), "{e}");
        let e = error("[parameters.\"finger.relaxed_fraction\"]\nmin = 0.01\nmax = 0.5\n");
        assert!(e.contains("recordings") && e.contains("[[targets]]"), "{e}");
    }
}
