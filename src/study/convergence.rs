//! Convergence of the twin's answers under numerical refinement: each Section V case (object ×
//! feedback on/off × seed) at the default timestep and finger links, at the timestep halved
//! at least twice and down to [`FINEST_TIMESTEP_S`] and at the links doubled and quadrupled, and
//! at the finest of both.
//!
//! Each run gives the figures users compare (outcome, drop phase and time, rise time, largest
//! fluctuation while moving) and its force-trace RMSE against the finest setting. Pairs of settings
//! are then judged by the [`Criteria`]: the default against each refinement, and the two finest
//! settings against each other (so the reference itself is shown converged).
//!
//! A produce item ([`Plan::produce`]) adds its flex's numerics to the refinements (the grid
//! refined, the quadratic degrees of freedom) and its answers to the criteria: the peak contact
//! pressure, and for a harvest how it ended and the pull the stem reached.

use super::{StudyRun, cell, run_all, set, write_csv};
use std::path::{Path, PathBuf};
use tendril_plot::convergence::{ConvergenceRow, render};
use tendril_run::metrics::despiked;
use tendril_run::trace::TraceRow;

/// The study halves the timestep down to this one at least \[s\] unless asked for a finer one
/// (`tendril chart convergence --finest-step`): the issue's "down to at least 0.625 ms" (and always
/// at least twice, step/2 and step/4).
pub const FINEST_TIMESTEP_S: f64 = 0.000625;

/// What "converged" means here: two settings give the same answers within these tolerances.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Criteria {
    /// Largest drop-time difference \[s\].
    pub drop_time_s: f64,
    /// Largest rise-time difference \[s\].
    pub rise_time_s: f64,
    /// Largest difference of the largest fluctuation while moving \[percentage points\].
    pub fluctuation_pp: f64,
    /// Largest RMS difference of the true pad-force traces up to the first drop \[N\].
    pub force_rmse_n: f64,
    /// Largest difference of a produce item's peak contact pressure, relative to the larger \[%\].
    pub peak_pressure_pct: f64,
    /// Largest difference of a harvest's largest stem tension (the pull the grip reached),
    /// relative to the larger \[%\].
    pub stem_tension_pct: f64,
}

/// The project's convergence criteria (issue "Answers that do not depend on the numerics"): drop
/// time 0.5 s (the paper reads its drop times off a plot to about that), rise 0.3 s, fluctuation
/// 5 points (the paper's fluctuations are 12-28 %), force 0.05 N (5 % of a 1 N setpoint, 1.7 times
/// the interrogator noise's effect on the estimate).
///
/// A produce item's peak pressure: 10 % (the bruise thresholds are stated to a tenth at best; the
/// pressure goes as the cube root of the force, so 10 % is a third of the force); a harvest's pull:
/// 10 %, the same share of the force as the pad's 0.05 N of a 0.5 N setpoint.
pub const CRITERIA: Criteria = Criteria {
    drop_time_s: 0.5,
    rise_time_s: 0.3,
    fluctuation_pp: 5.0,
    force_rmse_n: 0.05,
    peak_pressure_pct: 10.0,
    stem_tension_pct: 10.0,
};

/// A produce item's flex at one setting: its grid (points per axis) and degrees of freedom.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlexSetting {
    /// Points per axis.
    pub count: u32,
    /// Degrees of freedom.
    pub dof: tendril_twin::physics::Dof,
}

impl FlexSetting {
    /// The flex of `scenario` as loaded (its `[produce]` or the item's file); None for a rigid
    /// object.
    pub fn of(scenario: &tendril_run::scenario::PickPlaceScenario) -> anyhow::Result<Option<FlexSetting>> {
        Ok(scenario.object.model()?.produce.map(|item| FlexSetting {
            count: scenario.produce.count.unwrap_or(item.count[0]),
            dof: scenario.produce.dof.unwrap_or(item.dof),
        }))
    }
}

/// One numerical setting: a timestep and a number of finger links.
#[derive(Debug, Clone, PartialEq)]
pub struct Setting {
    /// Short name (`default`, `step/2`, `links x2`, `finest`...).
    pub label: String,
    /// Physics timestep \[s\].
    pub timestep_s: f64,
    /// Finger links.
    pub segments: u32,
    /// A produce item's flex (`None` for a rigid object's study).
    pub flex: Option<FlexSetting>,
}

