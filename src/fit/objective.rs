//! How far a simulated run is from a recording: the force trace's RMS error on the recording's
//! time base, plus soft terms for the drop time and phase.
//!
//! The force trace carries the fit: it changes smoothly with the parameters, where an outcome is a
//! step function of them (held or not). Ticks from the first drop of either run on are left out (a
//! falling object striking the strip is chaotic in any simulation and in the cell: its spikes would
//! make the objective rough); the drop time's error is a term of its own, in proportion to the
//! error, so a drop a little early or late costs a little.

use super::recording::{Events, Tick};
use crate::run::trace::TraceRow;
use serde::{Deserialize, Serialize};

/// The weights of the objective's terms (`[objective]` in FIT.toml).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Weights {
    /// Weight of the force trace's RMS error [1/N].
    pub force_rmse: f64,
    /// Weight of the drop-time error [1/s]; a run that holds counts as dropping at its end. 0.05:
    /// half a second (the validation's tolerance) costs 0.025, half the force error allowed.
    pub drop_time: f64,
    /// Cost of a different outcome or drop phase.
    pub drop_phase: f64,
    /// The task phases whose ticks the force error covers (default: from the grasp to the
    /// lowering, while the object is in the hand).
    pub phases: Vec<String>,
}

impl Default for Weights {
    fn default() -> Weights {
        Weights {
            force_rmse: 1.0,
            drop_time: 0.05,
            drop_phase: 0.05,
            phases: ["grasp", "lift", "transfer", "lower"].map(String::from).to_vec(),
        }
    }
}

/// Phase names a trace can hold.
pub const PHASES: [&str; 9] = ["home", "grow", "wrap", "grasp", "lift", "transfer", "lower", "release", "done"];

impl Weights {
    /// The first bad weight or phase, as (key, reason).
    pub fn check(&self) -> Option<(String, String)> {
        for (key, w) in
            [("force_rmse", self.force_rmse), ("drop_time", self.drop_time), ("drop_phase", self.drop_phase)]
        {
            if !(w.is_finite() && w >= 0.0) {
                return Some((format!("objective.{key}"), format!("must be a finite number >= 0, got {w}")));
            }
        }
        if self.force_rmse + self.drop_time + self.drop_phase <= 0.0 {
            return Some(("objective".into(), "every weight is 0: nothing to fit".into()));
        }
        if self.phases.is_empty() {
            return Some(("objective.phases".into(), "lists no phase".into()));
        }
        self.phases.iter().find(|p| !PHASES.contains(&p.as_str())).map(|p| {
            ("objective.phases".into(), format!("unknown phase `{p}` (expected one of {})", PHASES.join(", ")))
        })
    }
}

/// How a simulated run compares with its recording.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Residual {
    /// The recording's name.
    pub recording: String,
    /// RMS of simulated − recorded force over the compared ticks \[N\] (None: no tick compared).
    pub force_rmse_n: Option<f64>,
    /// Simulated − recorded drop time \[s\], a held run counting as dropping at its end (None:
    /// both held).
    pub drop_time_error_s: Option<f64>,
    /// Same outcome and drop phase.
    pub same_outcome: bool,
    /// The simulated run's outcome.
    pub outcome: String,
    /// The simulated run's drop phase.
    pub drop_phase: Option<String>,
    /// The simulated drop time after the arm started moving \[s\].
    pub drop_time_s: Option<f64>,
    /// This recording's part of the objective.
    pub score: f64,
}

/// Linear interpolation of the simulated force at `t` (held at the ends).
fn force_at(rows: &[TraceRow], t: f64) -> f64 {
    let i = rows.partition_point(|r| r.time_s < t);
    if i == 0 {
        return rows.first().map_or(f64::NAN, |r| r.force_n);
    }
    if i >= rows.len() {
        return rows.last().map_or(f64::NAN, |r| r.force_n);
    }
    let (a, b) = (&rows[i - 1], &rows[i]);
    let span = b.time_s - a.time_s;
    if span <= 0.0 { b.force_n } else { a.force_n + (b.force_n - a.force_n) * (t - a.time_s) / span }
}

/// RMS force error of `rows` against the recorded `ticks` in `phases` (by the recording's phase),
/// leaving out ticks from `first_drop_at` on.
pub fn force_rmse(ticks: &[Tick], rows: &[TraceRow], phases: &[String], first_drop_at: f64) -> Option<f64> {
    if rows.is_empty() {
        return None;
    }
    let (mut sum, mut n) = (0.0, 0usize);
    for t in ticks.iter().filter(|t| t.time_s < first_drop_at && phases.iter().any(|p| *p == t.phase)) {
        let d = force_at(rows, t.time_s) - t.force_n;
        if d.is_finite() {
            sum += d * d;
            n += 1;
        }
    }
    (n > 0).then(|| (sum / n as f64).sqrt())
}

