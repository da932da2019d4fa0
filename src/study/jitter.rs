//! The real path under timing jitter: the scenario run against the virtual devices (`tendril
//! serve`'s, in-process, in real time) while they hold back and bunch their packets, each run
//! compared phase by phase with the same scenario on the twin ([`tendril_run::compare`]), with the
//! default watchdogs. What it tells: how much jitter the real path tolerates with its answers
//! unchanged, and from what jitter on the watchdogs stop it.
//!
//! The cases: stalls twice a second of a length drawn between half the longest and the longest,
//! on every link at once and on the RTDE inputs alone (the arm's commands); and the named profiles
//! ([`JitterProfile`]). Each case is run with each seed; the runs take turns (they run in real
//! time, and two side by side on a 2-core machine would starve each other's deadlines).

use super::{cell, write_csv};
use std::path::{Path, PathBuf};
use tendril_control::task::Phase;
use tendril_plot::jitter::{JitterRow, render};
use tendril_run::compare::{TOLERANCES, Tick, compare, first_disagreement};
use tendril_run::execute::run_on_twin;
use tendril_run::real::run_on_real;
use tendril_serve::jitter::Link;
use tendril_serve::{Jitter, JitterModel, JitterProfile, ServeConfig, start};

/// Stall rate of the swept cases [1/s]: the busy-PC profile's.
pub const STALL_RATE_HZ: f64 = 2.0;

/// One case: what is injected, where.
#[derive(Debug, Clone, PartialEq)]
pub struct JitterCase {
    /// `sweep` for a stall length of the sweep, else the profile's name.
    pub label: String,
    /// What is injected (`None`: nothing).
    pub model: Option<JitterModel>,
    /// Only this link (`None`: all).
    pub only: Option<Link>,
}

impl JitterCase {
    /// Stalls of `longest_ms` at most (half of it at least), twice a second.
    pub fn stalls(longest_ms: f64, only: Option<Link>) -> JitterCase {
        let longest_s = longest_ms * 1e-3;
        let model = (longest_ms > 0.0).then_some(JitterModel {
            stall_rate_hz: STALL_RATE_HZ,
            stall_s: (0.5 * longest_s, longest_s),
            latency_median_s: 0.0,
            latency_sigma: 0.0,
        });
        JitterCase { label: "sweep".into(), model, only }
    }

    /// A named profile on every link.
    pub fn profile(p: JitterProfile) -> JitterCase {
        let label = serde_json::to_value(p).ok().and_then(|v| v.as_str().map(str::to_string)).unwrap_or_default();
        JitterCase { label, model: p.model(), only: None }
    }

    /// The longest stall injected \[ms\] (the chart's x axis).
    pub fn longest_stall_ms(&self) -> f64 {
        self.model.map_or(0.0, |m| m.stall_s.1 * 1e3)
    }
}

/// The study's cases: the full plan, or a few for a quick look.
pub fn cases(quick: bool) -> Vec<JitterCase> {
    let (all, commands): (&[f64], &[f64]) = if quick {
        (&[0.0, 20.0, 100.0], &[])
    } else {
        (&[0.0, 10.0, 20.0, 40.0, 60.0, 80.0, 100.0, 120.0, 150.0, 200.0], &[20.0, 40.0, 60.0, 100.0, 150.0, 200.0])
    };
    let mut out: Vec<JitterCase> = all.iter().map(|&ms| JitterCase::stalls(ms, None)).collect();
    out.extend(commands.iter().map(|&ms| JitterCase::stalls(ms, Some(Link::RtdeIn))));
    let profiles: &[JitterProfile] = if quick {
        &[JitterProfile::BusyPc, JitterProfile::Wifi]
    } else {
        &[JitterProfile::Loopback, JitterProfile::BusyPc, JitterProfile::Wifi]
    };
    out.extend(profiles.iter().map(|&p| JitterCase::profile(p)));
    out
}

/// The phases compared: those of the short grasp-hold-lift.
const PHASES: [Phase; 4] = [Phase::Grow, Phase::Wrap, Phase::Grasp, Phase::Lift];