/// The settings of a study and the pairs judged by the criteria.
#[derive(Debug, Clone)]
pub struct Plan {
    /// Every setting run, the default first, the finest last.
    pub settings: Vec<Setting>,
    /// Pairs of indices into `settings` judged against [`CRITERIA`].
    pub comparisons: Vec<(usize, usize)>,
}

impl Plan {
    /// The full study from the default timestep and links: the timestep halved at least twice and
    /// down to `finest_timestep_s` or below ([`FINEST_TIMESTEP_S`] unless a finer reference is
    /// wanted), the links ×2 and ×4, the finest of both, and its two neighbours (one refinement
    /// coarser in time, one in links) for the reference pair.
    pub fn full(timestep_s: f64, segments: u32, finest_timestep_s: f64) -> Plan {
        let s = |label: String, timestep_s: f64, segments: u32| Setting { label, timestep_s, segments, flex: None };
        let mut settings = vec![s("default".into(), timestep_s, segments)];
        let mut dt = timestep_s;
        let mut k = 1;
        while k <= 2 || dt > finest_timestep_s * 1.0001 {
            dt /= 2.0;
            settings.push(s(format!("step/{}", 1 << k), dt, segments));
            k += 1;
        }
        let finest_dt = dt;
        settings.push(s("links x2".into(), timestep_s, 2 * segments));
        settings.push(s("links x4".into(), timestep_s, 4 * segments));
        settings.push(s("finest step x2".into(), 2.0 * finest_dt, 4 * segments));
        settings.push(s("finest links /2".into(), finest_dt, 2 * segments));
        settings.push(s("finest".into(), finest_dt, 4 * segments));
        let find = |l: &str| settings.iter().position(|x| x.label == l);
        let last = settings.len() - 1;
        let mut comparisons = Vec::new();
        for l in ["step/2", "step/4", "links x2"] {
            if let Some(i) = find(l) {
                comparisons.push((0, i));
            }
        }
        comparisons.push((last, last - 2));
        comparisons.push((last, last - 1));
        Plan { settings, comparisons }
    }

    /// The CI-sized study: the default against step/2 and links ×2 (links ×2, the last setting,
    /// stands in as the finest for the RMSE column).
    pub fn quick(timestep_s: f64, segments: u32) -> Plan {
        let settings = vec![
            Setting { label: "default".into(), timestep_s, segments, flex: None },
            Setting { label: "step/2".into(), timestep_s: timestep_s / 2.0, segments, flex: None },
            Setting { label: "links x2".into(), timestep_s, segments: 2 * segments, flex: None },
        ];
        Plan { settings, comparisons: vec![(0, 1), (0, 2)] }
    }

    /// A produce item's study from the default timestep, links and flex `flex`: the default
    /// against step/2, links ×2, the flex's grid refined (twice the intervals per axis) and its
    /// quadratic degrees of freedom (when the default's are trilinear), each judged against the
    /// default.
    pub fn produce(timestep_s: f64, segments: u32, flex: FlexSetting) -> Plan {
        use tendril_twin::physics::Dof;
        let s = |label: &str, timestep_s: f64, segments: u32, flex: FlexSetting| Setting {
            label: label.into(),
            timestep_s,
            segments,
            flex: Some(flex),
        };
        let mut settings = vec![
            s("default", timestep_s, segments, flex),
            s("step/2", timestep_s / 2.0, segments, flex),
            s("links x2", timestep_s, 2 * segments, flex),
            s("grid x2", timestep_s, segments, FlexSetting { count: 2 * flex.count - 1, ..flex }),
        ];
        if flex.dof == Dof::Trilinear {
            settings.push(s("quadratic", timestep_s, segments, FlexSetting { dof: Dof::Quadratic, ..flex }));
        }
        let comparisons = (1..settings.len()).map(|i| (0, i)).collect();
        Plan { settings, comparisons }
    }

    /// A produce item's CI-sized study: the default against step/2 only (the first refinement
    /// of [`Plan::produce`]).
    pub fn produce_quick(timestep_s: f64, segments: u32, flex: FlexSetting) -> Plan {
        let mut plan = Plan::produce(timestep_s, segments, flex);
        plan.settings.truncate(2);
        plan.comparisons.truncate(1);
        plan
    }

