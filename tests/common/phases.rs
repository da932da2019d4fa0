//! The simulated path against the real path, phase by phase, whether the runs come from memory or
//! from `trace.csv`: the library's comparison (`tendril_run::compare`, where the tolerances and
//! the measurements behind them are) with the assertions the real-path tests make.

use tendril_control::task::Phase;
use tendril_run::compare::{TOLERANCES, Tick, compare, describe, first_disagreement};
use tendril_run::runner::RunReport;

/// The phases the short grasp-hold-lift goes through, in order.
pub const PHASES: [Phase; 4] = [Phase::Grow, Phase::Wrap, Phase::Grasp, Phase::Lift];

/// The ticks of a run in memory.
pub fn from_report(report: &RunReport) -> Vec<Tick> {
    report.rows.iter().map(Tick::from).collect()
}

/// The ticks of a run's `trace.csv`.
pub fn from_trace_csv(path: &std::path::Path) -> Vec<Tick> {
    from_trace_csv_column(path, "force_n")
}

/// The ticks of a run's `trace.csv` with `column` as the force (`pad1_force_n`: a sensor array's
/// further pad's estimate).
pub fn from_trace_csv_column(path: &std::path::Path, column: &str) -> Vec<Tick> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("a header").split(',').collect();
    let col = |name: &str| header.iter().position(|c| *c == name).unwrap_or_else(|| panic!("no {name} column"));
    let (phase, time, force) = (col("phase"), col("time_s"), col(column));
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            Tick {
                phase: serde_json::from_value(serde_json::Value::String(f[phase].into())).expect("a phase name"),
                time_s: f[time].parse().unwrap(),
                force_n: f[force].parse().unwrap(),
            }
        })
        .collect()
}

/// Why the real run does not agree with the simulated one within the tolerances, if it does not;
/// prints both runs' figures.
pub fn disagreement(sim: &[Tick], real: &[Tick]) -> Option<String> {
    let comparisons = compare(sim, real, &PHASES);
    eprint!("{}", describe(&comparisons));
    assert_eq!(comparisons.len(), PHASES.len(), "the simulated run went through every phase");
    first_disagreement(&comparisons, &TOLERANCES)
}

/// Every phase of [`PHASES`] reached on the real path, its force percentiles and duration within
/// the tolerances of the simulated run's.
pub fn assert_phases_agree(sim: &[Tick], real: &[Tick]) {
    if let Some(why) = disagreement(sim, real) {
        panic!("{why}");
    }
}
