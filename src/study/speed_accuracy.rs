//! Speed against accuracy: one scenario over timestep × integrator × friction cone × finger
//! links on MuJoCo, and timestep × solver iterations × finger links on rapier, each compared
//! with one reference run (MuJoCo, smallest timestep, finest finger). A produce item's study
//! ([`ProduceGrid`]) varies its flex's grid and degrees of freedom instead of the integrator and
//! the cone (a flex runs on MuJoCo's discrete integrator only), and adds the peak contact
//! pressure's error.
//!
//! Accuracy is the RMS difference of the true sensor-force trace from the reference's, tick by
//! tick while the object should be held, and the drop-time difference. The runs are made without
//! force feedback, so the object slips out and a drop time exists to compare. Speed is simulated
//! seconds per CPU second of the thread that ran it (`RunSummary::sim_s_per_cpu_s`), so runs can
//! share the machine without changing each other's speed.

use super::convergence::{FlexSetting, force_rmse};
use super::{Damage, cell, run_all, set, write_csv};
use std::path::{Path, PathBuf};
use tendril_config::Override;
use tendril_plot::speed_accuracy::{SpeedAccuracyRow, render};
use tendril_run::scenario::PickPlaceScenario;
use tendril_twin::physics::{Dof, FingerConfig, PhysicsConfig};

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
    /// The full study (about 140 runs): uniform fingers around the 64 links the uniform grid
    /// converges at, halved and doubled, and graded fingers (the default's first, 7 links with a
    /// base stretch 8x finer), each at a step of 0.625-5 ms, against the convergence study's
    /// finest setting.
    pub fn full() -> Grid {
        let f = FingerConfig::default();
        Grid {
            timesteps_s: vec![0.000625, 0.00125, 0.0025, 0.005],
            integrators: vec!["euler", "implicitfast", "implicit", "rk4"],
            cones: vec!["pyramidal", "elliptic"],
            segments: vec![32, 64, 128],
            rapier_iterations: vec![4, 8],
            rapier_timesteps_s: vec![0.0025, 0.005],
            rapier_segments: vec![32],
            reference: (0.0003125, 256),
            // The default's finger, then the whole-link default's links (8 with the base 8x finer),
            // finer and graded otherwise, and last those 8 links with their first 17.5 mm as one
            // coarse link (issue 39's lever 2, fine links only where objects touch;
            // docs/studies/levers.md).
            graded: vec![
                (f.segments, f.base_refinement, f.fine_from_m),
                (8, 8, 0.0),
                (16, 8, 0.0),
                (16, 4, 0.0),
                (32, 2, 0.0),
                (8, 8, 0.0175),
            ],
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

    /// The grid to run with `sets`: this one, and `default`'s finger among its graded ones when
    /// `sets` moves it ([`DEFAULT_KEYS`]), so that it runs at every step. The full grid runs the
    /// project's default finger already; the quick one, a small look, does not.
    fn for_sets(&self, sets: &[Override], default: &Point) -> anyhow::Result<Grid> {
        if sets.iter().any(|o| DEFAULT_KEYS.contains(&o.key.as_str())) {
            self.with_default(default)
        } else {
            Ok(self.clone())
        }
    }

    /// This grid with `default`'s finger among its graded ones, so that it runs at every step;
    /// an error when `default`'s step is not one of the grid's.
    fn with_default(&self, default: &Point) -> anyhow::Result<Grid> {
        if !self.timesteps_s.contains(&default.timestep_s) {
            anyhow::bail!(
                "--set physics.timestep_s: the default's step ({} s) must be one of the study's steps ({:?} s)",
                default.timestep_s,
                self.timesteps_s
            );
        }
        let mut grid = self.clone();
        let finger = (default.segments, default.base_refinement, default.fine_from_m);
        if !grid.graded.contains(&finger) {
            grid.graded.insert(0, finger);
        }
        Ok(grid)
    }

    /// Every point, the reference first.
    fn points(&self) -> Vec<Point> {
        let mut labels = vec![Point::mujoco(self.reference.0, "implicitfast", "elliptic", self.reference.1)];
        for &dt in &self.timesteps_s {
            for &segments in &self.segments {
                for &integrator in &self.integrators {
                    for &cone in &self.cones {
                        labels.push(Point::mujoco(dt, integrator, cone, segments));
                    }
                }
                for &solver in &self.solvers {
                    labels.push(Point { solver, ..Point::mujoco(dt, "implicitfast", "elliptic", segments) });
                }
                if self.rapier_timesteps_s.contains(&dt) && self.rapier_segments.contains(&segments) {
                    labels.extend(self.rapier_iterations.iter().map(|&it| Point::rapier(dt, it, segments)));
                }
            }
            labels.extend(
                self.graded
                    .iter()
                    .map(|&(segments, refinement, from_m)| Point::graded(dt, segments, refinement, from_m)),
            );
        }
        labels
    }
}

/// The grid of a produce item's speed/accuracy study: the step × the finger's links × the flex's
/// grid and degrees of freedom, on MuJoCo's discrete integrator (the one a flex runs on) with
/// elliptic cones, against one reference, the finest of each.
#[derive(Debug, Clone)]
pub struct ProduceGrid {
    /// Timesteps \[s\].
    pub timesteps_s: Vec<f64>,
    /// Finger links (`finger.segments`; the default base refinement kept, as the convergence
    /// study's links ×2 keeps it).
    pub segments: Vec<u32>,
    /// The flex's grids and degrees of freedom.
    pub flexes: Vec<FlexSetting>,
    /// Other MuJoCo constraint solvers (`physics.solver`), each run at every timestep with the
    /// default links and flex.
    pub solvers: Vec<&'static str>,
    /// The reference: timestep \[s\], links and flex.
    pub reference: (f64, u32, FlexSetting),
    /// The item's own flex (the scenario's), ringed as the default with the project's step and
    /// links.
    pub default_flex: FlexSetting,
}

impl ProduceGrid {
    /// The full study around the item's flex `flex` (23 runs for a trilinear flex of 7 points):
    /// the step at 2.5 and 1.25 ms, the default's links and twice them, the grid coarser (5
    /// points), as given and refined (twice the intervals), trilinear and quadratic, and the CG
    /// solver, against the refined quadratic flex at 0.625 ms and twice the default's links.
    pub fn full(flex: FlexSetting) -> ProduceGrid {
        let links = FingerConfig::default().segments;
        let (coarse, fine) = (flex.count.saturating_sub(2).max(3), 2 * flex.count - 1);
        let at = |count: u32, dof: Dof| FlexSetting { count, dof };
        let mut flexes = vec![at(coarse, Dof::Trilinear), at(flex.count, Dof::Trilinear), at(fine, Dof::Trilinear)];
        flexes.extend([at(flex.count, Dof::Quadratic), at(fine, Dof::Quadratic)]);
        ProduceGrid {
            timesteps_s: vec![0.0025, 0.00125],
            segments: vec![links, 2 * links],
            flexes,
            solvers: vec!["cg"],
            reference: (0.000625, 2 * links, at(fine, Dof::Quadratic)),
            default_flex: flex,
        }
    }

    /// A small grid for a quick look: the item's flex and its quadratic form at 2.5 ms and the
    /// default's links, against the same flex at 1.25 ms.
    pub fn quick(flex: FlexSetting) -> ProduceGrid {
        let links = FingerConfig::default().segments;
        ProduceGrid {
            timesteps_s: vec![0.0025],
            segments: vec![links],
            flexes: vec![flex, FlexSetting { dof: Dof::Quadratic, ..flex }],
            solvers: vec![],
            reference: (0.00125, links, flex),
            default_flex: flex,
        }
    }

    /// Every point, the reference first.
    fn points(&self) -> Vec<Point> {
        let default_links = FingerConfig::default().segments;
        let (dt, links, flex) = self.reference;
        let mut points = vec![Point::produce(dt, links, flex)];
        for &dt in &self.timesteps_s {
            for &links in &self.segments {
                points.extend(self.flexes.iter().map(|&flex| Point::produce(dt, links, flex)));
            }
            points.extend(
                self.solvers
                    .iter()
                    .map(|&solver| Point { solver, ..Point::produce(dt, default_links, self.default_flex) }),
            );
        }
        points
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
    /// A produce item's flex (None for a rigid object).
    flex: Option<FlexSetting>,
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
            flex: None,
        }
    }

    /// A graded finger (`finger.base_refinement`, `finger.fine_from_m` \[m\]) with implicitfast,
    /// elliptic cones and Newton.
    fn graded(timestep_s: f64, segments: u32, base_refinement: u32, fine_from_m: f64) -> Point {
        Point { base_refinement, fine_from_m, ..Point::mujoco(timestep_s, "implicitfast", "elliptic", segments) }
    }

    /// A produce item's point: `segments` links (the default base refinement), the flex `flex`,
    /// the discrete integrator and elliptic cones.
    fn produce(timestep_s: f64, segments: u32, flex: FlexSetting) -> Point {
        let f = FingerConfig::default();
        let graded = Point::graded(timestep_s, segments, f.base_refinement, f.fine_from_m);
        Point { integrator: "discrete".into(), flex: Some(flex), ..graded }
    }

    /// The study's default: the scenario's own step and finger as loaded (after `--set`; for a
    /// produce item, with its flex `flex`).
    fn scenario_default(p: &PhysicsConfig, f: &FingerConfig, flex: Option<FlexSetting>) -> Point {
        match flex {
            Some(flex) => Point::produce(p.timestep_s, f.segments, flex),
            None => Point::graded(p.timestep_s, f.segments, f.base_refinement, f.fine_from_m),
        }
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
            flex: None,
        }
    }

    fn overrides(&self) -> Vec<Override> {
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
        if let Some(f) = self.flex {
            o.extend([set("produce.count", f.count), set("produce.dof", format!("\"{}\"", f.dof.name()))]);
        }
        o
    }
}

