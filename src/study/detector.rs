//! Settings chosen by the object (`tendril chart detector`): what a simulated detector's errors cost
//! (`[detector]`, `tendril_run::detector`). Two parts, on the twin, each case over seeds:
//!
//! - **pairs**: every object run with every class's settings from the table (the detector always
//!   reports that class; a confusion row of one) and with none (a miss: the table's fallback, or
//!   the scenario's own settings): held runs, fluctuation while moving, peak force and cycle time
//!   per (true, assumed) pair, and for a produce item the runs that bruised it and its peak
//!   contact pressure: what a wrong class costs.
//! - **accuracy**: every object with a detector of each accuracy (the rest spread evenly over the
//!   other classes) and a fixed miss rate: held runs and fluctuation against accuracy.
//!
//! The objects are scenario files and the classes the table's rows: a further object (a produce
//! item) is one more scenario and one more `[classes.NAME]` row, no code changed.

use super::{Damage, cell, run_all, set, write_csv};
use std::path::{Path, PathBuf};
use tendril_config::Override;
use tendril_plot::panels::{Mark, Panel, Panels, Series};
use tendril_run::object_table::ObjectTable;

/// The table the study uses by default: the paper's objects' tuned settings.
pub const DEFAULT_TABLE: &str = "scenarios/object-table.toml";

/// What the study runs.
#[derive(Debug, Clone)]
pub struct Plan {
    /// One scenario per object.
    pub scenarios: Vec<PathBuf>,
    /// The per-object table (absolute).
    pub table: PathBuf,
    /// The accuracies of the second part.
    pub accuracies: Vec<f64>,
    /// Whether the second part also runs a detector at chance (one over the table's classes).
    pub chance: bool,
    /// Its miss rate.
    pub miss_rate: f64,
    /// The seeds of every case.
    pub seeds: Vec<u64>,
}

impl Plan {
    /// The plan: quick (accuracies 1 and 0.5, seeds 1-2) or full (1, 0.95, 0.9, 0.8, 0.6 and
    /// chance among the table's classes, seeds 1-10), `seeds` replacing the default when given; a
    /// miss rate of 5 %.
    pub fn new(scenarios: Vec<PathBuf>, table: PathBuf, quick: bool, seeds: &[u64]) -> Plan {
        let default_seeds: Vec<u64> = if quick { vec![1, 2] } else { (1..=10).collect() };
        Plan {
            scenarios,
            table,
            accuracies: if quick { vec![1.0, 0.5] } else { vec![1.0, 0.95, 0.9, 0.8, 0.6] },
            chance: !quick,
            miss_rate: 0.05,
            seeds: if seeds.is_empty() { default_seeds } else { seeds.to_vec() },
        }
    }
}

/// One (object, assumed class) over its seeds.
#[derive(Debug, Clone, PartialEq)]
pub struct PairRow {
    /// The object.
    pub object: String,
    /// The class whose settings it ran with (`miss`: none reported).
    pub assumed: String,
    /// Runs.
    pub runs: usize,
    /// Runs that held.
    pub held: usize,
    /// Mean of the held runs' largest fluctuation while moving [%].
    pub fluctuation_mean_pct: Option<f64>,
    /// Mean of the largest force estimate while holding \[N\].
    pub peak_force_mean_n: Option<f64>,
    /// Mean cycle time \[s\].
    pub cycle_mean_s: Option<f64>,
    /// Runs that bruised their produce item (0 for a rigid object).
    pub bruised: usize,
    /// Mean of the runs' peak contact pressure on a produce item \[kPa\].
    pub peak_pressure_mean_kpa: Option<f64>,
}

/// One (object, accuracy) over its seeds.
#[derive(Debug, Clone, PartialEq)]
pub struct AccuracyRow {
    /// The object.
    pub object: String,
    /// The detector's accuracy.
    pub accuracy: f64,
    /// Runs.
    pub runs: usize,
    /// Runs whose detector reported the true class.
    pub correct: usize,
    /// Runs that held.
    pub held: usize,
    /// Mean of the held runs' largest fluctuation while moving [%].
    pub fluctuation_mean_pct: Option<f64>,
    /// Runs that bruised their produce item (0 for a rigid object).
    pub bruised: usize,
    /// Whether the object is a produce item (its runs report damage).
    pub produce: bool,
}

