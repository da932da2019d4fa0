//! `tendril chart`: studies over many runs, each written as CSV and charted.

use super::emit;
use crate::cell::physics::{Backend, FingerConfig, PhysicsConfig};
use crate::study;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `tendril chart`.
#[derive(Debug, clap::Args)]
pub struct ChartArgs {
    /// Which study: `convergence` (exits 1 when a convergence criterion breaks), `speed-accuracy`,
    /// `stability` or `gain-map`.
    #[arg(value_parser = ["convergence", "speed-accuracy", "stability", "gain-map"])]
    study: String,
    /// Scenario to study [default: convergence and gain-map the three objects; speed-accuracy the crimper (its fine reference drops it too, so
    /// drop times compare), stability the hammer (the heaviest load)].
    #[arg(long)]
    scenario: Vec<PathBuf>,
    /// Output folder [default: out/<study>].
    #[arg(long)]
    out: Option<PathBuf>,
    /// A small grid, for a quick look.
    #[arg(long)]
    quick: bool,
    /// Worker threads for the studies that do not time runs (convergence, stability, gain-map);
    /// 0: one per core, at most 1024.
    #[arg(long, default_value_t = 0, value_parser = super::sweep::threads_or_all)]
    threads: usize,
    /// Convergence: the seeds of every case.
    #[arg(long, value_delimiter = ',', default_values_t = [1u64, 2, 3])]
    seeds: Vec<u64>,
    /// Convergence: the physics backend (`mujoco` or `rapier`) [default: the scenario's].
    #[arg(long)]
    backend: Option<Backend>,
    /// Convergence: override a scenario value in every run: `--set key.path=value` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<crate::scenario::Override>,
}

/// The three objects' scenarios, or the ones given.
fn objects_or(given: &[PathBuf]) -> Vec<PathBuf> {
    if given.is_empty() {
        ["crimper", "shampoo", "hammer"].map(|o| PathBuf::from(format!("scenarios/{o}.toml"))).to_vec()
    } else {
        given.to_vec()
    }
}

pub fn run(a: ChartArgs) -> anyhow::Result<ExitCode> {
    let out = a.out.clone().unwrap_or_else(|| PathBuf::from("out").join(&a.study));
    let first = |default: &str| a.scenario.first().cloned().unwrap_or_else(|| PathBuf::from(default));
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
            let grid = if a.quick { study::speed_accuracy::Grid::quick() } else { study::speed_accuracy::Grid::full() };
            let p = PhysicsConfig::default();
            let defaults = (p.timestep_s, "implicitfast", "elliptic", FingerConfig::default().segments);
            study::speed_accuracy::run(&first("scenarios/crimper.toml"), &grid, defaults, &out)?
        }
        "stability" => {
            let steps: &[f64] = if a.quick { &[0.005, 0.04] } else { &study::stability::TIMESTEPS_S };
            study::stability::run(&first("scenarios/hammer.toml"), steps, &out, a.threads)?
        }
        _ => {
            let scenarios = objects_or(&a.scenario);
            let (kp, ki): (&[f64], &[f64]) =
                if a.quick { (&[5.0, 20.0], &[0.05]) } else { (&study::gain_map::KP, &study::gain_map::KI) };
            study::gain_map::run(&scenarios, kp, ki, &out, a.threads)?
        }
    };
    for f in files {
        emit(&format!("{}\n", f.display()));
    }
    Ok(ExitCode::SUCCESS)
}

/// `tendril chart convergence`: every case (object × feedback × seed) over the refinements, the
/// criteria judged and printed. Returns the files written and whether every criterion holds.
fn convergence(a: &ChartArgs, out: &std::path::Path) -> anyhow::Result<(Vec<PathBuf>, bool)> {
    use study::convergence::{CRITERIA, Case, Plan, run};
    let mut extra = a.set.clone();
    extra.extend(a.backend.map(crate::scenario::Override::backend));
    // The refinements start from the first scenario's own timestep and links (after --set).
    let scenarios = objects_or(&a.scenario);
    let base: crate::run::scenario::PickPlaceScenario = crate::scenario::load(&scenarios[0], &extra)?;
    let (dt, links) = (base.physics.timestep_s, base.finger.segments);
    let plan = if a.quick { Plan::quick(dt, links) } else { Plan::full(dt, links) };
    let cases: Vec<Case> = scenarios
        .into_iter()
        .flat_map(|scenario| {
            let seeds = a.seeds.clone();
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
