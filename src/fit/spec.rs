//! FIT.toml: which recordings, which scenario keys within which bounds, how to weigh the error,
//! how many evaluations.
//!
//! ```toml
//! recordings = ["runs/crimper-off", "runs/crimper-on"]   # run folders, relative to this file
//! [parameters."finger.relaxation_time_s"]
//! min = 5.0
//! max = 60.0
//! scale = "log"          # or "linear" (the default)
//! start = 15.0           # default: the middle of the range
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
//! ```
//! Everything is checked before anything runs ([`load_fit`]).

use super::objective::Weights;
use super::optimizer::Budget;
use super::recording::Recording;
use super::space::{Parameter, ParameterSpec};
use crate::scenario::ScenarioError;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// FIT.toml as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FitFile {
    /// Run folders, relative to the fit file.
    pub recordings: Vec<PathBuf>,
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
}

/// Reads a TOML spec file into `T`, errors naming the file and the dotted key.
pub fn read_spec<T: serde::de::DeserializeOwned>(file: &Path) -> Result<T, ScenarioError> {
    let text = crate::scenario::read_text(file)?;
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

/// Reads and checks a fit file: every recording read and matched, every parameter a scenario key
/// whose bounds are valid values in every recording's scenario, the weights and budget sane.
pub fn load_fit(file: &Path) -> Result<Fit, SpecError> {
    let spec: FitFile = read_spec(file)?;
    if spec.recordings.is_empty() {
        return Err(invalid(file, ("recordings".into(), "lists no recording".into())).into());
    }
    if let Some(bad) = spec.objective.check() {
        return Err(invalid(file, bad).into());
    }
    if let Some(bad) = spec.budget.check() {
        return Err(invalid(file, bad).into());
    }
    let params = super::space::parameters(file, &spec.parameters)?;
    let base = file.parent().unwrap_or(Path::new(""));
    let recordings = spec
        .recordings
        .iter()
        .enumerate()
        .map(|(index, dir)| {
            Recording::read(&base.join(dir)).map_err(|source| SpecError::Recording { file: file.into(), index, source })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let summaries: Vec<PathBuf> = recordings.iter().map(|r| r.dir.join("summary.json")).collect();
    let scenarios: Vec<(&Path, &toml::Table)> =
        summaries.iter().zip(&recordings).map(|(f, r)| (f.as_path(), &r.table)).collect();
    super::space::check_bounds(file, &params, &scenarios)?;
    Ok(Fit { file: file.into(), recordings, params, weights: spec.objective, budget: spec.budget })
}

impl Fit {
    /// Starts the search from the values `overlay` gives for the fit's parameters (a previous fit's
    /// `overlay.toml`); with `evaluations = 1` the fit only scores those values against its
    /// recordings, which is how held-out recordings are predicted. A value that is not a number
    /// or lies outside the parameter's bounds is an error naming the overlay and the key.
    pub fn start_from(&mut self, overlay: &crate::scenario::Overlay) -> Result<(), ScenarioError> {
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
