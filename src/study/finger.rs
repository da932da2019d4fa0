//! A finger sized by the twin (`tendril chart finger`): the finger's growth length (the paper's
//! 14 cm and around it) and the pad's height on the sleeve (`finger.pad_protrusion_m`: how far its
//! bump stands off the strip) against hold margin, contact area, peak force and cycle time, per
//! object, on the twin; and the size the numbers recommend.
//!
//! Each growth length is a strip of that length grown out whole (`finger.length_m` =
//! `task.growth_m`), cut into links of about the default finger's 20 mm (`finger.segments` in
//! proportion, rounded: 19.4-21 mm at the study's lengths), so the discretisation is the converged
//! default's at every length. Per case:
//! - feedback on (the paper's mode 2): held or not, the largest pad force (estimate) and grip
//!   force (ground truth, the strip and pad on the object) while holding, the area of the finger's
//!   faces on the object when the lift starts ([`tendril_twin::physics::Scene::contact_area_m2`]),
//!   the cycle time and, for a produce item, whether the grip bruised it and its peak pressure;
//! - feedback off (the paper's mode 1, the grip frozen when the arm starts): how long the grip
//!   holds the object after the arm starts, the hold margin: the creep-limited reserve of the
//!   grip, which the paper's Fig. 9 measures (10 / 13 / 17 s for crimper / shampoo / hammer on the
//!   paper's finger), capped by the end of the carry.
//!
//! The objects are scenario files: a further object (a produce item) is studied by passing its
//! scenario with `--scenario`, no code changed.

use super::{Damage, cell, set, write_csv};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use tendril_config::Override;
use tendril_control::task::Phase;
use tendril_plot::panels::{Mark, Panel, Panels, Series};
use tendril_run::execute::{ModelCache, summarize};
use tendril_run::scenario::PickPlaceScenario;
use tendril_run::session::{Action, Session};

/// The default finger's link length \[m\]: 14 cm in 7 links (`FingerConfig`'s default; a test
/// holds the two together).
pub const LINK_M: f64 = 0.02;

/// Growth lengths of the full study \[m\]: the paper's 14 cm and two links either side.
pub const GROWTH_M: [f64; 5] = [0.105, 0.1225, 0.14, 0.1575, 0.175];

/// Pad heights of the full study \[m\]: the default 5.5 mm (the 4 mm casing standing on the
/// sleeve, the highest `finger.pad_protrusion_m` allows) and the casing recessed into the sleeve by
/// 1 to 4 mm (at 1.5 mm only the bump stands out).
pub const PAD_HEIGHT_M: [f64; 5] = [0.0015, 0.0025, 0.0035, 0.0045, 0.0055];

/// What the study runs.
#[derive(Debug, Clone)]
pub struct Plan {
    /// One scenario per object.
    pub scenarios: Vec<PathBuf>,
    /// Growth lengths \[m\].
    pub growth_m: Vec<f64>,
    /// Pad heights \[m\].
    pub pad_height_m: Vec<f64>,
    /// Seeds of every case.
    pub seeds: Vec<u64>,
}

impl Plan {
    /// Quick: 14 and 17.5 cm at the default pad, seed 1; full: [`GROWTH_M`] × [`PAD_HEIGHT_M`],
    /// seeds 1-2. Lists given replace the defaults.
    pub fn new(scenarios: Vec<PathBuf>, quick: bool, growth_m: &[f64], pad_height_m: &[f64], seeds: &[u64]) -> Plan {
        let or = |given: &[f64], quick_default: &[f64], full: &[f64]| {
            if !given.is_empty() {
                given.to_vec()
            } else if quick {
                quick_default.to_vec()
            } else {
                full.to_vec()
            }
        };
        Plan {
            scenarios,
            growth_m: or(growth_m, &[0.14, 0.175], &GROWTH_M),
            pad_height_m: or(pad_height_m, &[0.0055], &PAD_HEIGHT_M),
            seeds: if !seeds.is_empty() {
                seeds.to_vec()
            } else if quick {
                vec![1]
            } else {
                vec![1, 2]
            },
        }
    }
}

/// A finger size's overrides: the strip of `growth_m` grown whole, links of [`LINK_M`], the pad
/// `pad_height_m` proud.
pub fn finger_overrides(growth_m: f64, pad_height_m: f64) -> Vec<Override> {
    let segments = ((growth_m / LINK_M).round() as i64).max(2);
    vec![
        set("finger.length_m", growth_m),
        set("task.growth_m", growth_m),
        set("finger.segments", segments),
        set("finger.pad_protrusion_m", pad_height_m),
    ]
}

