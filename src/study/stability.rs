//! Stability where numerical methods fail: for each MuJoCo integrator and for rapier, the
//! scenario at growing timesteps, classified as stable, diverged, too deep a penetration, or a
//! lost grasp (the object dropped although the run at the project's defaults holds it).

use super::{cell, run_all, set, write_csv};
use std::path::{Path, PathBuf};
use tendril_plot::stability::{StabilityRow, render};

/// Timesteps tried \[s\], from MuJoCo's usual 1 ms to the largest a scenario accepts (50 ms).
pub const TIMESTEPS_S: [f64; 7] = [0.001, 0.002, 0.005, 0.01, 0.02, 0.03, 0.05];
/// MuJoCo integrators compared.
pub const INTEGRATORS: [&str; 4] = ["euler", "implicitfast", "implicit", "rk4"];
/// The rapier series' label (rapier steps with its PGS solver and symplectic Euler).
pub const RAPIER_SERIES: &str = "pgs";
/// The rapier series' finger: 32 uniform links (`finger.base_refinement` 1), as in its tests, where
/// its calibration was checked (docs/studies/rapier.md#the-papers-rows-on-rapier). At 64 uniform links rapier runs at
/// about 0.1x real time, and the 1 ms point alone would take ten minutes.
pub const RAPIER_SEGMENTS: u32 = 32;

/// Runs the study on `scenario` (which should hold its object at the defaults), writes
/// `stability.csv` and its chart into `out`. `threads` workers.
pub fn run(scenario: &Path, timesteps: &[f64], out: &Path, threads: usize) -> anyhow::Result<Vec<PathBuf>> {
    let mut sets = vec![vec![]];
    let mut labels = vec![("default", 0.0)];
    for integrator in INTEGRATORS {
        for &dt in timesteps {
            sets.push(vec![set("physics.timestep_s", dt), set("physics.integrator", format!("\"{integrator}\""))]);
            labels.push((integrator, dt));
        }
    }
    // rapier at its default solver iterations: one series (it has one integrator), on the 32-link
    // finger (`RAPIER_SEGMENTS`).
    for &dt in timesteps {
        sets.push(vec![
            set("physics.timestep_s", dt),
            set("physics.backend", "\"rapier\""),
            set("finger.segments", RAPIER_SEGMENTS),
            set("finger.base_refinement", 1),
        ]);
        labels.push((RAPIER_SERIES, dt));
    }
    let runs = run_all(scenario, sets, threads)?;
    let held_at_defaults = runs[0].summary.outcome == "held";
    let rows: Vec<StabilityRow> = runs[1..]
        .iter()
        .zip(&labels[1..])
        .map(|(r, &(integrator, dt))| {
            let error = r.summary.error.as_deref().unwrap_or("");
            let outcome = match r.summary.outcome.as_str() {
                "error" if error.contains("penetrat") => "penetration",
                "error" => "diverged",
                "dropped" if held_at_defaults => "lost_grasp",
                _ => "stable",
            };
            StabilityRow {
                backend: r.summary.run.backend.clone(),
                integrator: integrator.into(),
                timestep_s: dt,
                outcome: outcome.into(),
            }
        })
        .collect();
    std::fs::create_dir_all(out).map_err(|e| anyhow::anyhow!("{}: {e}", out.display()))?;
    let csv = out.join("stability.csv");
    let cells: Vec<Vec<String>> = rows
        .iter()
        .zip(&runs[1..])
        .map(|(r, run)| {
            vec![
                r.backend.clone(),
                r.integrator.clone(),
                r.timestep_s.to_string(),
                r.outcome.clone(),
                cell(Some(run.summary.real_time_factor)),
                run.summary.error.clone().unwrap_or_default(),
            ]
        })
        .collect();
    write_csv(&csv, &["backend", "integrator", "timestep_s", "outcome", "sim_s_per_wall_s", "cause"], &cells)?;
    let mut files = vec![csv];
    files.extend(render(&rows, out)?);
    Ok(files)
}