    /// The plan for `scenario` as loaded (its `--set`s applied), from its own timestep, links and,
    /// for a produce item, its flex's grid and degrees of freedom (the scenario's `[produce]` or
    /// the item's file): [`Plan::produce`] (with `quick`, [`Plan::produce_quick`]) for a produce
    /// item, else [`Plan::full`] down to `finest_timestep_s` (with `quick`, [`Plan::quick`]).
    pub fn for_scenario(
        scenario: &tendril_run::scenario::PickPlaceScenario,
        quick: bool,
        finest_timestep_s: f64,
    ) -> anyhow::Result<Plan> {
        let (dt, links) = (scenario.physics.timestep_s, scenario.finger.segments);
        Ok(match FlexSetting::of(scenario)? {
            Some(flex) => {
                if quick {
                    Plan::produce_quick(dt, links, flex)
                } else {
                    Plan::produce(dt, links, flex)
                }
            }
            None if quick => Plan::quick(dt, links),
            None => Plan::full(dt, links, finest_timestep_s),
        })
    }
}

/// One case: a scenario (object), a feedback mode and a seed.
#[derive(Debug, Clone, PartialEq)]
pub struct Case {
    /// Scenario file.
    pub scenario: PathBuf,
    /// Force control kept on while the arm moves.
    pub feedback: bool,
    /// Seed.
    pub seed: u64,
}

/// The answers of one run that the criteria compare.
#[derive(Debug, Clone, PartialEq)]
pub struct Answers {
    /// `held`, `dropped` or `error`.
    pub outcome: String,
    /// Phase of the drop.
    pub drop_phase: Option<String>,
    /// Drop time after the arm starts \[s\].
    pub drop_time_s: Option<f64>,
    /// Rise time to 90 % \[s\].
    pub rise_time_s: Option<f64>,
    /// Largest fluctuation while moving \[%\].
    pub fluctuation_pct: Option<f64>,
    /// A produce item's largest peak contact pressure \[kPa\].
    pub peak_pressure_kpa: Option<f64>,
    /// A harvest's end.
    pub harvest: Option<String>,
    /// A harvest's largest stem tension \[N\].
    pub max_stem_tension_n: Option<f64>,
}

impl Answers {
    fn of(run: &StudyRun) -> Answers {
        let s = &run.summary;
        Answers {
            outcome: s.outcome.clone(),
            drop_phase: s.drop_phase.clone(),
            drop_time_s: s.drop_time_s,
            rise_time_s: s.metrics.rise_time_90_s,
            fluctuation_pct: s.metrics.max_fluctuation_pct,
            peak_pressure_kpa: s.produce.as_ref().map(|p| p.peak_pressure_kpa),
            harvest: s.produce.as_ref().and_then(|p| p.harvest.clone()),
            max_stem_tension_n: s.produce.as_ref().and_then(|p| p.max_stem_tension_n),
        }
    }
}

/// How two runs of one case compare, criterion by criterion.
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    /// Same outcome and drop phase (and, for a harvest, the same end).
    pub same_outcome: bool,
    /// Drop-time difference \[s\] (None unless both dropped).
    pub drop_time_s: Option<f64>,
    /// Rise-time difference \[s\] (None unless both rose).
    pub rise_time_s: Option<f64>,
    /// Fluctuation difference \[percentage points\] (None unless both held).
    pub fluctuation_pp: Option<f64>,
    /// RMS difference of the true pad force up to the first drop \[N\].
    pub force_rmse_n: Option<f64>,
    /// A produce item's peak-pressure difference, relative to the larger \[%\].
    pub peak_pressure_pct: Option<f64>,
    /// A harvest's largest-stem-tension difference, relative to the larger \[%\].
    pub stem_tension_pct: Option<f64>,
}