/// One run's figures.
#[derive(Debug, Clone)]
struct Figures {
    outcome: String,
    drop_time_s: Option<f64>,
    carry_s: Option<f64>,
    peak_force_n: Option<f64>,
    peak_grip_n: Option<f64>,
    contact_area_m2: Option<f64>,
    cycle_s: f64,
    damage: Damage,
    error: Option<String>,
}

/// Runs `scenario` on the twin, noting the contact area when the lift starts.
fn run_one(scenario: &PickPlaceScenario, models: &ModelCache) -> anyhow::Result<Figures> {
    let started = tendril_run::clock::RunClock::start();
    let _ = tendril_twin::mujoco_log::take_warnings();
    let mut cell = scenario.sim_cell(models.get(&scenario.scene_spec())?);
    let plan = scenario.control_plan();
    let mut session = Session::start(&mut cell, &plan, plan.controller.build(), None);
    let mut area = None;
    while let Some(row) = session.step(Action::Controller) {
        if area.is_none() && row.phase == Phase::Lift {
            area = session.cell().contact_area_m2();
        }
    }
    let (mut report, _) = session.finish();
    let summary = summarize(scenario, "mujoco", &mut report, started);
    let holding =
        |r: &&tendril_run::trace::TraceRow| r.phase.holding() && report.drop.is_none_or(|d| r.time_s < d.cell_time_s);
    let carry_s = report
        .motion_start_s
        .and_then(|m| report.rows.iter().find(|r| r.phase == Phase::Release).map(|r| r.time_s - m));
    Ok(Figures {
        outcome: summary.outcome.clone(),
        drop_time_s: summary.drop_time_s,
        carry_s,
        peak_force_n: summary.metrics.peak_force_n,
        peak_grip_n: report
            .rows
            .iter()
            .filter(holding)
            .map(|r| r.grip_force_n)
            .filter(|f| f.is_finite())
            .reduce(f64::max),
        contact_area_m2: area,
        cycle_s: summary.sim_time_s,
        damage: Damage::of(&summary),
        error: summary.error,
    })
}

/// One (object, growth, pad height) over its seeds.
#[derive(Debug, Clone, PartialEq)]
pub struct FingerRow {
    /// The object.
    pub object: String,
    /// Growth length \[m\].
    pub growth_m: f64,
    /// Pad height \[m\].
    pub pad_height_m: f64,
    /// Runs with feedback on.
    pub runs: usize,
    /// Of them, held.
    pub held: usize,
    /// Mean hold margin \[s\]: how long the frozen grip (feedback off) held after the arm started,
    /// the end of the carry when it held throughout.
    pub margin_mean_s: Option<f64>,
    /// Feedback-off runs that held to the release.
    pub held_frozen: usize,
    /// Mean area of the finger's faces on the object at the lift \[cm²\] (feedback on).
    pub contact_area_mean_cm2: Option<f64>,
    /// Mean of the largest pad force estimate while holding \[N\] (feedback on).
    pub peak_force_mean_n: Option<f64>,
    /// Mean of the largest grip force (truth) while holding \[N\] (feedback on).
    pub peak_grip_mean_n: Option<f64>,
    /// Mean cycle time \[s\] (feedback on).
    pub cycle_mean_s: Option<f64>,
    /// Runs with feedback on that bruised their produce item (0 for a rigid object).
    pub bruised: usize,
    /// Mean of the peak contact pressure on a produce item \[kPa\] (feedback on).
    pub peak_pressure_mean_kpa: Option<f64>,
}

/// What the study wrote and found.
pub struct Outcome {
    /// The files written.
    pub files: Vec<PathBuf>,
    /// One row per (object, size).
    pub summary: Vec<FingerRow>,
    /// The size the numbers recommend, and why.
    pub recommendation: String,
}