/// Compares a simulated run (`rows`, `events`) with a recording (`ticks`, `recorded`).
pub fn compare(
    name: &str,
    ticks: &[Tick],
    recorded: &Events,
    rows: &[TraceRow],
    events: &Events,
    w: &Weights,
) -> Residual {
    let first_drop_at =
        [recorded.drop_cell_time_s, events.drop_cell_time_s].into_iter().flatten().fold(f64::INFINITY, f64::min);
    let rmse = force_rmse(ticks, rows, &w.phases, first_drop_at);
    let drop_time_error_s = match (recorded.drop_cell_time_s, events.drop_cell_time_s) {
        (None, None) => None,
        (a, b) => Some(b.unwrap_or(events.sim_time_s) - a.unwrap_or(recorded.sim_time_s)),
    };
    let same_outcome = recorded.outcome == events.outcome && recorded.drop_phase == events.drop_phase;
    // A run with nothing to compare scores as the recording's RMS force (as if it read zero).
    let rmse_term = rmse.unwrap_or_else(|| {
        (ticks.iter().map(|t| t.force_n * t.force_n).sum::<f64>() / ticks.len().max(1) as f64).sqrt()
    });
    let score = w.force_rmse * rmse_term
        + w.drop_time * drop_time_error_s.map_or(0.0, f64::abs)
        + w.drop_phase * f64::from(u8::from(!same_outcome));
    Residual {
        recording: name.into(),
        force_rmse_n: rmse,
        drop_time_error_s,
        same_outcome,
        outcome: events.outcome.clone(),
        drop_phase: events.drop_phase.clone(),
        drop_time_s: events.drop_time_s,
        score,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::task::Phase;

    fn row(t: f64, f: f64) -> TraceRow {
        TraceRow {
            time_s: t,
            phase: Phase::Grasp,
            true_force_n: f,
            fbg1_nm: 0.0,
            fbg2_nm: 0.0,
            force_n: f,
            force_uncompensated_n: f,
            over_range: false,
            setpoint_n: 0.6,
            controller_on: true,
            controller_output_deg_s: 0.0,
            growth_motor_rad: 0.0,
            twine_motor_rad: 0.0,
            object_height_m: 0.0,
            slip_speed_m_s: 0.0,
            grip_force_n: 0.0,
        }
    }

    fn tick(t: f64, f: f64, phase: &str) -> Tick {
        Tick { time_s: t, phase: phase.into(), force_n: f }
    }

    fn held(end: f64) -> Events {
        Events { outcome: "held".into(), drop_cell_time_s: None, drop_time_s: None, drop_phase: None, sim_time_s: end }
    }

    #[test]
    fn rmse_interpolates_and_keeps_to_the_phases() {
        let rows = [row(0.0, 0.0), row(1.0, 1.0), row(2.0, 1.0)];
        let ticks = [tick(0.5, 0.5, "grasp"), tick(1.5, 2.0, "grasp"), tick(1.8, 100.0, "home")];
        let phases = vec!["grasp".to_string()];
        let r = force_rmse(&ticks, &rows, &phases, f64::INFINITY).unwrap();
        assert!((r - (0.5f64).sqrt()).abs() < 1e-12, "{r}");
        assert_eq!(force_rmse(&ticks, &rows, &phases, 0.1), None);
    }

    #[test]
    fn identical_runs_score_zero_and_a_late_drop_costs_in_proportion() {
        let w = Weights::default();
        let rows: Vec<TraceRow> = (0..100).map(|i| row(f64::from(i) * 0.1, 0.6)).collect();
        let ticks: Vec<Tick> = rows.iter().map(|r| tick(r.time_s, r.force_n, "grasp")).collect();
        let r = compare("a", &ticks, &held(9.9), &rows, &held(9.9), &w);
        assert_eq!((r.score, r.same_outcome, r.drop_time_error_s), (0.0, true, None));
        let dropped = |t: f64| Events {
            outcome: "dropped".into(),
            drop_cell_time_s: Some(t),
            drop_time_s: Some(t - 1.0),
            drop_phase: Some("lift".into()),
            sim_time_s: 9.9,
        };
        let a = compare("a", &ticks, &dropped(5.0), &rows, &dropped(5.5), &w);
        let b = compare("a", &ticks, &dropped(5.0), &rows, &dropped(7.0), &w);
        assert!(a.same_outcome && a.score > 0.0 && b.score > a.score, "{a:?} {b:?}");
        assert!((b.drop_time_error_s.unwrap() - 2.0).abs() < 1e-12);
    }

    #[test]
    fn bad_weights_are_named() {
        let mut w = Weights { drop_time: -1.0, ..Weights::default() };
        assert_eq!(w.check().unwrap().0, "objective.drop_time");
        w.drop_time = 0.0;
        w.phases = vec!["liftt".into()];
        assert!(w.check().unwrap().1.contains("liftt"));
    }
}