/// The keys a study's grid sets in every run itself: a `--set` of one would change nothing, so it
/// is refused. The step and the finger's links are not among them: set, they move the ringed
/// default, as they move the base of the convergence study.
const GRID_KEYS: [&str; 8] = [
    "feedback",
    "physics.backend",
    "physics.integrator",
    "physics.cone",
    "physics.solver",
    "physics.rapier.solver_iterations",
    "produce.count",
    "produce.dof",
];

/// The keys that move the ringed default: set, its finger runs at every step of the grid.
const DEFAULT_KEYS: [&str; 4] =
    ["physics.timestep_s", "finger.segments", "finger.base_refinement", "finger.fine_from_m"];

/// Loads `scenario` with `sets` (refusing a key the grid sets itself) and returns its default
/// point: the scenario's own step and finger, ringed in the chart (for a produce item, with the
/// flex `flex`).
fn load_default(scenario: &Path, sets: &[Override], flex: Option<FlexSetting>) -> anyhow::Result<Point> {
    if let Some(o) = sets.iter().find(|o| GRID_KEYS.contains(&o.key.as_str())) {
        anyhow::bail!(
            "--set {}: the speed-accuracy study sets this key in every run itself ({}); set the model's other keys",
            o.key,
            GRID_KEYS.join(", ")
        );
    }
    let loaded: PickPlaceScenario = tendril_config::load(scenario, sets)?;
    Ok(Point::scenario_default(&loaded.physics, &loaded.finger, flex))
}

