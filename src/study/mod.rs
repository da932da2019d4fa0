//! Studies over many runs: speed against accuracy, stability limits, gain maps, controllers.
//!
//! Each study loads one scenario with overrides per run, runs it on the twin, writes a CSV and
//! draws its chart with [`tendril_plot`].
//!
//! - [`convergence`]: each Section V case under timestep and finger-link refinement.
//! - [`speed_accuracy`]: timestep × integrator × cone × finger links against a fine reference.
//! - [`stability`]: the largest stable timestep per integrator, and what fails past it.
//! - [`gain_map`]: where in (Kp, Ki) the loop oscillates or loses the object, per object.
//! - [`controllers`]: each force controller × object × disturbance set over seeds: held rate,
//!   fluctuation, rise, overshoot, peak force.
//! - [`jitter`]: the real path against the virtual devices under injected timing jitter, against
//!   the twin (runs in real time, one at a time).
//! - [`settle`]: grasp until settled against the paper's fixed grasp: cycle time and held runs.
//! - [`detector`]: settings chosen by a detected class: what a wrong class costs, and held runs
//!   against the detector's accuracy.
//! - [`hold`]: a long grasp's grip and twine motor over time, the hold off and on.
//! - [`finger`]: the finger's growth length and pad height against hold margin, contact area, peak
//!   force and cycle time, and the size its numbers recommend.
//! - [`produce`]: the produce items against Hertz between plates, and each item's window of
//!   setpoints that holds or harvests it without bruising it.

pub mod controllers;
pub mod convergence;
pub mod detector;
pub mod finger;
pub mod gain_map;
pub mod hold;
pub mod jitter;
pub mod placement;
pub mod produce;
pub mod settle;
pub mod speed_accuracy;
pub mod stability;

use rayon::prelude::*;
use std::path::Path;
use tendril_config::Override;
use tendril_run::execute::{ModelCache, run_on_twin};
use tendril_run::runner::RunReport;
use tendril_run::scenario::PickPlaceScenario;
use tendril_run::summary::RunSummary;

/// `key=value` as an override (the value parsed as TOML, like `--set`).
pub fn set(key: &str, value: impl std::fmt::Display) -> Override {
    format!("{key}={value}").parse().expect("study keys and values are well formed")
}

/// One run of a study: its overrides and what came of it.
pub struct StudyRun {
    /// Overrides on the study's scenario.
    pub overrides: Vec<Override>,
    /// The summary (outcome "error" with the cause when the run could not start).
    pub summary: RunSummary,
    /// The run's ticks, when it ran.
    pub report: Option<RunReport>,
}

/// Loads `scenario` with each override set and runs them on `threads` workers (1 for timing
/// studies, so runs do not compete for cores). Bad keys or values fail before anything runs.
pub fn run_all(scenario: &Path, sets: Vec<Vec<Override>>, threads: usize) -> anyhow::Result<Vec<StudyRun>> {
    let scenarios: Vec<PickPlaceScenario> =
        sets.iter().map(|o| tendril_config::load(scenario, o)).collect::<Result<_, _>>()?;
    let models = ModelCache::default();
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build()?;
    let progress = indicatif::ProgressBar::new(sets.len() as u64);
    let runs = pool.install(|| {
        scenarios
            .par_iter()
            .zip(sets)
            .map(|(s, overrides)| {
                let run = match run_on_twin(s, &models, None) {
                    Ok((summary, report)) => StudyRun { overrides, summary, report: Some(report) },
                    Err(e) => StudyRun {
                        overrides,
                        summary: RunSummary::failed_to_start(&s.name, format!("{e:#}")),
                        report: None,
                    },
                };
                progress.inc(1);
                run
            })
            .collect()
    });
    progress.finish_and_clear();
    Ok(runs)
}

/// Writes a CSV of string cells, naming the file in the error.
pub fn write_csv(path: &Path, header: &[&str], rows: &[Vec<String>]) -> anyhow::Result<()> {
    let err = |e: csv::Error| anyhow::anyhow!("{}: {e}", path.display());
    let mut w = csv::Writer::from_path(path).map_err(err)?;
    w.write_record(header).map_err(err)?;
    for r in rows {
        w.write_record(r).map_err(err)?;
    }
    w.flush().map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))
}

/// A produce item's damage in one run of a study (both fields absent for a rigid object), so the
/// cycle's studies can count a grip that held but bruised as the failure it is on a farm.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Damage {
    /// The largest peak contact pressure on the item \[kPa\].
    pub peak_pressure_kpa: Option<f64>,
    /// Whether any contact went above the item's bruise threshold.
    pub bruised: Option<bool>,
}

impl Damage {
    /// The CSV columns of [`Damage::cells`], in their order (each study's run CSV names them here).
    pub const HEADER: [&'static str; 2] = ["peak_pressure_kpa", "bruised"];

    /// A run's damage, from its summary.
    pub fn of(summary: &RunSummary) -> Damage {
        let p = summary.produce.as_ref();
        Damage { peak_pressure_kpa: p.map(|p| p.peak_pressure_kpa), bruised: p.map(|p| p.bruised) }
    }

    /// Whether the run bruised its item (never, for a rigid object).
    pub fn is_bruised(&self) -> bool {
        self.bruised == Some(true)
    }

    /// Its CSV cells (empty for a rigid object).
    pub fn cells(&self) -> [String; 2] {
        [cell(self.peak_pressure_kpa), self.bruised.map_or(String::new(), |b| b.to_string())]
    }
}

/// Text of an optional number for a CSV cell (empty when absent).
pub fn cell(v: Option<f64>) -> String {
    v.map_or(String::new(), |v| format!("{v}"))
}