/// Runs every case with every seed on `scenario`, writes `jitter.csv` and its chart into `out`.
pub fn run(scenario: &Path, cases: &[JitterCase], seeds: &[u64], out: &Path) -> anyhow::Result<Vec<PathBuf>> {
    let s: tendril_run::scenario::PickPlaceScenario = tendril_config::load(scenario, &[])?;
    let (twin_summary, twin) = run_on_twin(&s, &Default::default(), None)?;
    anyhow::ensure!(twin.error.is_none(), "{}: the twin's run failed: {:?}", scenario.display(), twin.error);
    let twin: Vec<Tick> = twin.rows.iter().map(Tick::from).collect();
    let progress = indicatif::ProgressBar::new((cases.len() * seeds.len()) as u64);
    let mut rows = Vec::new();
    for case in cases {
        for &seed in seeds {
            let mut config = ServeConfig::ephemeral();
            config.jitter = case.model.map(|model| Jitter { model, seed, only: case.only });
            let serve = start(&s, &config)?;
            let cell = serve.real_cell_config().with_control_rate(s.control_rate_hz);
            let result = run_on_real(&s, cell, None);
            serve.stop().map_err(|e| anyhow::anyhow!("virtual devices: {e}"))?;
            let (summary, report) = result?;
            let real: Vec<Tick> = report.rows.iter().map(Tick::from).collect();
            let comparisons = compare(&twin, &real, &PHASES);
            let gap = |phase| comparisons.iter().find(|c| c.phase == phase).map_or(f64::INFINITY, |c| c.force_gap_n());
            let timing = summary.device_timing.unwrap_or_default();
            rows.push(JitterRow {
                case: case.label.clone(),
                link: case.only.map_or("all".to_string(), link_name),
                longest_stall_ms: case.longest_stall_ms(),
                seed,
                outcome: summary.outcome.clone(),
                watchdog: summary.error.as_deref().is_some_and(|e| e.contains("watchdog")),
                grasp_gap_n: gap(Phase::Grasp),
                lift_gap_n: gap(Phase::Lift),
                agrees: summary.error.is_none()
                    && summary.outcome == twin_summary.outcome
                    && first_disagreement(&comparisons, &TOLERANCES).is_none(),
                drop_alarms: summary.drop_alarms,
                tolerance_n: TOLERANCES.carry_n,
                oldest_sample_ms: timing.sensor_age.max_ms.max(timing.arm_age.max_ms).max(timing.motor_age.max_ms),
                error: summary.error.unwrap_or_default(),
            });
            progress.inc(1);
        }
    }
    progress.finish_and_clear();
    std::fs::create_dir_all(out).map_err(|e| anyhow::anyhow!("{}: {e}", out.display()))?;
    let csv = out.join("jitter.csv");
    let cells: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            vec![
                r.case.clone(),
                r.link.clone(),
                r.longest_stall_ms.to_string(),
                r.seed.to_string(),
                r.outcome.clone(),
                r.watchdog.to_string(),
                cell(r.grasp_gap_n.is_finite().then_some(r.grasp_gap_n)),
                cell(r.lift_gap_n.is_finite().then_some(r.lift_gap_n)),
                r.agrees.to_string(),
                r.drop_alarms.to_string(),
                r.tolerance_n.to_string(),
                r.oldest_sample_ms.to_string(),
                r.error.clone(),
            ]
        })
        .collect();
    let header = [
        "case",
        "link",
        "longest_stall_ms",
        "seed",
        "outcome",
        "watchdog",
        "grasp_gap_n",
        "lift_gap_n",
        "agrees",
        "drop_alarms",
        "tolerance_n",
        "oldest_sample_ms",
        "error",
    ];
    write_csv(&csv, &header, &cells)?;
    let mut files = vec![csv];
    files.extend(render(&rows, out)?);
    Ok(files)
}

/// A link's name as the command line spells it.
fn link_name(link: Link) -> String {
    serde_json::to_value(link).ok().and_then(|v| v.as_str().map(str::to_string)).unwrap_or_default()
}
