//! Grasp until settled (`tendril chart settle`): cycle time against the held fraction per object,
//! the paper's fixed 15 s grasp and shorter fixed grasps against settled grasps over a grid of
//! bands and dwells (`[task.settled_grasp]`), each case over seeds, on the twin. One row per run
//! (`settle.csv`), one per (object, grasp) (`settle_summary.csv`), a chart (`settle.png`), and the
//! settled grasp the numbers recommend: the shortest mean cycle among those that held every object
//! on every seed with no timeout and bruised no produce item.
//!
//! The objects are scenario files: a further object (a produce item) is studied by passing its
//! scenario with `--scenario`, no code changed.

use super::{Damage, cell, run_all, set, write_csv};
use std::path::{Path, PathBuf};
use tendril_config::Override;
use tendril_plot::panels::{Mark, Panel, Panels, Series};

/// How a case's grasp ends.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Grasp {
    /// After a fixed time \[s\] (the paper: 15 s).
    Fixed(f64),
    /// Once the estimate stayed within ±`band_pct` % of the setpoint for `dwell_s`.
    Settled {
        /// Half-width of the band [% of the setpoint].
        band_pct: f64,
        /// Dwell \[s\].
        dwell_s: f64,
    },
}

impl Grasp {
    /// The case's name in the CSVs.
    pub fn label(&self) -> String {
        match self {
            Grasp::Fixed(s) => format!("fixed {s} s"),
            Grasp::Settled { band_pct, dwell_s } => format!("settled ±{band_pct} % for {dwell_s} s"),
        }
    }

    /// Its series in the chart: the fixed grasps, or the settled ones of one band.
    fn series(&self) -> String {
        match self {
            Grasp::Fixed(_) => "fixed time".into(),
            Grasp::Settled { band_pct, .. } => format!("settled, ±{band_pct} %"),
        }
    }

    fn overrides(&self) -> Vec<Override> {
        match *self {
            Grasp::Fixed(s) => vec![set("task.grasp_s", s)],
            Grasp::Settled { band_pct, dwell_s } => vec![
                set("task.settled_grasp.enabled", true),
                set("task.settled_grasp.band_pct", band_pct),
                set("task.settled_grasp.dwell_s", dwell_s),
            ],
        }
    }
}

/// The grasps of the study: quick, the paper's 15 s and the default settled grasp; full, fixed 15, 5 and
/// 3 s and settled grasps in bands of ±5, 10 and 15 % with dwells of 0.5, 1 and 2 s.
pub fn grasps(quick: bool) -> Vec<Grasp> {
    if quick {
        let default = tendril_control::settle::SettleConfig::default();
        return vec![Grasp::Fixed(15.0), Grasp::Settled { band_pct: default.band_pct, dwell_s: default.dwell_s }];
    }
    let mut g: Vec<Grasp> = [15.0, 5.0, 3.0].into_iter().map(Grasp::Fixed).collect();
    for band_pct in [5.0, 10.0, 15.0] {
        for dwell_s in [0.5, 1.0, 2.0] {
            g.push(Grasp::Settled { band_pct, dwell_s });
        }
    }
    g
}

/// One run of the study.
#[derive(Debug, Clone, PartialEq)]
pub struct SettleRun {
    /// The object.
    pub object: String,
    /// The grasp.
    pub grasp: Grasp,
    /// The seed.
    pub seed: u64,
    /// "held", "dropped", "not_grasped" or "error".
    pub outcome: String,
    /// The cycle: cell time from the start to the end of the release \[s\].
    pub cycle_s: f64,
    /// How long the grasp lasted \[s\] (the fixed time, or until settled or timed out).
    pub grasp_s: Option<f64>,
    /// Largest fluctuation while the arm moved [%].
    pub fluctuation_pct: Option<f64>,
    /// A produce item's damage (absent for a rigid object).
    pub damage: Damage,
    /// The error that ended the run.
    pub error: Option<String>,
}

/// One (object, grasp) over its seeds.
#[derive(Debug, Clone, PartialEq)]
pub struct SettleRow {
    /// The object.
    pub object: String,
    /// The grasp.
    pub grasp: Grasp,
    /// Runs.
    pub runs: usize,
    /// Runs that held.
    pub held: usize,
    /// Runs whose grasp timed out (let go, not lifted).
    pub not_grasped: usize,
    /// Mean cycle time \[s\].
    pub cycle_mean_s: f64,
    /// Mean grasp time \[s\].
    pub grasp_mean_s: Option<f64>,
    /// Mean over the held runs of the largest fluctuation while moving [%].
    pub fluctuation_mean_pct: Option<f64>,
    /// Runs that bruised their produce item (0 for a rigid object).
    pub bruised: usize,
    /// Mean of the runs' peak contact pressure on a produce item \[kPa\].
    pub peak_pressure_mean_kpa: Option<f64>,
}

impl SettleRow {
    /// The held fraction [%].
    pub fn held_pct(&self) -> f64 {
        100.0 * self.held as f64 / self.runs.max(1) as f64
    }
}

