//! Speed against accuracy: one scenario over timestep × integrator × friction cone × finger
//! links on MuJoCo, and timestep × solver iterations × finger links on rapier, each compared
//! with one reference run (MuJoCo, smallest timestep, finest finger).
//!
//! Accuracy is the RMS difference of the true sensor-force trace from the reference's, tick by
//! tick while the object should be held, and the drop-time difference. The runs are made without
//! force feedback, so the object slips out and a drop time exists to compare. Speed is simulated
//! seconds per CPU second of the thread that ran it (`RunSummary::sim_s_per_cpu_s`), so runs can
//! share the machine without changing each other's speed.

use super::convergence::force_rmse;
use super::{cell, run_all, set, write_csv};
use std::path::{Path, PathBuf};
use tendril_plot::speed_accuracy::{SpeedAccuracyRow, render};
use tendril_twin::physics::{FingerConfig, PhysicsConfig};

/// The grid of a speed/accuracy study.
#[derive(Debug, Clone)]
pub struct Grid {
    /// Timesteps \[s\].
    pub timesteps_s: Vec<f64>,
    /// Integrators (`euler`, `implicitfast`, `implicit`, `rk4`).
    pub integrators: Vec<&'static str>,
    /// Friction cones (`pyramidal`, `elliptic`).
    pub cones: Vec<&'static str>,
    /// Finger links.
    pub segments: Vec<u32>,
    /// rapier solver iterations per step (the rapier series; empty: MuJoCo only). rapier has one
    /// integrator and its own friction cone, so its points vary iterations instead.
    pub rapier_iterations: Vec<u32>,
    /// The timesteps and links rapier runs at, each a subset of the MuJoCo axes: rapier runs at
    /// about a tenth of MuJoCo's speed, and its finest points would take hours.
    pub rapier_timesteps_s: Vec<f64>,
    /// See `rapier_timesteps_s`.
    pub rapier_segments: Vec<u32>,
    /// The reference: timestep \[s\] and links (MuJoCo, implicitfast, elliptic cone: the finest
    /// setting of the convergence study, where the integrators agree).
    pub reference: (f64, u32),
    /// Graded fingers (links, `finger.base_refinement`, `finger.fine_from_m` \[m\]) run at every
    /// MuJoCo timestep with implicitfast and elliptic cones: the strip cut finer only between its
    /// base (or `fine_from_m`) and the pad.
    pub graded: Vec<(u32, u32, f64)>,
    /// Other MuJoCo constraint solvers (`physics.solver`) run at every MuJoCo timestep with
    /// implicitfast, elliptic cones and each of `segments`.
    pub solvers: Vec<&'static str>,
}

impl Grid {
    /// The full study (about 130 runs): uniform fingers around the 64 links the uniform grid
    /// converges at, halved and doubled, and graded fingers (the default, 8 links with a base
    /// stretch 8x finer, among them), each at a step of 0.625-5 ms, against the convergence
    /// study's finest setting.
    pub fn full() -> Grid {
        Grid {
            timesteps_s: vec![0.000625, 0.00125, 0.0025, 0.005],
            integrators: vec!["euler", "implicitfast", "implicit", "rk4"],
            cones: vec!["pyramidal", "elliptic"],
            segments: vec![32, 64, 128],
            rapier_iterations: vec![4, 8],
            rapier_timesteps_s: vec![0.0025, 0.005],
            rapier_segments: vec![32],
            reference: (0.0003125, 256),
            // The last: the default with its first 17.5 mm as one coarse link (issue 39's lever 2,
            // fine links only where objects touch; docs/studies/levers.md).
            graded: vec![(8, 8, 0.0), (16, 8, 0.0), (16, 4, 0.0), (32, 2, 0.0), (8, 8, 0.0175)],
            solvers: vec!["cg"],
        }
    }

    /// A small grid for a quick look (and the tests).
    pub fn quick() -> Grid {
        Grid {
            timesteps_s: vec![0.002, 0.005],
            integrators: vec!["implicitfast", "euler"],
            cones: vec!["elliptic"],
            segments: vec![16],
            rapier_iterations: vec![8],
            rapier_timesteps_s: vec![0.002, 0.005],
            rapier_segments: vec![16],
            reference: (0.0025, 32),
            graded: vec![(8, 2, 0.0)],
            solvers: vec![],
        }
    }
}

/// One point of the grid: the backend's own axes (MuJoCo: integrator and cone; rapier: solver
/// iterations, with the integrator and cone columns naming what rapier does instead).
#[derive(Debug, Clone, PartialEq)]
struct Point {
    timestep_s: f64,
    integrator: String,
    cone: String,
    segments: u32,
    base_refinement: u32,
    fine_from_m: f64,
    solver: &'static str,
    rapier_iterations: Option<u32>,
}

impl Point {
    fn mujoco(timestep_s: f64, integrator: &str, cone: &str, segments: u32) -> Point {
        Point {
            timestep_s,
            integrator: integrator.into(),
            cone: cone.into(),
            segments,
            base_refinement: 1,
            fine_from_m: 0.0,
            solver: "newton",
            rapier_iterations: None,
        }
    }

    /// A graded finger (`finger.base_refinement`, `finger.fine_from_m` \[m\]) with implicitfast,
    /// elliptic cones and Newton.
    fn graded(timestep_s: f64, segments: u32, base_refinement: u32, fine_from_m: f64) -> Point {
        Point { base_refinement, fine_from_m, ..Point::mujoco(timestep_s, "implicitfast", "elliptic", segments) }
    }

