//! `tendril chart`: studies over many runs, each written as CSV and charted.

use super::emit;
use crate::study;
use std::path::PathBuf;
use std::process::ExitCode;
use tendril_twin::physics::Backend;

/// Arguments of `tendril chart`.
#[derive(Debug, clap::Args)]
pub struct ChartArgs {
    /// Which study: `convergence` (exits 1 when a convergence criterion breaks), `speed-accuracy`,
    /// `stability`, `gain-map`, `controllers` (each force controller under disturbances) or
    /// `jitter` (the real path against the virtual devices under injected timing jitter, in real
    /// time: about 14 s a run) or `placement` (FBG sensor layouts along the finger; prints the
    /// layout its numbers recommend), `settle` (grasp until settled against fixed grasps: cycle
    /// time and held runs; prints the settled grasp its numbers recommend) or `detector` (settings
    /// chosen by a detected class: each object with each class's settings, and held runs against
    /// the detector's accuracy; prints the pairs as a table) or `finger` (growth length and pad
    /// height against hold margin, contact area, peak force and cycle time; prints the size its
    /// numbers recommend) or `hold` (a long grasp's grip and twine motor over time: the runs given
    /// with `--run`, or the shortened hour run with the hold off and on) or `produce` (the
    /// produce items between plates against Hertz, and each one's window of setpoints that holds
    /// or harvests it without bruising it; prints the windows).
    #[arg(value_parser = ["convergence", "speed-accuracy", "stability", "gain-map", "controllers", "jitter", "placement", "settle", "detector", "finger", "hold", "produce"])]
    study: String,
    /// Scenario to study [default: convergence, gain-map, controllers, placement and settle the three objects; speed-accuracy the crimper (its fine reference drops it too, so
    /// drop times compare; a produce item's study varies its flex's grid and degrees of freedom), stability the hammer (the heaviest load)].
    #[arg(long)]
    scenario: Vec<PathBuf>,
    /// Output folder [default: out/<study>].
    #[arg(long)]
    out: Option<PathBuf>,
    /// A small grid, for a quick look.
    #[arg(long)]
    quick: bool,
    /// Worker threads; 0: one per core, at most 1024. Speeds are each run's own CPU time, so runs
    /// side by side do not slow each other's figures (beyond shared caches).
    #[arg(long, default_value_t = 0, value_parser = super::sweep::threads_or_all)]
    threads: usize,
    /// Convergence, controllers, jitter, placement, settle, detector and finger: the seeds of every case [default: convergence 1,2,3; placement 1-10, with --quick 1;
    /// controllers 1-10, with --quick 1,2; jitter 1,2, with --quick 1; settle and detector 1-10, with --quick 1 (detector 1,2); finger 1,2, with --quick 1].
    #[arg(long, value_delimiter = ',')]
    seeds: Vec<u64>,
    /// Convergence: the physics backend (`mujoco` or `rapier`) [default: the scenario's].
    #[arg(long)]
    backend: Option<Backend>,
    /// Convergence: halve the timestep down to this one at least \[s\], for a finer reference pair
    /// [default: 0.000625, the "down to at least 0.625 ms"; at most that, at least 1e-5].
    #[arg(long, value_name = "SECONDS")]
    finest_step: Option<f64>,
    /// Convergence, speed-accuracy and gain-map: override a scenario value in every run: `--set
    /// key.path=value` (repeatable). Speed-accuracy refuses the keys its grid sets itself; a set
    /// step or finger moves the default it rings.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<tendril_config::Override>,
    /// Gain map: the Kp values \[(°/s)/N\] [default: 2,5,10,20,50,100,200; with --quick 5,20].
    #[arg(long, value_delimiter = ',', value_name = "LIST")]
    kp: Vec<f64>,
    /// Detector: the per-object table the detected class chooses settings from [default:
    /// scenarios/object-table.toml].
    #[arg(long, value_name = "FILE")]
    table: Option<PathBuf>,
    /// Finger: the growth lengths \[m\] [default: 0.105,0.1225,0.14,0.1575,0.175; with --quick
    /// 0.14,0.175]; each must lie within the mechanism's travel (`task.growth_m`, 0 to 0.3 m).
    #[arg(long, value_delimiter = ',', value_name = "LIST")]
    growth: Vec<f64>,
    /// Finger: the pad heights on the sleeve \[m\] (`finger.pad_protrusion_m`, 0.0005 to 0.0055 m)
    /// [default: 0.0015,0.0025,0.0035,0.0045,0.0055; with --quick 0.0055].
    #[arg(long, value_delimiter = ',', value_name = "LIST")]
    pad_height: Vec<f64>,
    /// Hold: run folders to draw (each with its trace.csv), as NAME=DIR or DIR [default: run the
    /// shortened hour with the hold off and on].
    #[arg(long = "run", value_name = "DIR")]
    runs: Vec<String>,
    /// Gain map: the Ki values \[(°/s)/(N·s)\] [default: 0,0.05,0.5,5,50; with --quick 0.05].
    #[arg(long, value_delimiter = ',', value_name = "LIST")]
    ki: Vec<f64>,
    /// Gain map: run every STRIDE-th Kp and Ki first, then only the cells whose runs disagree,
    /// down to every point; the rest is filled in from the cells (the CSV's `ran` says which).
    /// 1 runs every point.
    #[arg(long, default_value_t = crate::sweep::refine::DEFAULT_STRIDE, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..=1024))]
    stride: usize,
    /// Gain map: also refine where a summary field crosses a value, `FIELD=VALUE` (e.g.
    /// `max_fluctuation_pct=10`); the CSV's `beyond_contour` says which side each point is on.
    #[arg(long, value_name = "FIELD=VALUE")]
    contour: Option<crate::sweep::contour::Contour>,
}

