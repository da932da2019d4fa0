//! `tendril fit` and `tendril tune`: searching scenario keys for the values that best match recorded
//! runs (calibrating the twin to a cell) or that best meet control goals (tuning the controller).
//!
//! - [`space`]: the parameters, their bounds and scales, checked against the scenarios.
//! - [`recording`]: a run folder read back (trace and effective scenario) and checked.
//! - [`bag`]: a rosbag2 recording (a lab's, or a run's `bag/`) read as a recording.
//! - [`objective`]: the distance between a simulated run and a recording.
//! - [`target`]: published figures (outcome, drop phase and time, rise, fluctuation) to match.
//! - [`optimizer`]: the CMA-ES search, parallel, over the unit cube of the parameters.
//! - [`log`]: the durable log of every evaluation, for `--resume`.
//! - [`spec`]: the fit file (FIT.toml).
//! - [`execute`]: running a fit and writing its results.
//! - [`tune`]: TUNE.toml and running a tune.

pub mod bag;
pub mod execute;
pub mod log;
pub mod objective;
pub mod optimizer;
pub mod recording;
pub mod space;
pub mod spec;
pub mod target;
pub mod tune;

pub use spec::{Fit, load_fit};

use std::path::Path;

/// Writes `path` atomically, naming it in the error.
pub fn write_text(path: &Path, text: &str) -> anyhow::Result<()> {
    tendril_config::write_atomically(path, text.as_bytes())
        .map_err(|(file, e)| anyhow::anyhow!("{}: cannot write: {e}", file.display()))
}

/// Writes `values` of `params` as an overlay (quoted dotted keys, one a line) under a `comment`. A
/// scoped parameter (`NAME:KEY`) holds for one scenario only, so it is written as a comment an
/// overlay does not apply, to be copied by hand where it belongs (an object's model, say).
pub fn write_overlay(path: &Path, comment: &str, params: &[space::Parameter], values: &[f64]) -> anyhow::Result<()> {
    let mut text =
        format!("# {comment}\n# Apply with --overlay {} on run, sweep, reproduce, serve or tune.\n", path.display());
    for (p, &v) in params.iter().zip(values) {
        if let Some(scope) = p.scope() {
            text += &format!("# {scope} only: \"{}\" = {}\n", p.scenario_key(), p.toml_value(v));
            continue;
        }
        let mut t = toml::Table::new();
        t.insert(p.key.clone(), p.toml_value(v));
        text += &toml::to_string(&t)?;
    }
    write_text(path, &text)
}