/// Runs the study on `scenario` with `sets` in every run (the model's keys: a calibration, a
/// joint, the contacts; the grid's own axes win), writes `speed_accuracy.csv` and its chart into
/// `out`, the scenario's own step and finger ringed as the default (run at every step when `sets`
/// moves it, `DEFAULT_KEYS`); `threads` runs at once (speed is each run's own CPU time). Returns
/// the files written.
pub fn run(
    scenario: &Path,
    grid: &Grid,
    sets: &[Override],
    out: &Path,
    threads: usize,
) -> anyhow::Result<Vec<PathBuf>> {
    let default = load_default(scenario, sets, None)?;
    measure(scenario, &grid.for_sets(sets, &default)?.points(), sets, &default, out, threads)
}

/// Runs a produce item's study ([`ProduceGrid`]) on `scenario` with `sets` in every run and
/// writes the same files, with the flex's columns and the peak pressure's error.
pub fn run_produce(
    scenario: &Path,
    grid: &ProduceGrid,
    sets: &[Override],
    out: &Path,
    threads: usize,
) -> anyhow::Result<Vec<PathBuf>> {
    let default = load_default(scenario, sets, Some(grid.default_flex))?;
    measure(scenario, &grid.points(), sets, &default, out, threads)
}

/// Runs `labels` (the reference first) on `scenario`, each after `sets`, `threads` at once, and
/// writes `speed_accuracy.csv` and its chart into `out`, `default` ringed.
fn measure(
    scenario: &Path,
    labels: &[Point],
    sets: &[Override],
    default: &Point,
    out: &Path,
    threads: usize,
) -> anyhow::Result<Vec<PathBuf>> {
    let overrides = labels.iter().map(|p| sets.iter().cloned().chain(p.overrides()).collect()).collect();
    let runs = run_all(scenario, overrides, threads)?;
    let reference = &runs[0];
    let rows: Vec<SpeedAccuracyRow> = runs
        .iter()
        .zip(labels)
        .enumerate()
        .map(|(i, (r, point))| {
            let ok = r.summary.outcome != "error";
            let drop_error = match (r.summary.drop_time_s, reference.summary.drop_time_s) {
                (Some(a), Some(b)) => Some((a - b).abs()),
                _ => None,
            };
            let peak = |r: &super::StudyRun| Damage::of(&r.summary).peak_pressure_kpa;
            let pressure_error = match (peak(r), peak(reference)) {
                (Some(a), Some(b)) if ok && b > 0.0 => Some(100.0 * (a - b).abs() / b),
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
                produce_grid: point.flex.map(|f| f.count),
                produce_dof: point.flex.map(|f| f.dof.name().to_string()),
                peak_pressure_error_pct: pressure_error,
                status: if ok { "ok".into() } else { "diverged".into() },
                is_default: point == default && i != 0,
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
        "produce_grid",
        "produce_dof",
        "peak_pressure_error_pct",
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
                r.produce_grid.map_or(String::new(), |n| n.to_string()),
                r.produce_dof.clone().unwrap_or_default(),
                cell(r.peak_pressure_error_pct),
            ]
        })
        .collect();
    write_csv(&csv, &header, &cells)?;
    let mut files = vec![csv];
    files.extend(render(&rows, out)?);
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_set_finger_is_ringed_and_run_at_every_step_and_a_grid_key_is_refused() {
        let crimper = Path::new("scenarios/crimper.toml");
        let sets = ["finger.segments=6", r#"finger.base_joint="whole_link""#].map(|s| s.parse().unwrap());
        let default = load_default(crimper, &sets, None).unwrap();
        assert_eq!(default, Point::graded(0.0025, 6, 8, 0.0));
        let points = Grid::full().for_sets(&sets, &default).unwrap().points();
        for dt in Grid::full().timesteps_s {
            assert_eq!(points.iter().filter(|p| **p == Point::graded(dt, 6, 8, 0.0)).count(), 1, "{dt}");
        }
        // The project's own default is already among the graded fingers: the grid is unchanged.
        let own = load_default(crimper, &[], None).unwrap();
        assert_eq!(Grid::full().for_sets(&[], &own).unwrap().points(), Grid::full().points());
        let err = load_default(crimper, &[r#"physics.integrator="euler""#.parse().unwrap()], None).unwrap_err();
        assert!(err.to_string().contains("--set physics.integrator: the speed-accuracy study sets this key"), "{err}");
        let off_step = ["physics.timestep_s=0.003".parse().unwrap()];
        let off_grid = load_default(crimper, &off_step, None).unwrap();
        let err = Grid::full().for_sets(&off_step, &off_grid).unwrap_err();
        assert!(err.to_string().contains("must be one of the study's steps"), "{err}");
        // The quick grid, whose steps are not the default's, runs as it is when nothing moves it.
        assert_eq!(Grid::quick().for_sets(&[], &own).unwrap().points(), Grid::quick().points());
    }

    #[test]
    fn a_produce_grid_holds_its_default_once_and_runs_every_point_on_the_discrete_integrator() {
        let flex = FlexSetting { count: 7, dof: Dof::Trilinear };
        let points = ProduceGrid::full(flex).points();
        // 2 steps × 2 links × 5 flexes, the CG solver at each step, and the reference.
        assert_eq!(points.len(), 23);
        let links = FingerConfig::default().segments;
        assert_eq!(points[0], Point::produce(0.000625, 2 * links, FlexSetting { count: 13, dof: Dof::Quadratic }));
        let default = Point::scenario_default(&PhysicsConfig::default(), &FingerConfig::default(), Some(flex));
        assert_eq!(points.iter().filter(|p| **p == default).count(), 1);
        for p in &points {
            let o = p.overrides();
            let value = |key: &str| o.iter().find(|o| o.key == key).map(|o| o.value.clone());
            assert_eq!(value("physics.integrator"), Some(toml::Value::String("discrete".into())), "{p:?}");
            assert!(value("produce.count").is_some() && value("produce.dof").is_some(), "{p:?}");
        }
        // A rigid object's grid never sets the flex.
        assert!(Grid::quick().points().iter().all(|p| p.flex.is_none()));
    }
}