    /// The project's default settings (`PhysicsConfig` and `FingerConfig` defaults).
    fn project_default() -> Point {
        let (p, f) = (PhysicsConfig::default(), FingerConfig::default());
        Point::graded(p.timestep_s, f.segments, f.base_refinement, f.fine_from_m)
    }

    fn rapier(timestep_s: f64, iterations: u32, segments: u32) -> Point {
        Point {
            timestep_s,
            integrator: format!("pgs ({iterations} it.)"),
            cone: "coulomb".into(),
            segments,
            base_refinement: 1,
            fine_from_m: 0.0,
            solver: "pgs",
            rapier_iterations: Some(iterations),
        }
    }

    fn overrides(&self) -> Vec<tendril_config::Override> {
        let mut o = vec![
            set("physics.timestep_s", self.timestep_s),
            set("finger.segments", self.segments),
            set("finger.base_refinement", self.base_refinement),
            set("finger.fine_from_m", self.fine_from_m),
            set("feedback", false),
        ];
        match self.rapier_iterations {
            None => o.extend([
                set("physics.integrator", format!("\"{}\"", self.integrator)),
                set("physics.cone", format!("\"{}\"", self.cone)),
                set("physics.solver", format!("\"{}\"", self.solver)),
            ]),
            Some(it) => o.extend([set("physics.backend", "\"rapier\""), set("physics.rapier.solver_iterations", it)]),
        }
        o
    }
}

/// Runs the study on `scenario`, writes `speed_accuracy.csv` and its chart into `out`, the
/// project's default settings ringed; `threads` runs at once (speed is each run's own CPU time).
/// Returns the files written.
pub fn run(scenario: &Path, grid: &Grid, out: &Path, threads: usize) -> anyhow::Result<Vec<PathBuf>> {
    let mut labels = vec![Point::mujoco(grid.reference.0, "implicitfast", "elliptic", grid.reference.1)];
    for &dt in &grid.timesteps_s {
        for &segments in &grid.segments {
            for &integrator in &grid.integrators {
                for &cone in &grid.cones {
                    labels.push(Point::mujoco(dt, integrator, cone, segments));
                }
            }
            for &solver in &grid.solvers {
                labels.push(Point { solver, ..Point::mujoco(dt, "implicitfast", "elliptic", segments) });
            }
            if grid.rapier_timesteps_s.contains(&dt) && grid.rapier_segments.contains(&segments) {
                labels.extend(grid.rapier_iterations.iter().map(|&it| Point::rapier(dt, it, segments)));
            }
        }
        labels.extend(
            grid.graded.iter().map(|&(segments, refinement, from_m)| Point::graded(dt, segments, refinement, from_m)),
        );
    }
    let default = Point::project_default();
    let runs = run_all(scenario, labels.iter().map(Point::overrides).collect(), threads)?;
    let reference = &runs[0];
    let rows: Vec<SpeedAccuracyRow> = runs
        .iter()
        .zip(&labels)
        .enumerate()
        .map(|(i, (r, point))| {
            let ok = r.summary.outcome != "error";
            let drop_error = match (r.summary.drop_time_s, reference.summary.drop_time_s) {
                (Some(a), Some(b)) => Some((a - b).abs()),
                _ => None,
            };
            SpeedAccuracyRow {
                backend: r.summary.run.backend.clone(),
                integrator: point.integrator.clone(),
                cone: point.cone.clone(),
                solver: point.solver.to_string(),
                timestep_s: point.timestep_s,
                segments: point.segments,
                base_refinement: point.base_refinement,
                fine_from_m: point.fine_from_m,
                sim_s_per_cpu_s: ok.then_some(r.summary.sim_s_per_cpu_s),
                force_rmse_n: if i == 0 {
                    Some(0.0)
                } else if ok {
                    force_rmse(r, reference)
                } else {
                    None
                },
                drop_time_error_s: if ok { drop_error } else { None },
                status: if ok { "ok".into() } else { "diverged".into() },
                is_default: *point == default && i != 0,
                is_reference: i == 0,
            }
        })
        .collect();
    std::fs::create_dir_all(out).map_err(|e| anyhow::anyhow!("{}: {e}", out.display()))?;
    let csv = out.join("speed_accuracy.csv");
    let header = [
        "backend",
        "integrator",
        "cone",
        "solver",
        "timestep_s",
        "segments",
        "base_refinement",
        "fine_from_m",
        "sim_s_per_cpu_s",
        "force_rmse_n",
        "drop_time_error_s",
        "status",
        "is_default",
        "is_reference",
    ];
    let cells: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            vec![
                r.backend.clone(),
                r.integrator.clone(),
                r.cone.clone(),
                r.solver.clone(),
                r.timestep_s.to_string(),
                r.segments.to_string(),
                r.base_refinement.to_string(),
                r.fine_from_m.to_string(),
                cell(r.sim_s_per_cpu_s),
                cell(r.force_rmse_n),
                cell(r.drop_time_error_s),
                r.status.clone(),
                r.is_default.to_string(),
                r.is_reference.to_string(),
            ]
        })
        .collect();
    write_csv(&csv, &header, &cells)?;
    let mut files = vec![csv];
    files.extend(render(&rows, out)?);
    Ok(files)
}
