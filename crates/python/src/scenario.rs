//! [`Scenario`] and `load`: a scenario file with an overlay and `set` overrides, loaded and checked
//! as `tendril run FILE --overlay O --set ...` loads it.

use crate::errors::{run_error, scenario_error};
use crate::overrides::overrides;
use pyo3::prelude::*;
use std::path::{Path, PathBuf};
use tendril_config::{Overlay, Override};
use tendril_run::scenario::PickPlaceScenario;

/// A loaded, checked scenario: what `tendril.load` returns and `tendril.run` runs.
#[pyclass(frozen, module = "tendril._native")]
#[derive(Clone)]
pub struct Scenario {
    /// The scenario file.
    file: PathBuf,
    /// The overlay file, if any.
    overlay: Option<PathBuf>,
    /// The `set` overrides, in order.
    set: Vec<Override>,
    /// The scenario with everything applied.
    pub(crate) scenario: PickPlaceScenario,
}

impl Scenario {
    /// Loads `file` with `overlay`, then `set`, as the command line's `ScenarioArgs::load` does.
    pub fn load(
        file: &Path,
        overlay: Option<&Path>,
        set: Vec<Override>,
    ) -> Result<Scenario, tendril_config::ScenarioError> {
        let scenario = Overlay::load(overlay)?.load_scenario(file, &set)?;
        Ok(Scenario { file: file.into(), overlay: overlay.map(Into::into), set, scenario })
    }

    /// This scenario loaded again with `extra` after its own overrides (how `tendril run`'s
    /// `--backend`, `--seed` and `--feedback` apply: as overrides after `--set`, checked alike).
    pub fn with(&self, extra: Vec<Override>) -> Result<Scenario, tendril_config::ScenarioError> {
        if extra.is_empty() {
            return Ok(self.clone());
        }
        let mut set = self.set.clone();
        set.extend(extra);
        Scenario::load(&self.file, self.overlay.as_deref(), set)
    }
}

#[pymethods]
impl Scenario {
    /// The scenario's `name`.
    #[getter]
    fn name(&self) -> &str {
        &self.scenario.name
    }

    /// The seed of every random process.
    #[getter]
    fn seed(&self) -> u64 {
        self.scenario.seed
    }

    /// The force setpoint \[N\].
    #[getter]
    fn setpoint_n(&self) -> f64 {
        self.scenario.setpoint_n
    }

    /// The scenario file.
    #[getter]
    fn file(&self) -> PathBuf {
        self.file.clone()
    }

    /// The overlay file, if any.
    #[getter]
    fn overlay(&self) -> Option<PathBuf> {
        self.overlay.clone()
    }

    /// The `set` overrides as `"key=value"` strings, in the order applied.
    #[getter]
    fn set(&self) -> Vec<String> {
        self.set.iter().map(|o| format!("{}={}", o.key, o.value)).collect()
    }

    /// The effective scenario (defaults, file, overlay and overrides applied) as JSON: what
    /// `summary.json` records under `effective_scenario`.
    fn to_json(&self) -> PyResult<String> {
        serde_json::to_string(&self.scenario).map_err(|e| run_error(e.into()))
    }

    /// The effective scenario as a dict (`to_json()` read back).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py.import("json")?.call_method1("loads", (self.to_json()?,))
    }

    /// The effective scenario as TOML: what `scenario.toml` holds, which `tendril run` repeats.
    fn to_toml(&self) -> PyResult<String> {
        toml::to_string(&self.scenario).map_err(|e| run_error(e.into()))
    }

    fn __repr__(&self) -> String {
        format!("<tendril.Scenario {:?} from {}>", self.scenario.name, self.file.display())
    }
}

/// Loads scenario file `path` with `overlay` (a file of scenario keys, applied first) and `set`
/// (a dict of dotted keys to values, or a list of `"key=value"` strings, applied last), checked
/// as the command line checks them. Raises `ScenarioError` with the command line's message.
#[pyfunction]
#[pyo3(signature = (path, set = None, overlay = None))]
pub fn load(path: PathBuf, set: Option<&Bound<'_, PyAny>>, overlay: Option<PathBuf>) -> PyResult<Scenario> {
    Scenario::load(&path, overlay.as_deref(), overrides(set)?).map_err(scenario_error)
}