/// The three objects' scenarios, or the ones given.
fn objects_or(given: &[PathBuf]) -> Vec<PathBuf> {
    if given.is_empty() {
        ["crimper", "shampoo", "hammer"].map(|o| PathBuf::from(format!("scenarios/{o}.toml"))).to_vec()
    } else {
        given.to_vec()
    }
}

/// The studies that apply `--set` to every run.
const SET_STUDIES: [&str; 3] = ["convergence", "speed-accuracy", "gain-map"];

pub fn run(a: ChartArgs) -> anyhow::Result<ExitCode> {
    let out = a.out.clone().unwrap_or_else(|| PathBuf::from("out").join(&a.study));
    let first = |default: &str| a.scenario.first().cloned().unwrap_or_else(|| PathBuf::from(default));
    // Every other study sets its own keys or runs the scenarios as given: a --set would do nothing.
    if !a.set.is_empty() && !SET_STUDIES.contains(&a.study.as_str()) {
        anyhow::bail!("--set applies to `chart {}` only, not to `chart {}`", SET_STUDIES.join("`, `"), a.study);
    }
    let files = match a.study.as_str() {
        "convergence" => {
            let (files, converged) = convergence(&a, &out)?;
            for f in files {
                emit(&format!("{}\n", f.display()));
            }
            // Like `reproduce`: the exit status says whether every criterion holds.
            return Ok(if converged { ExitCode::SUCCESS } else { ExitCode::FAILURE });
        }
        "speed-accuracy" => {
            use study::speed_accuracy::{Grid, ProduceGrid, run, run_produce};
            let scenario = first("scenarios/crimper.toml");
            // A produce item's study varies its flex instead of the integrator and the cone.
            let loaded: tendril_run::scenario::PickPlaceScenario = tendril_config::load(&scenario, &a.set)?;
            match study::convergence::FlexSetting::of(&loaded)? {
                Some(flex) => {
                    let grid = if a.quick { ProduceGrid::quick(flex) } else { ProduceGrid::full(flex) };
                    run_produce(&scenario, &grid, &a.set, &out, a.threads)?
                }
                None => run(&scenario, &if a.quick { Grid::quick() } else { Grid::full() }, &a.set, &out, a.threads)?,
            }
        }
        "stability" => {
            let steps: &[f64] = if a.quick { &[0.005, 0.04] } else { &study::stability::TIMESTEPS_S };
            study::stability::run(&first("scenarios/hammer.toml"), steps, &out, a.threads)?
        }
        "gain-map" => {
            let scenarios = objects_or(&a.scenario);
            let (kp, ki): (&[f64], &[f64]) =
                if a.quick { (&[5.0, 20.0], &[0.05]) } else { (&study::gain_map::KP, &study::gain_map::KI) };
            let kp = if a.kp.is_empty() { kp } else { &a.kp };
            let ki = if a.ki.is_empty() { ki } else { &a.ki };
            let refinement = study::gain_map::Refinement { stride: a.stride, contour: a.contour.clone() };
            study::gain_map::run(&scenarios, kp, ki, &a.set, &refinement, &out, a.threads)?
        }
        "controllers" => controllers(&a, &out)?,
        "placement" => {
            let plan = study::placement::Plan::new(objects_or(&a.scenario), a.quick, &a.seeds);
            let outcome = study::placement::run(&plan, &out, a.threads)?;
            emit(&format!("{}\n", outcome.recommendation));
            outcome.files
        }
        "settle" => {
            let seeds =
                if a.seeds.is_empty() { if a.quick { vec![1] } else { (1..=10).collect() } } else { a.seeds.clone() };
            let grasps = study::settle::grasps(a.quick);
            let outcome = study::settle::run(&objects_or(&a.scenario), &grasps, &seeds, &out, a.threads)?;
            emit(&format!("{}\n", outcome.recommendation));
            outcome.files
        }
        "detector" => {
            let table = a.table.clone().unwrap_or_else(|| PathBuf::from(study::detector::DEFAULT_TABLE));
            let table =
                std::fs::canonicalize(&table).map_err(|e| anyhow::anyhow!("--table {}: {e}", table.display()))?;
            let plan = study::detector::Plan::new(objects_or(&a.scenario), table, a.quick, &a.seeds);
            let outcome = study::detector::run(&plan, &out, a.threads)?;
            emit(&study::detector::pairs_markdown(&outcome.pairs));
            outcome.files
        }
        "finger" => {
            let plan = study::finger::Plan::new(objects_or(&a.scenario), a.quick, &a.growth, &a.pad_height, &a.seeds);
            let outcome = study::finger::run(&plan, &out, a.threads)?;
            emit(&format!("{}\n", outcome.recommendation));
            outcome.files
        }
        "hold" => {
            if a.runs.is_empty() {
                let (files, text) = study::hold::run_fast_creep(&first("scenarios/short-lift.toml"), &out)?;
                emit(&text);
                files
            } else {
                let runs: Vec<(String, PathBuf)> = a
                    .runs
                    .iter()
                    .map(|r| match r.rsplit_once('=') {
                        Some((name, dir)) => (name.to_string(), PathBuf::from(dir)),
                        None => (r.clone(), PathBuf::from(r)),
                    })
                    .collect();
                let scenario: tendril_run::scenario::PickPlaceScenario =
                    tendril_config::load(&first("scenarios/short-lift.toml"), &[])?;
                study::hold::draw(&runs, scenario.gripper.twine_max_deg.to_radians(), &out, "hold")?
            }
        }
        "produce" => {
            let plan = study::produce::Plan::new(&a.scenario, a.quick, &a.seeds)?;
            let outcome = study::produce::run(&plan, &out, a.threads)?;
            for w in &outcome.windows {
                let why = if w.reason.is_empty() { String::new() } else { format!(": {}", w.reason) };
                emit(&format!("{} ({}): window {}{why}\n", w.item, w.task, w.text()));
            }
            outcome.files
        }
        "jitter" => {
            let seeds = if a.seeds.is_empty() { if a.quick { vec![1] } else { vec![1, 2] } } else { a.seeds.clone() };
            study::jitter::run(&first("scenarios/short-lift.toml"), &study::jitter::cases(a.quick), &seeds, &out)?
        }
        other => anyhow::bail!("unknown study `{other}`"),
    };
    for f in files {
        emit(&format!("{}\n", f.display()));
    }
    Ok(ExitCode::SUCCESS)
}