/// What the study wrote and found.
pub struct Outcome {
    /// The files written.
    pub files: Vec<PathBuf>,
    /// The pairs' summary.
    pub pairs: Vec<PairRow>,
    /// The accuracy part's summary.
    pub accuracy: Vec<AccuracyRow>,
}

/// One run's figures.
struct Run {
    object: String,
    case: String,
    seed: u64,
    outcome: String,
    reported: Option<String>,
    fluctuation_pct: Option<f64>,
    peak_force_n: Option<f64>,
    cycle_s: f64,
    damage: Damage,
    error: Option<String>,
}

fn mean(values: impl Iterator<Item = f64>) -> Option<f64> {
    let v: Vec<f64> = values.collect();
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

/// Runs `cases` (a name and its overrides) × seeds on `scenario`.
fn run_cases(
    scenario: &Path,
    cases: &[(String, Vec<Override>)],
    seeds: &[u64],
    threads: usize,
) -> anyhow::Result<Vec<Run>> {
    let keyed: Vec<(String, u64)> =
        cases.iter().flat_map(|(n, _)| seeds.iter().map(move |s| (n.clone(), *s))).collect();
    let sets = cases
        .iter()
        .flat_map(|(_, o)| {
            seeds.iter().map(move |s| {
                let mut o = o.clone();
                o.push(set("seed", s));
                o
            })
        })
        .collect();
    let stem = scenario.file_stem().map_or(String::new(), |s| s.to_string_lossy().to_string());
    Ok(run_all(scenario, sets, threads)?
        .into_iter()
        .zip(keyed)
        .map(|(r, (case, seed))| {
            let s = r.summary;
            Run {
                object: if s.run.object.is_empty() { stem.clone() } else { s.run.object.clone() },
                case,
                seed,
                outcome: s.outcome.clone(),
                reported: s.detection.as_ref().and_then(|d| d.reported.clone()),
                fluctuation_pct: s.metrics.max_fluctuation_pct,
                peak_force_n: s.metrics.peak_force_n,
                cycle_s: s.sim_time_s,
                damage: Damage::of(&s),
                error: s.error,
            }
        })
        .collect())
}

/// Runs the plan on `threads` workers; writes `detector_runs.csv`, `detector_pairs.csv`,
/// `detector_accuracy.csv` and `detector.png/.svg` into `out`.
pub fn run(plan: &Plan, out: &Path, threads: usize) -> anyhow::Result<Outcome> {
    let table = ObjectTable::read(&plan.table).map_err(|e| anyhow::anyhow!("--table: {e}"))?;
    let classes = table.class_names();
    let base = |accuracy: f64, miss_rate: f64| {
        vec![
            set("detector.table", format!("{:?}", plan.table.display().to_string())),
            set("detector.accuracy", accuracy),
            set("detector.miss_rate", miss_rate),
        ]
    };
    let mut pair_runs = Vec::new();
    let mut accuracy_runs = Vec::new();
    for scenario in &plan.scenarios {
        let object: tendril_run::scenario::PickPlaceScenario = tendril_config::load(scenario, &[])?;
        let truth = object.object.label();
        let mut pairs: Vec<(String, Vec<Override>)> = classes
            .iter()
            .map(|assumed| {
                let mut o = base(1.0, 0.0);
                o.push(set(&format!("detector.confusion.{truth}"), format!("{{ {assumed} = 1.0 }}")));
                (assumed.clone(), o)
            })
            .collect();
        pairs.push(("miss".into(), base(1.0, 1.0)));
        pair_runs.extend(run_cases(scenario, &pairs, &plan.seeds, threads)?);
        let chance = plan.chance.then(|| 1.0 / classes.len() as f64);
        let levels: Vec<(String, Vec<Override>)> =
            plan.accuracies.iter().chain(chance.iter()).map(|&a| (format!("{a}"), base(a, plan.miss_rate))).collect();
        accuracy_runs.extend(run_cases(scenario, &levels, &plan.seeds, threads)?);
    }
    std::fs::create_dir_all(out).map_err(|e| anyhow::anyhow!("{}: {e}", out.display()))?;
    let runs_csv = out.join("detector_runs.csv");
    let run_cells = |part: &str, r: &Run| {
        let mut cells = vec![
            part.to_string(),
            r.object.clone(),
            r.case.clone(),
            r.seed.to_string(),
            r.outcome.clone(),
            r.reported.clone().unwrap_or_else(|| "miss".into()),
            cell(r.fluctuation_pct),
            cell(r.peak_force_n),
            format!("{}", r.cycle_s),
        ];
        cells.extend(r.damage.cells());
        cells.push(r.error.clone().unwrap_or_default());
        cells
    };
    let rows: Vec<Vec<String>> = pair_runs
        .iter()
        .map(|r| run_cells("pairs", r))
        .chain(accuracy_runs.iter().map(|r| run_cells("accuracy", r)))
        .collect();
    write_csv(
        &runs_csv,
        &[
            "part",
            "object",
            "case",
            "seed",
            "outcome",
            "reported",
            "fluctuation_pct",
            "peak_force_n",
            "cycle_s",
            Damage::HEADER[0],
            Damage::HEADER[1],
            "error",
        ],
        &rows,
    )?;
    let pairs = pair_summary(&pair_runs);
    let pairs_csv = out.join("detector_pairs.csv");
    write_csv(
        &pairs_csv,
        &[
            "object",
            "assumed",
            "runs",
            "held",
            "fluctuation_mean_pct",
            "peak_force_mean_n",
            "cycle_mean_s",
            "bruised",
            "peak_pressure_mean_kpa",
        ],
        &pairs
            .iter()
            .map(|p| {
                vec![
                    p.object.clone(),
                    p.assumed.clone(),
                    p.runs.to_string(),
                    p.held.to_string(),
                    cell(p.fluctuation_mean_pct),
                    cell(p.peak_force_mean_n),
                    cell(p.cycle_mean_s),
                    p.bruised.to_string(),
                    cell(p.peak_pressure_mean_kpa),
                ]
            })
            .collect::<Vec<_>>(),
    )?;
    let accuracy = accuracy_summary(&accuracy_runs);
    let accuracy_csv = out.join("detector_accuracy.csv");
    write_csv(
        &accuracy_csv,
        &["object", "accuracy", "runs", "correct", "held", "fluctuation_mean_pct", "bruised"],
        &accuracy
            .iter()
            .map(|a| {
                vec![
                    a.object.clone(),
                    format!("{}", a.accuracy),
                    a.runs.to_string(),
                    a.correct.to_string(),
                    a.held.to_string(),
                    cell(a.fluctuation_mean_pct),
                    a.bruised.to_string(),
                ]
            })
            .collect::<Vec<_>>(),
    )?;
    let mut files = vec![runs_csv, pairs_csv, accuracy_csv];
    files.extend(tendril_plot::panels::render(&chart(&accuracy), out, "detector")?);
    Ok(Outcome { files, pairs, accuracy })
}

fn pair_summary(runs: &[Run]) -> Vec<PairRow> {
    tendril_plot::grid::first_seen(runs.iter().map(|r| (r.object.clone(), r.case.clone())))
        .into_iter()
        .map(|(object, assumed)| {
            let g: Vec<&Run> = runs.iter().filter(|r| r.object == object && r.case == assumed).collect();
            PairRow {
                runs: g.len(),
                held: g.iter().filter(|r| r.outcome == "held").count(),
                fluctuation_mean_pct: mean(g.iter().filter(|r| r.outcome == "held").filter_map(|r| r.fluctuation_pct)),
                peak_force_mean_n: mean(g.iter().filter_map(|r| r.peak_force_n)),
                cycle_mean_s: mean(g.iter().filter(|r| r.outcome != "error").map(|r| r.cycle_s)),
                bruised: g.iter().filter(|r| r.damage.is_bruised()).count(),
                peak_pressure_mean_kpa: mean(g.iter().filter_map(|r| r.damage.peak_pressure_kpa)),
                object,
                assumed,
            }
        })
        .collect()
}

fn accuracy_summary(runs: &[Run]) -> Vec<AccuracyRow> {
    tendril_plot::grid::first_seen(runs.iter().map(|r| (r.object.clone(), r.case.clone())))
        .into_iter()
        .map(|(object, case)| {
            let g: Vec<&Run> = runs.iter().filter(|r| r.object == object && r.case == case).collect();
            AccuracyRow {
                accuracy: case.parse().unwrap_or(f64::NAN),
                runs: g.len(),
                correct: g.iter().filter(|r| r.reported.as_deref() == Some(object.as_str())).count(),
                held: g.iter().filter(|r| r.outcome == "held").count(),
                fluctuation_mean_pct: mean(g.iter().filter(|r| r.outcome == "held").filter_map(|r| r.fluctuation_pct)),
                bruised: g.iter().filter(|r| r.damage.is_bruised()).count(),
                produce: g.iter().any(|r| r.damage.bruised.is_some()),
                object,
            }
        })
        .collect()
}

/// Held runs and fluctuation against the detector's accuracy, a series per object; with produce,
/// the runs that bruised each item too.
fn chart(rows: &[AccuracyRow]) -> Panels {
    let objects = tendril_plot::grid::first_seen(rows.iter().map(|r| r.object.clone()));
    let produce = tendril_plot::grid::first_seen(rows.iter().filter(|r| r.produce).map(|r| r.object.clone()));
    let series_of = |objects: &[String], value: &dyn Fn(&AccuracyRow) -> Option<f64>| {
        objects
            .iter()
            .map(|o| Series {
                name: o.clone(),
                points: rows
                    .iter()
                    .filter(|r| &r.object == o)
                    .map(|r| (100.0 * r.accuracy, value(r).unwrap_or(f64::NAN)))
                    .collect(),
                mark: Mark::LineDots,
            })
            .collect::<Vec<_>>()
    };
    let series = |value: &dyn Fn(&AccuracyRow) -> Option<f64>| series_of(&objects, value);
    let mut panels = vec![
        Panel {
            caption: "held runs".into(),
            x_desc: "detector accuracy [%]".into(),
            y_desc: "held [% of seeds]".into(),
            series: series(&|r| Some(100.0 * r.held as f64 / r.runs.max(1) as f64)),
            y_range: Some((0.0, 105.0)),
        },
        Panel {
            caption: "largest fluctuation while moving, held runs".into(),
            x_desc: "detector accuracy [%]".into(),
            y_desc: "mean over seeds [%]".into(),
            series: series(&|r| r.fluctuation_mean_pct),
            y_range: None,
        },
    ];
    if !produce.is_empty() {
        panels.push(Panel {
            caption: "produce: runs that bruised the item".into(),
            x_desc: "detector accuracy [%]".into(),
            y_desc: "bruised [% of seeds]".into(),
            series: series_of(&produce, &|r| Some(100.0 * r.bruised as f64 / r.runs.max(1) as f64)),
            y_range: Some((0.0, 105.0)),
        });
    }
    Panels {
        title: "Settings chosen by a detected class: held runs and fluctuation against the detector's accuracy".into(),
        columns: panels.len(),
        panels,
    }
}

/// The pairs as a markdown table: rows the true object, columns the assumed class, each cell held
/// runs, mean fluctuation and peak force, and for produce the runs that bruised it.
pub fn pairs_markdown(pairs: &[PairRow]) -> String {
    let objects = tendril_plot::grid::first_seen(pairs.iter().map(|p| p.object.clone()));
    let assumed = tendril_plot::grid::first_seen(pairs.iter().map(|p| p.assumed.clone()));
    let mut text = format!("| object \\ settings of | {} |\n", assumed.join(" | "));
    text += &format!("|---|{}\n", "---|".repeat(assumed.len()));
    for o in &objects {
        let cells: Vec<String> = assumed
            .iter()
            .map(|a| match pairs.iter().find(|p| &p.object == o && &p.assumed == a) {
                Some(p) => format!(
                    "{}/{} held, {} %, peak {} N{}",
                    p.held,
                    p.runs,
                    p.fluctuation_mean_pct.map_or("-".into(), |f| format!("{f:.0}")),
                    p.peak_force_mean_n.map_or("-".into(), |f| format!("{f:.2}")),
                    p.peak_pressure_mean_kpa
                        .map_or(String::new(), |kpa| format!(", {}/{} bruised, {kpa:.0} kPa", p.bruised, p.runs))
                ),
                None => "-".into(),
            })
            .collect();
        text += &format!("| {o} | {} |\n", cells.join(" | "));
    }
    text
}
