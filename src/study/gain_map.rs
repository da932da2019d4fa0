//! Where the closed loop oscillates or loses the object: each object's scenario over a
//! (Kp, Ki) grid with feedback on.

use super::{run_all, set, write_csv};
use std::path::{Path, PathBuf};
use tendril_plot::gain_map::{GainMapRow, render};

/// Kp values tried [(°/s)/N]: a decade each side of the paper's 20.
pub const KP: [f64; 7] = [2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0];
/// Ki values tried [(°/s)/(N·s)]: from none through the paper's 0.05 to strongly integral.
pub const KI: [f64; 5] = [0.0, 0.05, 0.5, 5.0, 50.0];

/// Runs the map for each scenario, with `extra` applied to every run before the gains, writes
/// `gain_map.csv` and a chart per object into `out`. A gain the scenario's bounds refuse is an
/// error naming the key before anything runs.
pub fn run(
    scenarios: &[PathBuf],
    kp: &[f64],
    ki: &[f64],
    extra: &[tendril_config::Override],
    out: &Path,
    threads: usize,
) -> anyhow::Result<Vec<PathBuf>> {
    let mut rows = Vec::new();
    for scenario in scenarios {
        let mut sets = Vec::new();
        for &p in kp {
            for &i in ki {
                let mut overrides = extra.to_vec();
                overrides.extend([set("controller.kp", p), set("controller.ki", i), set("feedback", true)]);
                sets.push(overrides);
            }
        }
        for r in run_all(scenario, sets, threads)? {
            rows.push(GainMapRow {
                object: r.summary.run.object.clone(),
                kp: r.summary.run.gains.kp,
                ki: r.summary.run.gains.ki,
                outcome: r.summary.outcome.clone(),
                oscillating: r.summary.metrics.oscillating,
            });
        }
    }
    std::fs::create_dir_all(out).map_err(|e| anyhow::anyhow!("{}: {e}", out.display()))?;
    let csv = out.join("gain_map.csv");
    let cells: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            vec![r.object.clone(), r.kp.to_string(), r.ki.to_string(), r.outcome.clone(), r.oscillating.to_string()]
        })
        .collect();
    write_csv(&csv, &["object", "kp", "ki", "outcome", "oscillating"], &cells)?;
    let mut files = vec![csv];
    files.extend(render(&rows, out)?);
    Ok(files)
}