impl Comparison {
    /// Compares `a` with `b`.
    pub fn between(a: &StudyRun, b: &StudyRun) -> Comparison {
        let (x, y) = (Answers::of(a), Answers::of(b));
        let diff = |p: Option<f64>, q: Option<f64>| p.zip(q).map(|(p, q)| (p - q).abs());
        let relative = |p: Option<f64>, q: Option<f64>| {
            p.zip(q).map(|(p, q)| if p.max(q) > 0.0 { 100.0 * (p - q).abs() / p.max(q) } else { 0.0 })
        };
        Comparison {
            same_outcome: x.outcome == y.outcome && x.drop_phase == y.drop_phase && x.harvest == y.harvest,
            peak_pressure_pct: relative(x.peak_pressure_kpa, y.peak_pressure_kpa),
            stem_tension_pct: relative(x.max_stem_tension_n, y.max_stem_tension_n),
            drop_time_s: diff(x.drop_time_s, y.drop_time_s),
            rise_time_s: diff(x.rise_time_s, y.rise_time_s),
            fluctuation_pp: diff(x.fluctuation_pct, y.fluctuation_pct),
            force_rmse_n: force_rmse(a, b),
        }
    }

    /// The criteria this comparison breaks (empty: converged). A rise time present in one run
    /// only counts as broken; so does a trace that cannot be compared.
    pub fn failures(&self, c: &Criteria) -> Vec<&'static str> {
        let mut failed = Vec::new();
        let over = |v: Option<f64>, limit: f64| v.is_some_and(|v| v > limit);
        if !self.same_outcome {
            failed.push("outcome");
        }
        if over(self.drop_time_s, c.drop_time_s) {
            failed.push("drop time");
        }
        if over(self.rise_time_s, c.rise_time_s) {
            failed.push("rise time");
        }
        if over(self.fluctuation_pp, c.fluctuation_pp) {
            failed.push("fluctuation");
        }
        if self.force_rmse_n.is_none_or(|v| v > c.force_rmse_n) {
            failed.push("force RMSE");
        }
        if over(self.peak_pressure_pct, c.peak_pressure_pct) {
            failed.push("peak pressure");
        }
        if over(self.stem_tension_pct, c.stem_tension_pct) {
            failed.push("harvest pull");
        }
        failed
    }
}

/// RMS difference of two runs' true pad force, tick by tick, while both hold the object and
/// up to [`Criteria::drop_time_s`] before the first drop of either. None when a run has no ticks to
/// compare.
///
/// The ticks before a drop are the breakaway, and the drop-time criterion already judges them.
/// The drop watch counts a drop once the object has slid 20 mm, and it starts to slide 0.3-0.4 s
/// before that, striking the pad as it goes. The hammer without feedback, seed 3, at the default:
/// the slip speed rose from 0.3 to 18 mm/s between 36.77 and 36.92 s, the drop counted at 37.21 s,
/// and the pad read 0-2.6 N strikes. Where those strikes fall is the drop's timing, which two runs
/// may differ in by up to that criterion. Comparing the strikes tick by tick judged the timing again,
/// to a tenth of a second: 0.062 N of RMS difference against step/2, and 0.006 N without the
/// last 0.5 s. After a drop the force is a falling object striking the strip, chaotic in any
/// simulation. The fit's objective leaves out the same stretch, with its own 1 s margin
/// (`fit::objective::Weights::drop_margin_s`).
///
/// Both traces go through the [`despiked`] median that rise times are read through: the pad's
/// first touch is an impact a few milliseconds long, and the 100 Hz trace samples its peak or
/// misses it depending on where a tick falls (crimper without feedback, seed 1: 1.32 N for one tick
/// at 1.25 ms, nothing at 0.625 ms), which alone made 0.034 N of a 0.054 N RMS difference. The
/// median removes one- and two-tick excursions and keeps everything slower.
pub fn force_rmse(a: &StudyRun, b: &StudyRun) -> Option<f64> {
    let (a, b) = (a.report.as_ref()?, b.report.as_ref()?);
    let first_drop = [a.drop, b.drop].iter().flatten().map(|d| d.cell_time_s).fold(f64::INFINITY, f64::min);
    held_force_rmse(&a.rows, &b.rows, first_drop - CRITERIA.drop_time_s)
}

/// RMS difference of two traces' [`despiked`] true pad force over the ticks where both hold the
/// object, before `until_s` (cell time). None when no tick is left.
fn held_force_rmse(a: &[TraceRow], b: &[TraceRow], until_s: f64) -> Option<f64> {
    let force = |rows: &[TraceRow]| despiked(&rows.iter().map(|r| r.true_force_n).collect::<Vec<_>>());
    let (fa, fb) = (force(a), force(b));
    let diffs: Vec<f64> = a
        .iter()
        .zip(b)
        .zip(fa.iter().zip(&fb))
        .filter(|((x, y), _)| x.phase.holding() && y.phase.holding() && x.time_s < until_s)
        .map(|(_, (p, q))| (p - q).powi(2))
        .filter(|d| d.is_finite())
        .collect();
    (!diffs.is_empty()).then(|| (diffs.iter().sum::<f64>() / diffs.len() as f64).sqrt())
}

