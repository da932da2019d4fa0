//! Where to put the FBG pads: sensor layouts (1 to 4 pads, their places along the strip, one or two
//! fibres) × objects × disturbance sets × feedback on and off × seeds, on the twin. One row per run
//! (`placement.csv`), one per (layout, object, condition) (`placement_summary.csv`), a chart, and
//! the layout the numbers recommend.
//!
//! The layouts keep pad 0, the paper's pad on the sleeve (61.25 mm of arc), and add pads where the
//! wraps press (12 mm from the strip's base, where every object's wrap starts), as tall as pad 0
//! (5.5 mm) or low (2.5 mm, `protrusion_m`), or beyond pad 0 (77.5 and 94 mm), which a held object
//! does not reach and a sliding one may. Their gratings are
//! spaced so every layout passes the multiplexing check (`tendril_fbg::array`); the four-pad
//! layout puts its fourth pad on a second fibre with its own reference grating. The disturbance
//! sets are `tendril chart controllers`' `none` and its knock (the arm at the paper's limits, 0.3
//! N·s 1 s into the transfer).

use super::controllers::{DisturbanceSet, disturbance_sets};
use super::{cell, run_all, set, write_csv};
use std::path::{Path, PathBuf};
use tendril_config::Override;
use tendril_plot::placement::{PlacementRow, render};
use tendril_run::runner::RunReport;

/// One sensor layout of the study.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// Name, as written in the CSVs and the chart.
    pub name: &'static str,
    /// `array.pads`, as a TOML value (empty: the paper's single pad).
    pub pads: &'static str,
    /// Further scenario overrides of the layout (key, TOML value), e.g. acting on the cue.
    pub extra: Vec<(&'static str, &'static str)>,
    /// Gratings it needs, pad 0's two included.
    pub gratings: u32,
    /// Interrogator channels (fibres) it needs.
    pub channels: u32,
}

/// The layouts: `quick` keeps the paper's pad and the three-pad array of
/// `scenarios/hammer-array.toml` (a low pad at the base, one beyond pad 0); the full study all of
/// them.
pub fn layouts(quick: bool) -> Vec<Layout> {
    let l = |name, pads, gratings, channels| Layout { name, pads, extra: vec![], gratings, channels };
    let paper = l("1: paper", "", 2, 1);
    let base = l("2: +base", "[{arc_m=0.012,lambda1_nm=1525.0}]", 3, 1);
    let low = l("2: +base low", "[{arc_m=0.012,lambda1_nm=1525.0,protrusion_m=0.0025}]", 3, 1);
    let tip = l("2: +tip side", "[{arc_m=0.0775,lambda1_nm=1560.0}]", 3, 1);
    let tips = l("3: tip side ×2", "[{arc_m=0.0775,lambda1_nm=1560.0},{arc_m=0.094,lambda1_nm=1575.0}]", 4, 1);
    let three = l(
        "3: base low+tip side",
        "[{arc_m=0.012,lambda1_nm=1525.0,protrusion_m=0.0025},{arc_m=0.0775,lambda1_nm=1560.0}]",
        4,
        1,
    );
    let four = l(
        "4: two fibres",
        "[{arc_m=0.012,lambda1_nm=1525.0,protrusion_m=0.0025},{arc_m=0.0775,lambda1_nm=1560.0},\
         {arc_m=0.094,channel=2,lambda1_nm=1540.0,lambda2_nm=1550.0}]",
        6,
        2,
    );
    let acting =
        Layout { name: "3: as above + re-tighten", extra: vec![("array.retighten_factor", "1.5")], ..three.clone() };
    if quick { vec![paper, three] } else { vec![paper, base, low, tip, tips, three, four, acting] }
}

/// What the study runs.
#[derive(Debug, Clone)]
pub struct Plan {
    /// One scenario per object.
    pub scenarios: Vec<PathBuf>,
    /// The layouts.
    pub layouts: Vec<Layout>,
    /// The disturbance sets.
    pub sets: Vec<DisturbanceSet>,
    /// Feedback while the arm moves: on, off (full study) or on only (quick).
    pub feedback: Vec<bool>,
    /// The seeds of every case.
    pub seeds: Vec<u64>,
}