/// What the study wrote and found.
pub struct Outcome {
    /// The files written.
    pub files: Vec<PathBuf>,
    /// One row per (object, grasp).
    pub summary: Vec<SettleRow>,
    /// The settled grasp recommended, and why.
    pub recommendation: String,
}

/// Runs every grasp × seed on each scenario (one per object) on `threads` workers; writes
/// `settle.csv`, `settle_summary.csv` and `settle.png/.svg` into `out`.
pub fn run(
    scenarios: &[PathBuf],
    grasps: &[Grasp],
    seeds: &[u64],
    out: &Path,
    threads: usize,
) -> anyhow::Result<Outcome> {
    let mut runs = Vec::new();
    for scenario in scenarios {
        let cases: Vec<(Grasp, u64)> = grasps.iter().flat_map(|g| seeds.iter().map(move |s| (*g, *s))).collect();
        let sets = cases
            .iter()
            .map(|(g, seed)| {
                let mut o = g.overrides();
                o.push(set("seed", seed));
                o
            })
            .collect();
        let stem = scenario.file_stem().map_or(String::new(), |s| s.to_string_lossy().to_string());
        for (r, (grasp, seed)) in run_all(scenario, sets, threads)?.into_iter().zip(cases) {
            let s = r.summary;
            let grasp_s = match grasp {
                Grasp::Fixed(t) => (s.outcome != "error").then_some(t),
                Grasp::Settled { .. } => s.grasp_duration_s,
            };
            runs.push(SettleRun {
                object: if s.run.object.is_empty() { stem.clone() } else { s.run.object.clone() },
                grasp,
                seed,
                outcome: s.outcome.clone(),
                cycle_s: s.sim_time_s,
                grasp_s,
                fluctuation_pct: s.metrics.max_fluctuation_pct,
                damage: Damage::of(&s),
                error: s.error,
            });
        }
    }
    std::fs::create_dir_all(out).map_err(|e| anyhow::anyhow!("{}: {e}", out.display()))?;
    let csv = out.join("settle.csv");
    write_csv(
        &csv,
        &[
            "object",
            "grasp",
            "seed",
            "outcome",
            "cycle_s",
            "grasp_s",
            "fluctuation_pct",
            Damage::HEADER[0],
            Damage::HEADER[1],
            "error",
        ],
        &runs
            .iter()
            .map(|r| {
                let mut cells = vec![
                    r.object.clone(),
                    r.grasp.label(),
                    r.seed.to_string(),
                    r.outcome.clone(),
                    format!("{}", r.cycle_s),
                    cell(r.grasp_s),
                    cell(r.fluctuation_pct),
                ];
                cells.extend(r.damage.cells());
                cells.push(r.error.clone().unwrap_or_default());
                cells
            })
            .collect::<Vec<_>>(),
    )?;
    let summary = aggregate(&runs);
    let summary_csv = out.join("settle_summary.csv");
    write_csv(
        &summary_csv,
        &[
            "object",
            "grasp",
            "runs",
            "held",
            "not_grasped",
            "held_pct",
            "cycle_mean_s",
            "grasp_mean_s",
            "fluctuation_mean_pct",
            "bruised",
            "peak_pressure_mean_kpa",
        ],
        &summary
            .iter()
            .map(|r| {
                vec![
                    r.object.clone(),
                    r.grasp.label(),
                    r.runs.to_string(),
                    r.held.to_string(),
                    r.not_grasped.to_string(),
                    format!("{}", r.held_pct()),
                    format!("{}", r.cycle_mean_s),
                    cell(r.grasp_mean_s),
                    cell(r.fluctuation_mean_pct),
                    r.bruised.to_string(),
                    cell(r.peak_pressure_mean_kpa),
                ]
            })
            .collect::<Vec<_>>(),
    )?;
    let mut files = vec![csv, summary_csv];
    files.extend(tendril_plot::panels::render(&chart(&summary), out, "settle")?);
    let recommendation = recommend(&summary);
    Ok(Outcome { files, summary, recommendation })
}