/// `tendril chart convergence`: every case (object × feedback × seed) over the refinements, the
/// criteria judged and printed. Returns the files written and whether every criterion holds.
fn convergence(a: &ChartArgs, out: &std::path::Path) -> anyhow::Result<(Vec<PathBuf>, bool)> {
    use study::convergence::{CRITERIA, Case, FINEST_TIMESTEP_S, Plan, run};
    let mut extra = a.set.clone();
    extra.extend(a.backend.map(|b| b.as_override()));
    // The refinements start from the first scenario's own timestep and links (after --set).
    let scenarios = objects_or(&a.scenario);
    let base: tendril_run::scenario::PickPlaceScenario = tendril_config::load(&scenarios[0], &extra)?;
    let finest = a.finest_step.unwrap_or(FINEST_TIMESTEP_S);
    // 1e-5 s: the scenario's own lower bound on `physics.timestep_s`.
    if !(1e-5..=FINEST_TIMESTEP_S).contains(&finest) {
        anyhow::bail!(
            "--finest-step: must be between 0.00001 and {FINEST_TIMESTEP_S} s (the issue's coarsest reference), got {finest}"
        );
    }
    if a.quick && a.finest_step.is_some() {
        anyhow::bail!("--finest-step: the --quick plan has no finest setting (default, step/2 and links x2 only)");
    }
    // A produce item's study refines its flex as well (with --quick, the step only).
    let plan = Plan::for_scenario(&base, a.quick, finest)?;
    let seeds = if a.seeds.is_empty() { vec![1, 2, 3] } else { a.seeds.clone() };
    let cases: Vec<Case> = scenarios
        .into_iter()
        .flat_map(|scenario| {
            let seeds = seeds.clone();
            [true, false].into_iter().flat_map(move |feedback| {
                let scenario = scenario.clone();
                seeds.clone().into_iter().map(move |seed| Case { scenario: scenario.clone(), feedback, seed })
            })
        })
        .collect();
    let threads = if a.threads == 0 { std::thread::available_parallelism().map_or(1, |n| n.get()) } else { a.threads };
    let (result, files) = run(&cases, &plan, &extra, threads, out)?;
    let failures = result.failures();
    emit(&format!(
        "convergence: {} of {} comparisons meet the criteria (drop {} s, rise {} s, fluctuation {} pp, force {} N)\n",
        result.verdicts.len() - failures.len(),
        result.verdicts.len(),
        CRITERIA.drop_time_s,
        CRITERIA.rise_time_s,
        CRITERIA.fluctuation_pp,
        CRITERIA.force_rmse_n
    ));
    for (case, pair, failed) in &failures {
        emit(&format!("  {case}, {pair}: {}\n", failed.join(", ")));
    }
    Ok((files, failures.is_empty()))
}