impl Plan {
    /// The plan over `scenarios`: quick (seed 1, two layouts, feedback on) or full (seeds 1-10,
    /// every layout, feedback on and off), `seeds` replacing the default seeds when given.
    pub fn new(scenarios: Vec<PathBuf>, quick: bool, seeds: &[u64]) -> Plan {
        let default_seeds: Vec<u64> = if quick { vec![1] } else { (1..=10).collect() };
        Plan {
            scenarios,
            layouts: layouts(quick),
            // `none` and the controllers study's knock: its quick sets.
            sets: disturbance_sets(true),
            feedback: if quick { vec![true] } else { vec![true, false] },
            seeds: if seeds.is_empty() { default_seeds } else { seeds.to_vec() },
        }
    }

    /// Runs in the plan.
    pub fn len(&self) -> usize {
        self.scenarios.len() * self.layouts.len() * self.sets.len() * self.feedback.len() * self.seeds.len()
    }

    /// Whether the plan runs nothing.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// One run of the study.
#[derive(Debug, Clone, PartialEq)]
pub struct PlacementRun {
    /// Layout name.
    pub layout: String,
    /// Object.
    pub object: String,
    /// Disturbance set.
    pub disturbance: String,
    /// Feedback while the arm moves.
    pub feedback: bool,
    /// Seed.
    pub seed: u64,
    /// "held", "dropped" or "error".
    pub outcome: String,
    /// Largest fluctuation of the controlled force while moving [%].
    pub fluctuation_pct: Option<f64>,
    /// Largest true force on any pad while holding \[N\].
    pub max_pad_force_n: Option<f64>,
    /// Share of the holding ticks on which some pad was pressed beyond its range [%].
    pub over_range_pct: Option<f64>,
    /// From the true drop to the slip detector's first alarm \[s\] (negative: before it).
    pub detector_delay_s: Option<f64>,
    /// The same for the array's cue.
    pub cue_delay_s: Option<f64>,
    /// The cue's alarms no drop followed.
    pub cue_false_alarms: Option<u64>,
    /// The slip detector's alarms no drop followed.
    pub detector_false_alarms: Option<u64>,
    /// The error that ended the run.
    pub error: Option<String>,
}

/// What the study wrote and found.
pub struct Outcome {
    /// The files written.
    pub files: Vec<PathBuf>,
    /// One row per run.
    pub runs: Vec<PlacementRun>,
    /// One row per (layout, object, condition).
    pub summary: Vec<SummaryRow>,
    /// The recommended layout and why.
    pub recommendation: String,
}

fn overrides(layout: &Layout, s: &DisturbanceSet, feedback: bool, seed: u64) -> Vec<Override> {
    let mut o: Vec<Override> = s.overrides.iter().map(|(k, v)| set(k, v)).collect();
    if !layout.pads.is_empty() {
        o.push(set("array.pads", layout.pads));
    }
    o.extend(layout.extra.iter().map(|(k, v)| set(k, v)));
    o.push(set("feedback", feedback));
    o.push(set("seed", seed));
    o
}

/// The largest true pad force while holding and the share of holding ticks with a pad over the
/// sensor's range, from the run's rows.
fn pad_loads(report: &RunReport, range_n: f64) -> (Option<f64>, Option<f64>) {
    let drop = report.drop.map(|d| d.cell_time_s);
    let held: Vec<f64> = report
        .rows
        .iter()
        .filter(|r| r.phase.holding() && drop.is_none_or(|d| r.time_s < d) && r.true_force_n.is_finite())
        .map(|r| r.array.pads.as_slice().iter().map(|p| p.true_force_n).fold(r.true_force_n, f64::max))
        .collect();
    if held.is_empty() {
        return (None, None);
    }
    let over = held.iter().filter(|&&f| f > range_n).count() as f64 / held.len() as f64;
    (held.iter().copied().reduce(f64::max), Some(100.0 * over))
}

/// Runs the plan on `threads` workers, writes `placement.csv`, `placement_summary.csv` and the
/// chart into `out`.
pub fn run(plan: &Plan, out: &Path, threads: usize) -> anyhow::Result<Outcome> {
    let range_n = tendril_fbg::estimate::ForceCalibration::default().range_n;
    let mut runs = Vec::with_capacity(plan.len());
    for scenario in &plan.scenarios {
        let mut cases = Vec::new();
        let mut sets = Vec::new();
        for layout in &plan.layouts {
            for s in &plan.sets {
                for &feedback in &plan.feedback {
                    for &seed in &plan.seeds {
                        cases.push((layout.name, s.name, feedback, seed));
                        sets.push(overrides(layout, s, feedback, seed));
                    }
                }
            }
        }
        let stem = scenario.file_stem().map_or(String::new(), |s| s.to_string_lossy().to_string());
        for (r, (layout, set_name, feedback, seed)) in run_all(scenario, sets, threads)?.into_iter().zip(cases) {
            let s = r.summary;
            let (max_pad_force_n, over_range_pct) =
                r.report.as_ref().map_or((None, None), |rep| pad_loads(rep, range_n));
            let array = s.array.clone().unwrap_or_default();
            runs.push(PlacementRun {
                layout: layout.to_string(),
                object: if s.run.object.is_empty() { stem.clone() } else { s.run.object.clone() },
                disturbance: set_name.to_string(),
                feedback,
                seed,
                outcome: s.outcome.clone(),
                fluctuation_pct: s.metrics.max_fluctuation_pct,
                max_pad_force_n,
                over_range_pct,
                detector_delay_s: s.drop_detection_delay_s,
                cue_delay_s: array.cue_detection_delay_s,
                cue_false_alarms: s.array.as_ref().and(array.cue_false_alarms),
                detector_false_alarms: s.false_alarms,
                error: s.error,
            });
        }
    }
    std::fs::create_dir_all(out).map_err(|e| anyhow::anyhow!("{}: {e}", out.display()))?;
    let summary = aggregate(&runs, &plan.layouts);
    let csv = out.join("placement.csv");
    write_csv(&csv, &RUN_COLUMNS, &runs.iter().map(run_cells).collect::<Vec<_>>())?;
    let summary_csv = out.join("placement_summary.csv");
    write_csv(&summary_csv, &SUMMARY_COLUMNS, &summary.iter().map(summary_cells).collect::<Vec<_>>())?;
    let chart_rows: Vec<PlacementRow> = summary
        .iter()
        .map(|r| PlacementRow {
            layout: r.layout.clone(),
            object: r.object.clone(),
            condition: r.condition(),
            runs: r.runs,
            held: r.held,
            max_pad_force_mean_n: r.max_pad_force_mean_n,
        })
        .collect();
    let mut files = vec![csv, summary_csv];
    files.extend(render(&chart_rows, out)?);
    let recommendation = recommend(&summary, &plan.layouts);
    Ok(Outcome { files, runs, summary, recommendation })
}

/// The columns of `placement.csv`.
pub const RUN_COLUMNS: [&str; 14] = [
    "layout",
    "object",
    "disturbance",
    "feedback",
    "seed",
    "outcome",
    "fluctuation_pct",
    "max_pad_force_n",
    "over_range_pct",
    "detector_delay_s",
    "cue_delay_s",
    "cue_false_alarms",
    "detector_false_alarms",
    "error",
];

fn run_cells(r: &PlacementRun) -> Vec<String> {
    let n = |v: Option<u64>| v.map_or(String::new(), |n| n.to_string());
    vec![
        r.layout.clone(),
        r.object.clone(),
        r.disturbance.clone(),
        r.feedback.to_string(),
        r.seed.to_string(),
        r.outcome.clone(),
        cell(r.fluctuation_pct),
        cell(r.max_pad_force_n),
        cell(r.over_range_pct),
        cell(r.detector_delay_s),
        cell(r.cue_delay_s),
        n(r.cue_false_alarms),
        n(r.detector_false_alarms),
        r.error.clone().unwrap_or_default(),
    ]
}

/// How early an alarm must come to count as seeing a drop in time to act \[s\]: within 0.3 s of
/// it, as `tendril chart controllers` counts the slip detector's ("drops seen ≤ 0.3 s").
pub const SEEN_WITHIN_S: f64 = 0.3;

/// One (layout, object, disturbance set, feedback) over its seeds.
#[derive(Debug, Clone, PartialEq)]
pub struct SummaryRow {
    /// Layout name.
    pub layout: String,
    /// Gratings and channels the layout needs.
    pub gratings: u32,
    /// Channels.
    pub channels: u32,
    /// Object.
    pub object: String,
    /// Disturbance set.
    pub disturbance: String,
    /// Feedback while moving.
    pub feedback: bool,
    /// Runs.
    pub runs: usize,
    /// Runs that held.
    pub held: usize,
    /// Runs that ended on an error.
    pub errors: usize,
    /// Mean of the held runs' largest fluctuation while moving [%].
    pub fluctuation_mean_pct: Option<f64>,
    /// Mean over the runs of the largest true pad force while holding \[N\].
    pub max_pad_force_mean_n: Option<f64>,
    /// Mean share of holding ticks with a pad over its range [%].
    pub over_range_mean_pct: Option<f64>,
    /// Drops.
    pub drops: usize,
    /// Drops the slip detector saw within [`SEEN_WITHIN_S`].
    pub seen_by_detector: usize,
    /// Drops the array's cue saw within [`SEEN_WITHIN_S`].
    pub seen_by_cue: usize,
    /// Mean of (detector's delay − cue's delay) over the drops both saw \[s\]: how much earlier
    /// the cue came (negative: later).
    pub cue_lead_mean_s: Option<f64>,
    /// The cue's false alarms over the runs.
    pub cue_false_alarms: u64,
    /// The slip detector's false alarms over the runs.
    pub detector_false_alarms: u64,
}

impl SummaryRow {
    /// The condition's label in the chart.
    pub fn condition(&self) -> String {
        let set = if self.disturbance == "none" { "none" } else { "knock" };
        format!("{set}, feedback {}", if self.feedback { "on" } else { "off" })
    }
}

fn mean(values: impl Iterator<Item = f64>) -> Option<f64> {
    let v: Vec<f64> = values.collect();
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

/// The summary rows, in the plan's order.
fn aggregate(runs: &[PlacementRun], layouts: &[Layout]) -> Vec<SummaryRow> {
    let mut keys: Vec<(String, String, String, bool)> = Vec::new();
    for r in runs {
        let k = (r.layout.clone(), r.object.clone(), r.disturbance.clone(), r.feedback);
        if !keys.contains(&k) {
            keys.push(k);
        }
    }
    keys.into_iter()
        .map(|(layout, object, disturbance, feedback)| {
            let group: Vec<&PlacementRun> = runs
                .iter()
                .filter(|r| {
                    r.layout == layout && r.object == object && r.disturbance == disturbance && r.feedback == feedback
                })
                .collect();
            let l = layouts.iter().find(|l| l.name == layout);
            let dropped: Vec<&&PlacementRun> = group.iter().filter(|r| r.outcome == "dropped").collect();
            let seen = |d: Option<f64>| d.is_some_and(|d| d <= SEEN_WITHIN_S);
            SummaryRow {
                gratings: l.map_or(0, |l| l.gratings),
                channels: l.map_or(0, |l| l.channels),
                runs: group.len(),
                held: group.iter().filter(|r| r.outcome == "held").count(),
                errors: group.iter().filter(|r| r.outcome == "error").count(),
                fluctuation_mean_pct: mean(
                    group.iter().filter(|r| r.outcome == "held").filter_map(|r| r.fluctuation_pct),
                ),
                max_pad_force_mean_n: mean(group.iter().filter_map(|r| r.max_pad_force_n)),
                over_range_mean_pct: mean(group.iter().filter_map(|r| r.over_range_pct)),
                drops: dropped.len(),
                seen_by_detector: dropped.iter().filter(|r| seen(r.detector_delay_s)).count(),
                seen_by_cue: dropped.iter().filter(|r| seen(r.cue_delay_s)).count(),
                cue_lead_mean_s: mean(dropped.iter().filter_map(|r| Some(r.detector_delay_s? - r.cue_delay_s?))),
                cue_false_alarms: group.iter().filter_map(|r| r.cue_false_alarms).sum(),
                detector_false_alarms: group.iter().filter_map(|r| r.detector_false_alarms).sum(),
                layout,
                object,
                disturbance,
                feedback,
            }
        })
        .collect()
}

/// The columns of `placement_summary.csv`.
pub const SUMMARY_COLUMNS: [&str; 19] = [
    "layout",
    "gratings",
    "channels",
    "object",
    "disturbance",
    "feedback",
    "runs",
    "held",
    "errors",
    "fluctuation_mean_pct",
    "max_pad_force_mean_n",
    "over_range_mean_pct",
    "drops",
    "seen_by_detector",
    "seen_by_cue",
    "cue_lead_mean_s",
    "cue_false_alarms",
    "detector_false_alarms",
    "condition",
];

fn summary_cells(r: &SummaryRow) -> Vec<String> {
    vec![
        r.layout.clone(),
        r.gratings.to_string(),
        r.channels.to_string(),
        r.object.clone(),
        r.disturbance.clone(),
        r.feedback.to_string(),
        r.runs.to_string(),
        r.held.to_string(),
        r.errors.to_string(),
        cell(r.fluctuation_mean_pct),
        cell(r.max_pad_force_mean_n),
        cell(r.over_range_mean_pct),
        r.drops.to_string(),
        r.seen_by_detector.to_string(),
        r.seen_by_cue.to_string(),
        cell(r.cue_lead_mean_s),
        r.cue_false_alarms.to_string(),
        r.detector_false_alarms.to_string(),
        r.condition(),
    ]
}

/// The layout the numbers recommend: the most runs held over every object and condition; among
/// equals, the fewest gratings (a pad that holds nothing more is a cost), then the fewest holding
/// ticks over the sensor's range. Said with its numbers against the paper's single pad.
pub fn recommend(summary: &[SummaryRow], layouts: &[Layout]) -> String {
    let score = |name: &str| {
        let rows: Vec<&SummaryRow> = summary.iter().filter(|r| r.layout == name).collect();
        let held: usize = rows.iter().map(|r| r.held).sum();
        let runs: usize = rows.iter().map(|r| r.runs).sum();
        let over = mean(rows.iter().filter_map(|r| r.over_range_mean_pct)).unwrap_or(0.0);
        let seen: usize = rows.iter().map(|r| r.seen_by_cue.max(r.seen_by_detector)).sum();
        let drops: usize = rows.iter().map(|r| r.drops).sum();
        (held, runs, over, seen, drops)
    };
    let mut ranked: Vec<&Layout> = layouts.iter().collect();
    // Most held first; then fewest gratings; then least over range; then the plan's order.
    ranked.sort_by(|a, b| {
        let (sa, sb) = (score(a.name), score(b.name));
        sb.0.cmp(&sa.0).then(a.gratings.cmp(&b.gratings)).then(sa.2.total_cmp(&sb.2))
    });
    let Some(best) = ranked.first() else { return "no layout was run".into() };
    let (held, runs, over, seen, drops) = score(best.name);
    let mut text = format!(
        "recommended: {} ({} gratings on {} channel(s)): held {held} of {runs} runs, pads over range on {over:.1} % of the \
         holding ticks, {seen} of {drops} drops seen within {SEEN_WITHIN_S} s",
        best.name, best.gratings, best.channels
    );
    if let Some(paper) = layouts.first().filter(|p| p.name != best.name) {
        let (held, runs, over, seen, drops) = score(paper.name);
        text += &format!(
            "; the paper's single pad: held {held} of {runs}, over range {over:.1} %, {seen} of {drops} drops seen"
        );
    }
    text
}