fn mean(values: impl Iterator<Item = f64>) -> Option<f64> {
    let v: Vec<f64> = values.collect();
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

/// The summary rows, in the order the runs came.
fn aggregate(runs: &[SettleRun]) -> Vec<SettleRow> {
    let keys = tendril_plot::grid::first_seen(runs.iter().map(|r| (r.object.clone(), r.grasp.label())));
    keys.into_iter()
        .map(|(object, label)| {
            let group: Vec<&SettleRun> =
                runs.iter().filter(|r| r.object == object && r.grasp.label() == label).collect();
            SettleRow {
                grasp: group[0].grasp,
                runs: group.len(),
                held: group.iter().filter(|r| r.outcome == "held").count(),
                not_grasped: group.iter().filter(|r| r.outcome == "not_grasped").count(),
                cycle_mean_s: mean(group.iter().map(|r| r.cycle_s)).unwrap_or(f64::NAN),
                grasp_mean_s: mean(group.iter().filter_map(|r| r.grasp_s)),
                fluctuation_mean_pct: mean(
                    group.iter().filter(|r| r.outcome == "held").filter_map(|r| r.fluctuation_pct),
                ),
                bruised: group.iter().filter(|r| r.damage.is_bruised()).count(),
                peak_pressure_mean_kpa: mean(group.iter().filter_map(|r| r.damage.peak_pressure_kpa)),
                object,
            }
        })
        .collect()
}

/// One panel per object: held fraction against mean cycle time, a series per kind of grasp.
fn chart(summary: &[SettleRow]) -> Panels {
    let objects = tendril_plot::grid::first_seen(summary.iter().map(|r| r.object.clone()));
    let panels = objects
        .iter()
        .map(|object| {
            let rows: Vec<&SettleRow> = summary.iter().filter(|r| &r.object == object).collect();
            let names = tendril_plot::grid::first_seen(rows.iter().map(|r| r.grasp.series()));
            let series = names
                .into_iter()
                .map(|name| {
                    let mut points: Vec<(f64, f64)> = rows
                        .iter()
                        .filter(|r| r.grasp.series() == name)
                        .map(|r| (r.cycle_mean_s, r.held_pct()))
                        .collect();
                    points.sort_by(|a, b| a.0.total_cmp(&b.0));
                    Series { name, points, mark: Mark::LineDots }
                })
                .collect();
            Panel {
                caption: format!("{object}: held runs against cycle time"),
                x_desc: "mean cycle time [s]".into(),
                y_desc: "held [% of seeds]".into(),
                series,
                y_range: Some((0.0, 105.0)),
            }
        })
        .collect();
    Panels { title: "Grasp until settled: cycle time and held runs per object".into(), panels, columns: 3 }
}

/// The settled grasp with the shortest mean cycle (over the objects) among those that held every
/// run of every object and bruised none, said with its numbers against the paper's fixed 15 s.
pub fn recommend(summary: &[SettleRow]) -> String {
    let labels = tendril_plot::grid::first_seen(summary.iter().map(|r| r.grasp.label()));
    let of = |label: &str| summary.iter().filter(|r| r.grasp.label() == label).collect::<Vec<_>>();
    let cycle = |rows: &[&SettleRow]| mean(rows.iter().map(|r| r.cycle_mean_s)).unwrap_or(f64::NAN);
    let best = labels
        .iter()
        .filter(|l| {
            let rows = of(l);
            matches!(rows[0].grasp, Grasp::Settled { .. }) && rows.iter().all(|r| r.held == r.runs && r.bruised == 0)
        })
        .min_by(|a, b| cycle(&of(a)).total_cmp(&cycle(&of(b))));
    let Some(best) = best else {
        return "recommended: none of the settled grasps held every run of every object without bruising it".into();
    };
    let rows = of(best);
    let mut text = format!("recommended: {best}: held every run, mean cycle {:.1} s", cycle(&rows));
    let paper = Grasp::Fixed(15.0).label();
    let paper_rows = of(&paper);
    if !paper_rows.is_empty() {
        let held: usize = paper_rows.iter().map(|r| r.held).sum();
        let runs: usize = paper_rows.iter().map(|r| r.runs).sum();
        text += &format!("; the paper's {paper}: held {held} of {runs}, mean cycle {:.1} s", cycle(&paper_rows));
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(object: &str, grasp: Grasp, held: usize, bruised: usize, cycle_mean_s: f64) -> SettleRow {
        SettleRow {
            object: object.into(),
            grasp,
            runs: 5,
            held,
            not_grasped: 0,
            cycle_mean_s,
            grasp_mean_s: None,
            fluctuation_mean_pct: None,
            bruised,
            peak_pressure_mean_kpa: None,
        }
    }

    #[test]
    fn a_settled_grasp_that_bruises_a_produce_item_is_not_recommended() {
        let quick = Grasp::Settled { band_pct: 15.0, dwell_s: 0.5 };
        let slow = Grasp::Settled { band_pct: 15.0, dwell_s: 2.0 };
        let mut summary = vec![
            row("crimper", quick, 5, 0, 30.0),
            row("cherry_tomato", quick, 5, 0, 30.0),
            row("crimper", slow, 5, 0, 32.0),
            row("cherry_tomato", slow, 5, 0, 32.0),
        ];
        assert!(recommend(&summary).starts_with("recommended: settled ±15 % for 0.5 s"), "{}", recommend(&summary));
        // Held every run, but bruised one: the slower grasp is the one that keeps the fruit whole.
        summary[1].bruised = 1;
        assert!(recommend(&summary).starts_with("recommended: settled ±15 % for 2 s"), "{}", recommend(&summary));
        summary[3].bruised = 2;
        assert!(recommend(&summary).contains("none of the settled grasps"), "{}", recommend(&summary));
    }
}