/// `tendril chart controllers`: each controller × object × disturbance set × seed; prints the
/// summary as markdown and whether a controller meets the goal. Returns the files written.
fn controllers(a: &ChartArgs, out: &std::path::Path) -> anyhow::Result<Vec<PathBuf>> {
    use study::controllers::{GOAL_SET, Plan, run};
    use tendril_plot::controllers_summary::{GOAL_FLUCTUATION_PCT, controllers_meeting_goal, markdown};
    if let Some(seed) = a.seeds.iter().enumerate().find(|(i, s)| a.seeds[..*i].contains(s)).map(|(_, s)| s) {
        anyhow::bail!("--seeds: seed {seed} is given twice (each seed is one run per case)");
    }
    if a.backend.is_some() {
        anyhow::bail!("--backend applies to `chart convergence` only");
    }
    let plan = Plan::new(objects_or(&a.scenario), a.quick, &a.seeds);
    let started = std::time::Instant::now();
    let result = run(&plan, out, a.threads)?;
    emit(&markdown(&result.summary));
    let objects = tendril_plot::grid::first_seen(result.summary.iter().map(|r| r.object.as_str())).len();
    if plan.sets.iter().any(|s| s.name == GOAL_SET) {
        let meeting = controllers_meeting_goal(&result.summary, GOAL_SET);
        emit(&format!(
            "\ngoal (every object held in every seed, largest fluctuation while moving <= {GOAL_FLUCTUATION_PCT} %, \
             under `{GOAL_SET}`, {objects} object(s), {} seed(s)): {}\n",
            plan.seeds.len(),
            if meeting.is_empty() {
                "met by no controller".to_string()
            } else {
                format!("met by {}", meeting.join(", "))
            }
        ));
    }
    emit(&format!("{} runs in {:.0} s wall\n", result.runs.len(), started.elapsed().as_secs_f64()));
    Ok(result.files)
}