fn mean(values: impl Iterator<Item = f64>) -> Option<f64> {
    let v: Vec<f64> = values.collect();
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

/// Runs the plan on `threads` workers; writes `finger.csv`, `finger_summary.csv` and
/// `finger.png/.svg` into `out`. Every case is loaded (and its keys checked) before any runs: a
/// growth length outside the mechanism's travel is an error naming its key.
pub fn run(plan: &Plan, out: &Path, threads: usize) -> anyhow::Result<Outcome> {
    struct Case {
        object: String,
        growth_m: f64,
        pad_height_m: f64,
        feedback: bool,
        seed: u64,
        scenario: PickPlaceScenario,
    }
    let mut cases = Vec::new();
    for file in &plan.scenarios {
        for &growth_m in &plan.growth_m {
            for &pad_height_m in &plan.pad_height_m {
                for feedback in [true, false] {
                    for &seed in &plan.seeds {
                        let mut o = finger_overrides(growth_m, pad_height_m);
                        o.extend([set("feedback", feedback), set("seed", seed)]);
                        let scenario: PickPlaceScenario = tendril_config::load(file, &o)?;
                        let object = scenario.object.label();
                        cases.push(Case { object, growth_m, pad_height_m, feedback, seed, scenario });
                    }
                }
            }
        }
    }
    let models = ModelCache::default();
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build()?;
    let progress = indicatif::ProgressBar::new(cases.len() as u64);
    let figures: Vec<Figures> = pool.install(|| {
        cases
            .par_iter()
            .map(|c| {
                let f = run_one(&c.scenario, &models).unwrap_or_else(|e| Figures {
                    outcome: "error".into(),
                    drop_time_s: None,
                    carry_s: None,
                    peak_force_n: None,
                    peak_grip_n: None,
                    contact_area_m2: None,
                    cycle_s: f64::NAN,
                    damage: Damage::default(),
                    error: Some(format!("{e:#}")),
                });
                progress.inc(1);
                f
            })
            .collect()
    });
    progress.finish_and_clear();
    std::fs::create_dir_all(out).map_err(|e| anyhow::anyhow!("{}: {e}", out.display()))?;
    let csv = out.join("finger.csv");
    write_csv(
        &csv,
        &[
            "object",
            "growth_m",
            "pad_height_m",
            "feedback",
            "seed",
            "outcome",
            "drop_time_s",
            "carry_s",
            "contact_area_cm2",
            "peak_force_n",
            "peak_grip_n",
            "cycle_s",
            Damage::HEADER[0],
            Damage::HEADER[1],
            "error",
        ],
        &cases
            .iter()
            .zip(&figures)
            .map(|(c, f)| {
                let mut cells = vec![
                    c.object.clone(),
                    format!("{}", c.growth_m),
                    format!("{}", c.pad_height_m),
                    c.feedback.to_string(),
                    c.seed.to_string(),
                    f.outcome.clone(),
                    cell(f.drop_time_s),
                    cell(f.carry_s),
                    cell(f.contact_area_m2.map(|a| a * 1e4)),
                    cell(f.peak_force_n),
                    cell(f.peak_grip_n),
                    format!("{}", f.cycle_s),
                ];
                cells.extend(f.damage.cells());
                cells.push(f.error.clone().unwrap_or_default());
                cells
            })
            .collect::<Vec<_>>(),
    )?;
    let keys = tendril_plot::grid::first_seen(
        cases.iter().map(|c| (c.object.clone(), c.growth_m.to_bits(), c.pad_height_m.to_bits())),
    );
    let summary: Vec<FingerRow> = keys
        .into_iter()
        .map(|(object, g, p)| {
            let group: Vec<(&Case, &Figures)> = cases
                .iter()
                .zip(&figures)
                .filter(|(c, _)| c.object == object && c.growth_m.to_bits() == g && c.pad_height_m.to_bits() == p)
                .collect();
            let on: Vec<&Figures> = group.iter().filter(|(c, _)| c.feedback).map(|(_, f)| *f).collect();
            let off: Vec<&Figures> = group.iter().filter(|(c, _)| !c.feedback).map(|(_, f)| *f).collect();
            FingerRow {
                growth_m: f64::from_bits(g),
                pad_height_m: f64::from_bits(p),
                runs: on.len(),
                held: on.iter().filter(|f| f.outcome == "held").count(),
                margin_mean_s: mean(off.iter().filter_map(|f| f.drop_time_s.or(f.carry_s))),
                held_frozen: off.iter().filter(|f| f.outcome == "held").count(),
                contact_area_mean_cm2: mean(on.iter().filter_map(|f| f.contact_area_m2.map(|a| a * 1e4))),
                peak_force_mean_n: mean(on.iter().filter_map(|f| f.peak_force_n)),
                peak_grip_mean_n: mean(on.iter().filter_map(|f| f.peak_grip_n)),
                cycle_mean_s: mean(on.iter().filter(|f| f.outcome != "error").map(|f| f.cycle_s)),
                bruised: on.iter().filter(|f| f.damage.is_bruised()).count(),
                peak_pressure_mean_kpa: mean(on.iter().filter_map(|f| f.damage.peak_pressure_kpa)),
                object,
            }
        })
        .collect();
    let summary_csv = out.join("finger_summary.csv");
    write_csv(
        &summary_csv,
        &[
            "object",
            "growth_m",
            "pad_height_m",
            "runs",
            "held",
            "margin_mean_s",
            "held_frozen",
            "contact_area_mean_cm2",
            "peak_force_mean_n",
            "peak_grip_mean_n",
            "cycle_mean_s",
            "bruised",
            "peak_pressure_mean_kpa",
        ],
        &summary
            .iter()
            .map(|r| {
                vec![
                    r.object.clone(),
                    format!("{}", r.growth_m),
                    format!("{}", r.pad_height_m),
                    r.runs.to_string(),
                    r.held.to_string(),
                    cell(r.margin_mean_s),
                    r.held_frozen.to_string(),
                    cell(r.contact_area_mean_cm2),
                    cell(r.peak_force_mean_n),
                    cell(r.peak_grip_mean_n),
                    cell(r.cycle_mean_s),
                    r.bruised.to_string(),
                    cell(r.peak_pressure_mean_kpa),
                ]
            })
            .collect::<Vec<_>>(),
    )?;
    let mut files = vec![csv, summary_csv];
    files.extend(tendril_plot::panels::render(&chart(&summary), out, "finger")?);
    let recommendation = recommend(&summary);
    Ok(Outcome { files, summary, recommendation })
}

/// Per object a row of panels (hold margin, contact area, peak grip force, cycle time) against
/// growth length, a series per pad height.
fn chart(summary: &[FingerRow]) -> Panels {
    let objects = tendril_plot::grid::first_seen(summary.iter().map(|r| r.object.clone()));
    let heights = tendril_plot::grid::first_seen(summary.iter().map(|r| r.pad_height_m.to_bits()));
    type Metric = (&'static str, &'static str, fn(&FingerRow) -> Option<f64>);
    let metrics: [Metric; 4] = [
        ("hold margin: frozen grip held after the arm started", "[s]", |r| r.margin_mean_s),
        ("finger area on the object at the lift", "[cm²]", |r| r.contact_area_mean_cm2),
        ("largest grip force while holding (feedback on)", "[N]", |r| r.peak_grip_mean_n),
        ("cycle time (feedback on)", "[s]", |r| r.cycle_mean_s),
    ];
    let mut panels = Vec::new();
    for object in &objects {
        for (caption, unit, value) in metrics {
            let series = heights
                .iter()
                .map(|&h| Series {
                    name: format!("pad {} mm proud", f64::from_bits(h) * 1e3),
                    points: summary
                        .iter()
                        .filter(|r| &r.object == object && r.pad_height_m.to_bits() == h)
                        .map(|r| (r.growth_m * 100.0, value(r).unwrap_or(f64::NAN)))
                        .collect(),
                    mark: Mark::LineDots,
                })
                .collect();
            panels.push(Panel {
                caption: format!("{object}: {caption}"),
                x_desc: "growth length [cm]".into(),
                y_desc: unit.into(),
                series,
                y_range: None,
            });
        }
    }
    Panels { title: "A finger sized by the twin: growth length and pad height per object".into(), panels, columns: 4 }
}

/// The size the numbers recommend: among those that held every run with feedback on for every
/// object without bruising a produce item, the gentlest whose frozen grip (feedback off) still carried every object to the end of
/// the carry: the smallest largest grip force over the objects, ties by the shorter cycle. The
/// hold margin is capped by the carry, so once a grip carries to its end a tighter one only
/// squeezes harder (a pad recessed into the sleeve leaves the wrap's force to the strip, which the
/// setpoint on the pad no longer bounds). If no size carried every object frozen, the largest
/// smallest hold margin, ties by the larger smallest contact area, then the shorter cycle. Said
/// with its numbers against the paper's 14 cm, 5.5 mm.
pub fn recommend(summary: &[FingerRow]) -> String {
    let sizes =
        tendril_plot::grid::first_seen(summary.iter().map(|r| (r.growth_m.to_bits(), r.pad_height_m.to_bits())));
    let rows = |s: (u64, u64)| -> Vec<&FingerRow> {
        summary.iter().filter(|r| (r.growth_m.to_bits(), r.pad_height_m.to_bits()) == s).collect()
    };
    let min = |rs: &[&FingerRow], f: fn(&FingerRow) -> Option<f64>| {
        rs.iter().map(|r| f(r).unwrap_or(0.0)).fold(f64::INFINITY, f64::min)
    };
    let max_grip =
        |s: (u64, u64)| rows(s).iter().map(|r| r.peak_grip_mean_n.unwrap_or(f64::INFINITY)).fold(0.0, f64::max);
    let cycle = |s: (u64, u64)| mean(rows(s).iter().filter_map(|r| r.cycle_mean_s)).unwrap_or(f64::INFINITY);
    let score = |s: (u64, u64)| {
        let rs = rows(s);
        (min(&rs, |r| r.margin_mean_s), min(&rs, |r| r.contact_area_mean_cm2), cycle(s))
    };
    let describe = |s: (u64, u64)| {
        let rs = rows(s);
        let (margin, area, cycle) = score(s);
        let held: usize = rs.iter().map(|r| r.held).sum();
        let runs: usize = rs.iter().map(|r| r.runs).sum();
        let frozen: usize = rs.iter().map(|r| r.held_frozen).sum();
        let bruised: usize = rs.iter().map(|r| r.bruised).sum();
        let bruised = if bruised > 0 { format!(", {bruised} bruised") } else { String::new() };
        let per_object: Vec<String> = rs
            .iter()
            .map(|r| format!("{} {}", r.object, r.margin_mean_s.map_or("-".into(), |m| format!("{m:.1} s"))))
            .collect();
        format!(
            "growth {:.2} cm, pad {:.1} mm proud: held {held} of {runs} with feedback on{bruised}, {frozen} of {runs} carried \
             frozen; hold margin at least {margin:.1} s ({}), grip force at most {:.1} N, finger area on the object \
             at least {area:.1} cm², mean cycle {cycle:.1} s",
            f64::from_bits(s.0) * 100.0,
            f64::from_bits(s.1) * 1e3,
            per_object.join(", "),
            max_grip(s),
        )
    };
    let held: Vec<(u64, u64)> = sizes
        .iter()
        .copied()
        .filter(|&s| rows(s).iter().all(|r| r.held == r.runs && r.runs > 0 && r.bruised == 0))
        .collect();
    let carried = held.iter().copied().filter(|&s| rows(s).iter().all(|r| r.held_frozen == r.runs));
    let gentlest = carried.min_by(|&a, &b| max_grip(a).total_cmp(&max_grip(b)).then(cycle(a).total_cmp(&cycle(b))));
    let best = gentlest.or_else(|| {
        held.iter().copied().max_by(|&a, &b| {
            let (sa, sb) = (score(a), score(b));
            sa.0.total_cmp(&sb.0).then(sa.1.total_cmp(&sb.1)).then(sb.2.total_cmp(&sa.2))
        })
    });
    let Some(best) = best else {
        return "recommended: none of the sizes held every run of every object without bruising it".into();
    };
    let mut text = format!("recommended: {}", describe(best));
    let paper = (0.14_f64.to_bits(), 0.0055_f64.to_bits());
    if best != paper && sizes.contains(&paper) {
        text += &format!("; the paper's finger: {}", describe(paper));
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_studys_links_are_the_default_fingers() {
        let f = tendril_twin::physics::FingerConfig::default();
        assert!((LINK_M - f.length_m / f64::from(f.segments)).abs() < 1e-12, "{LINK_M} m against {f:?}");
    }

    fn row(growth_m: f64, peak_grip_mean_n: f64, bruised: usize) -> FingerRow {
        FingerRow {
            object: "cherry_tomato".into(),
            growth_m,
            pad_height_m: 0.0055,
            runs: 2,
            held: 2,
            margin_mean_s: Some(21.0),
            held_frozen: 2,
            contact_area_mean_cm2: Some(3.0),
            peak_force_mean_n: Some(0.6),
            peak_grip_mean_n: Some(peak_grip_mean_n),
            cycle_mean_s: Some(43.0),
            bruised,
            peak_pressure_mean_kpa: Some(100.0),
        }
    }

    #[test]
    fn a_size_that_bruises_a_produce_item_is_not_recommended() {
        // The gentler grip bruised the fruit once (its bump pressed on it): the other size wins.
        let summary = vec![row(0.14, 3.0, 1), row(0.175, 5.0, 0)];
        let text = recommend(&summary);
        assert!(text.starts_with("recommended: growth 17.50 cm"), "{text}");
        let text = recommend(&[row(0.14, 3.0, 1)]);
        assert!(text.contains("without bruising"), "{text}");
    }
}
