//! The simulated path against the real path, phase by phase: what "force estimates agree" means
//! in the real-path tests, whether the runs come from memory or from `trace.csv`.
//!
//! Tolerances: the real path's timing jitters (ticks land a fraction of a millisecond late, the
//! twin steps on its own clock), so traces are not identical; per phase, the median and the 5th
//! and 95th percentiles of the force estimate must agree within 0.1 N (a sixth of the 0.6 N
//! setpoint, about 40 times the sensor's 2.6 mN resolution) while the finger grows and wraps,
//! within 0.25 N in the grasp and 0.2 N (a third of the setpoint) in the lift, and phase durations
//! within 0.2 s. Those two are transients whose course moves with the tick timing. In the grasp
//! the coil can seat in one of two ways (the commands reach the twin's 5 ms physics steps at
//! whatever phase the two clocks have): the second way was seen in 1 of 15 runs on an idle machine
//! and 5 of 13 with both cores loaded, with the grasp's median at 0.50-0.54 N against 0.41 N and
//! its 95th percentile up to 0.175 N higher, while the lift that follows agreed within 0.05 N. In
//! the lift, the moment the object's weight comes off the table and the force transient after it
//! move (medians seen 0.10 N apart on a loaded 2-core machine, within 5 mN on an idle one). The
//! percentiles catch a grip that shakes: when the virtual arm still jumped to each streamed
//! target, the lift's force swung between 0.15 N and the sensor's 4.6 N limit (5th-95th
//! percentiles 0.15-2.2 N against the simulated run's 0.56-0.66 N) while its median stayed within
//! 0.05 N. Means and extremes are not compared: single spikes move with the jitter.
//!
//! The lift's 95th percentile has a tolerance of its own, 0.6 N. On the real path the force
//! sometimes makes a slow excursion in the lift: up to 0.25-0.55 N above the setpoint for about a
//! second, then back, while the median stays within 0.07 N of the simulated run's. It was seen in
//! 2 of 5 runs of the feedforward controller on an idle machine (95th percentile 0.84-0.88 N
//! against the twin's 0.62 N), and in 1 of 4 of the slip-margin controller with the prescribed arm
//! (1.11 N against 0.58 N). Its cause, like the grasp's second seating, lies in where the commands
//! fall against the twin's own steps, and is not established further. 0.6 N still catches the
//! shaking grip above (1.5 N off).

use tendril::run::runner::RunReport;

/// The phases the short grasp-hold-lift goes through, in order.
pub const PHASES: [&str; 4] = ["grow", "wrap", "grasp", "lift"];

/// Tolerance [N] on the force estimate's `percentile` (0.05, 0.5 or 0.95) in `phase` (module doc).
pub fn force_tolerance_n(phase: &str, percentile: f64) -> f64 {
    match phase {
        "grasp" => 0.25,
        "lift" if percentile > 0.9 => 0.6,
        "lift" => 0.2,
        _ => 0.1,
    }
}

/// Phase duration tolerance [s].
pub const DURATION_TOLERANCE_S: f64 = 0.2;

/// One control tick: its phase, cell time [s] and force estimate [N].
#[derive(Debug, Clone, PartialEq)]
pub struct Tick {
    /// Task phase name.
    pub phase: String,
    /// Cell time [s].
    pub time_s: f64,
    /// Force estimate [N].
    pub force_n: f64,
}

/// The ticks of a run in memory.
pub fn from_report(report: &RunReport) -> Vec<Tick> {
    report
        .rows
        .iter()
        .map(|r| Tick { phase: r.phase.name().to_string(), time_s: r.time_s, force_n: r.force_n })
        .collect()
}

/// The ticks of a run's `trace.csv`.
pub fn from_trace_csv(path: &std::path::Path) -> Vec<Tick> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("a header").split(',').collect();
    let col = |name: &str| header.iter().position(|c| *c == name).unwrap_or_else(|| panic!("no {name} column"));
    let (phase, time, force) = (col("phase"), col("time_s"), col("force_n"));
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            Tick { phase: f[phase].to_string(), time_s: f[time].parse().unwrap(), force_n: f[force].parse().unwrap() }
        })
        .collect()
}

/// What is compared of one phase.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhaseStats {
    /// 5th percentile, median and 95th percentile of the force estimate [N].
    pub force_n: [f64; 3],
    /// Duration [s].
    pub duration_s: f64,
}

/// The percentiles compared, with their names.
const PERCENTILES: [(f64, &str); 3] = [(0.05, "5th percentile"), (0.5, "median"), (0.95, "95th percentile")];

/// Force percentiles and duration of `phase`.
pub fn phase_stats(ticks: &[Tick], phase: &str) -> PhaseStats {
    let rows: Vec<&Tick> = ticks.iter().filter(|t| t.phase == phase).collect();
    assert!(!rows.is_empty(), "no {phase} rows");
    let mut forces: Vec<f64> = rows.iter().map(|t| t.force_n).collect();
    forces.sort_by(f64::total_cmp);
    let at = |p: f64| forces[((forces.len() - 1) as f64 * p).round() as usize];
    PhaseStats { force_n: PERCENTILES.map(|(p, _)| at(p)), duration_s: rows[rows.len() - 1].time_s - rows[0].time_s }
}

/// Every phase of [`PHASES`] reached on the real path, its force percentiles and duration within
/// the tolerances of the simulated run's; prints the figures.
pub fn assert_phases_agree(sim: &[Tick], real: &[Tick]) {
    for phase in PHASES {
        assert!(real.iter().any(|t| t.phase == phase), "real run never reached {phase}");
        let (s, r) = (phase_stats(sim, phase), phase_stats(real, phase));
        let (d_sim, d_real) = (s.duration_s, r.duration_s);
        eprintln!(
            "{phase}: force 5/50/95 % sim {:.3?} N real {:.3?} N; duration sim {d_sim:.2} s real {d_real:.2} s",
            s.force_n, r.force_n
        );
        for ((f_sim, f_real), (p, name)) in s.force_n.into_iter().zip(r.force_n).zip(PERCENTILES) {
            let tolerance_n = force_tolerance_n(phase, p);
            assert!(
                (f_sim - f_real).abs() < tolerance_n,
                "{phase}: force {name} sim {f_sim:.3} N, real {f_real:.3} N (tolerance {tolerance_n} N)"
            );
        }
        assert!(
            (d_sim - d_real).abs() < DURATION_TOLERANCE_S,
            "{phase}: duration sim {d_sim:.2} s, real {d_real:.2} s (tolerance {DURATION_TOLERANCE_S} s)"
        );
    }
}