/// A study's result: every run's row, and every comparison's verdict.
pub struct Study {
    /// One row per case and setting.
    pub rows: Vec<ConvergenceRow>,
    /// (case label, comparison label, comparison) for every case and judged pair.
    pub verdicts: Vec<(String, String, Comparison)>,
}

impl Study {
    /// The verdicts that break a criterion, with what they break.
    pub fn failures(&self) -> Vec<(&str, &str, Vec<&'static str>)> {
        self.verdicts
            .iter()
            .map(|(case, pair, c)| (case.as_str(), pair.as_str(), c.failures(&CRITERIA)))
            .filter(|(_, _, f)| !f.is_empty())
            .collect()
    }
}

fn case_label(case: &Case) -> String {
    let object = case.scenario.file_stem().map_or_else(String::new, |s| s.to_string_lossy().to_string());
    format!("{object} {} seed {}", if case.feedback { "on" } else { "off" }, case.seed)
}

/// Runs every case at every setting of `plan` (`extra` overrides on all, for example the backend)
/// on `threads` workers, and judges the plan's pairs.
pub fn study(cases: &[Case], plan: &Plan, extra: &[tendril_config::Override], threads: usize) -> anyhow::Result<Study> {
    let mut rows = Vec::new();
    let mut verdicts = Vec::new();
    // One batch per scenario file (run_all loads one file), all its cases and settings at once.
    let mut scenarios: Vec<&Path> = cases.iter().map(|c| c.scenario.as_path()).collect();
    scenarios.dedup();
    for scenario in scenarios {
        let mine: Vec<&Case> = cases.iter().filter(|c| c.scenario == scenario).collect();
        let mut sets = Vec::new();
        for case in &mine {
            for s in &plan.settings {
                let mut o = extra.to_vec();
                o.extend([
                    set("physics.timestep_s", s.timestep_s),
                    set("finger.segments", s.segments),
                    set("feedback", case.feedback),
                    set("seed", case.seed),
                ]);
                if let Some(f) = s.flex {
                    o.extend([set("produce.count", f.count), set("produce.dof", format!("\"{}\"", f.dof.name()))]);
                }
                sets.push(o);
            }
        }
        let runs = run_all(scenario, sets, threads)?;
        for (case, runs) in mine.iter().zip(runs.chunks(plan.settings.len())) {
            let label = case_label(case);
            let finest = runs.last().expect("a plan has settings");
            for (s, run) in plan.settings.iter().zip(runs) {
                let a = Answers::of(run);
                rows.push(ConvergenceRow {
                    backend: run.summary.run.backend.clone(),
                    case: label.clone(),
                    object: run.summary.run.object.clone(),
                    feedback: case.feedback,
                    seed: case.seed,
                    setting: s.label.clone(),
                    timestep_s: s.timestep_s,
                    segments: s.segments,
                    outcome: a.outcome,
                    drop_phase: a.drop_phase,
                    drop_time_s: a.drop_time_s,
                    rise_time_s: a.rise_time_s,
                    fluctuation_pct: a.fluctuation_pct,
                    force_rmse_vs_finest_n: force_rmse(run, finest),
                    sim_s_per_wall_s: run.summary.real_time_factor,
                    error: run.summary.error.clone(),
                    grid: s.flex.map(|f| f.count),
                    dof: s.flex.map(|f| f.dof.name().to_string()),
                    peak_pressure_kpa: a.peak_pressure_kpa,
                    harvest: a.harvest,
                    max_stem_tension_n: a.max_stem_tension_n,
                });
            }
            for &(i, j) in &plan.comparisons {
                let pair = format!("{} vs {}", plan.settings[i].label, plan.settings[j].label);
                verdicts.push((label.clone(), pair, Comparison::between(&runs[i], &runs[j])));
            }
        }
    }
    Ok(Study { rows, verdicts })
}

/// Runs the study, writes `convergence.csv` (one row per case and setting),
/// `convergence_criteria.csv` (one row per case and judged pair) and the chart into `out`; returns
/// the study and the files written.
pub fn run(
    cases: &[Case],
    plan: &Plan,
    extra: &[tendril_config::Override],
    threads: usize,
    out: &Path,
) -> anyhow::Result<(Study, Vec<PathBuf>)> {
    let study = study(cases, plan, extra, threads)?;
    std::fs::create_dir_all(out).map_err(|e| anyhow::anyhow!("{}: {e}", out.display()))?;
    let csv = out.join("convergence.csv");
    let cells: Vec<Vec<String>> = study.rows.iter().map(ConvergenceRow::cells).collect();
    write_csv(&csv, &ConvergenceRow::HEADER, &cells)?;
    let criteria = out.join("convergence_criteria.csv");
    let header = [
        "case",
        "comparison",
        "same_outcome",
        "drop_time_diff_s",
        "rise_time_diff_s",
        "fluctuation_diff_pp",
        "force_rmse_n",
        "peak_pressure_diff_pct",
        "stem_tension_diff_pct",
        "converged",
        "failed",
    ];
    let cells: Vec<Vec<String>> = study
        .verdicts
        .iter()
        .map(|(case, pair, c)| {
            let failed = c.failures(&CRITERIA);
            vec![
                case.clone(),
                pair.clone(),
                c.same_outcome.to_string(),
                cell(c.drop_time_s),
                cell(c.rise_time_s),
                cell(c.fluctuation_pp),
                cell(c.force_rmse_n),
                cell(c.peak_pressure_pct),
                cell(c.stem_tension_pct),
                failed.is_empty().to_string(),
                failed.join("; "),
            ]
        })
        .collect();
    write_csv(&criteria, &header, &cells)?;
    let mut files = vec![csv, criteria];
    files.extend(render(&study.rows, out)?);
    Ok((study, files))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_full_plan_halves_the_step_to_the_finest_and_judges_the_issue_pairs() {
        let plan = Plan::full(0.005, 8, FINEST_TIMESTEP_S);
        let labels: Vec<&str> = plan.settings.iter().map(|s| s.label.as_str()).collect();
        assert_eq!(
            labels,
            [
                "default",
                "step/2",
                "step/4",
                "step/8",
                "links x2",
                "links x4",
                "finest step x2",
                "finest links /2",
                "finest"
            ]
        );
        let finest = plan.settings.last().unwrap();
        assert!((finest.timestep_s - FINEST_TIMESTEP_S).abs() < 1e-12 && finest.segments == 32);
        let pairs: Vec<(&str, &str)> = plan
            .comparisons
            .iter()
            .map(|&(i, j)| (plan.settings[i].label.as_str(), plan.settings[j].label.as_str()))
            .collect();
        assert_eq!(
            pairs,
            [
                ("default", "step/2"),
                ("default", "step/4"),
                ("default", "links x2"),
                ("finest", "finest step x2"),
                ("finest", "finest links /2")
            ]
        );
        // A default one halving from 0.625 ms is still halved twice: step/2 and step/4 are always judged.
        let fine = Plan::full(0.00125, 64, FINEST_TIMESTEP_S);
        let steps: Vec<(&str, f64)> = fine.settings.iter().take(4).map(|s| (s.label.as_str(), s.timestep_s)).collect();
        assert_eq!(steps, [("default", 0.00125), ("step/2", 0.000625), ("step/4", 0.0003125), ("links x2", 0.00125)]);
        assert_eq!(fine.settings.last().unwrap().segments, 256);
        // A finer reference on request: the default's step halved down to it, the pairs the same.
        let finer = Plan::full(0.0025, 8, 0.00015625);
        let steps: Vec<f64> = finer.settings.iter().filter(|s| s.segments == 8).map(|s| s.timestep_s).collect();
        assert_eq!(steps, [0.0025, 0.00125, 0.000625, 0.0003125, 0.00015625]);
        let finest = finer.settings.last().unwrap();
        assert_eq!((finest.timestep_s, finest.segments), (0.00015625, 32));
        assert_eq!(finer.comparisons.len(), plan.comparisons.len());
    }

    #[test]
    fn a_produce_plan_refines_the_flex_and_its_quick_form_the_step_only() {
        use tendril_twin::physics::Dof;
        let flex = FlexSetting { count: 7, dof: Dof::Trilinear };
        let plan = Plan::produce(0.0025, 8, flex);
        let settings: Vec<(&str, f64, u32, u32, Dof)> = plan
            .settings
            .iter()
            .map(|s| {
                let f = s.flex.unwrap();
                (s.label.as_str(), s.timestep_s, s.segments, f.count, f.dof)
            })
            .collect();
        assert_eq!(
            settings,
            [
                ("default", 0.0025, 8, 7, Dof::Trilinear),
                ("step/2", 0.00125, 8, 7, Dof::Trilinear),
                ("links x2", 0.0025, 16, 7, Dof::Trilinear),
                ("grid x2", 0.0025, 8, 13, Dof::Trilinear),
                ("quadratic", 0.0025, 8, 7, Dof::Quadratic)
            ]
        );
        assert_eq!(plan.comparisons, [(0, 1), (0, 2), (0, 3), (0, 4)]);
        // Already quadratic: nothing finer to try in the degrees of freedom.
        assert_eq!(Plan::produce(0.0025, 8, FlexSetting { dof: Dof::Quadratic, ..flex }).settings.len(), 4);
        let quick = Plan::produce_quick(0.0025, 8, flex);
        assert_eq!(quick.settings, plan.settings[..2]);
        assert_eq!(quick.comparisons, [(0, 1)]);
    }

    #[test]
    fn the_force_trace_is_compared_while_held_and_up_to_the_drop_criterion_before_a_drop() {
        use tendril_control::task::Phase;
        // Two held traces 0.01 N apart at 100 Hz, the second striking the pad with 2 N for 0.1 s in
        // the breakaway 0.3 s before a drop at 10 s.
        let trace = |offset: f64, strike: bool| -> Vec<TraceRow> {
            (0..1000)
                .map(|i| {
                    let t = f64::from(i) * 0.01;
                    let f = if strike && (9.7..9.8).contains(&t) { 2.0 } else { 1.0 + offset };
                    TraceRow::at(t, if t < 1.0 { Phase::Wrap } else { Phase::Lift }, f)
                })
                .collect()
        };
        let (a, b) = (trace(0.0, false), trace(0.01, true));
        let breakaway_left_out = held_force_rmse(&a, &b, 10.0 - CRITERIA.drop_time_s).unwrap();
        assert!((breakaway_left_out - 0.01).abs() < 1e-9, "{breakaway_left_out}");
        // Compared up to the drop itself, the strikes alone break the criterion.
        let up_to_the_drop = held_force_rmse(&a, &b, 10.0).unwrap();
        assert!(up_to_the_drop > CRITERIA.force_rmse_n, "{up_to_the_drop}");
        // Nothing held before the limit: nothing to compare.
        assert_eq!(held_force_rmse(&a, &b, 0.5), None);
    }

    #[test]
    fn each_criterion_can_fail_on_its_own() {
        let ok = Comparison {
            same_outcome: true,
            drop_time_s: Some(0.4),
            rise_time_s: Some(0.2),
            fluctuation_pp: Some(4.0),
            force_rmse_n: Some(0.04),
            peak_pressure_pct: Some(9.0),
            stem_tension_pct: Some(9.0),
        };
        assert!(ok.failures(&CRITERIA).is_empty());
        let cases: [(Comparison, &str); 7] = [
            (Comparison { same_outcome: false, ..ok.clone() }, "outcome"),
            (Comparison { drop_time_s: Some(0.6), ..ok.clone() }, "drop time"),
            (Comparison { rise_time_s: Some(0.31), ..ok.clone() }, "rise time"),
            (Comparison { fluctuation_pp: Some(5.5), ..ok.clone() }, "fluctuation"),
            (Comparison { force_rmse_n: None, ..ok.clone() }, "force RMSE"),
            (Comparison { peak_pressure_pct: Some(11.0), ..ok.clone() }, "peak pressure"),
            (Comparison { stem_tension_pct: Some(10.5), ..ok.clone() }, "harvest pull"),
        ];
        for (c, what) in cases {
            assert_eq!(c.failures(&CRITERIA), [what]);
        }
        // A figure only one run has (held vs dropped) is judged by the outcome alone.
        let held_vs_dropped = Comparison { same_outcome: false, drop_time_s: None, ..ok };
        assert_eq!(held_vs_dropped.failures(&CRITERIA), ["outcome"]);
    }
}
