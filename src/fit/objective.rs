//! How far a simulated run is from a recording: the force trace's RMS error on the recording's
//! time base, plus soft terms for the drop time and phase.
//!
//! The force trace and the twine motor's position carry the fit. The motor's position is what the
//! force controller wound in to hold the setpoint: with feedback on it records the tendon path's
//! stiffness (its level) and creep (its slope over the hold) where the force, held at the setpoint,
//! shows neither. The force trace changes smoothly with the parameters, where an outcome is a
//! step function of them (held or not). Two things keep the objective smooth:
//! - the traces are compared after a moving average (`smooth_s`, 0.5 s): contacts make the twin,
//!   like the cell, chaotic at the scale of ticks (a relaxation time changed by 1e-5 relative moves
//!   the stick-slip jitter and gives a tick-by-tick RMS error of 0.01-0.15 N), while the slow
//!   shape (the rise, the creep of a frozen grip) is what the parameters set;
//! - ticks from `drop_margin_s` before the first drop of either run on are left out (a slipping,
//!   then falling object striking the strip is chaotic in any simulation and in the cell); the drop
//!   time's error is a term of its own, in proportion, so a drop a little early or late costs a
//!   little.

use super::recording::{Events, Tick};
use serde::{Deserialize, Serialize};
use tendril_run::trace::TraceRow;

/// The weights of the objective's terms (`[objective]` in FIT.toml).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Weights {
    /// Weight of the force trace's RMS error [1/N].
    pub force_rmse: f64,
    /// Weight of the twine motor position's RMS error [1/rad]. 2: the contacts' chaos moves it by
    /// ≈ 0.004 rad (0.008), a tendon stiffness 10 % off by ≈ 0.04 rad (0.08).
    pub twine_motor: f64,
    /// Weight of the drop-time error [1/s]; a run that holds counts as dropping at its end. 0.05:
    /// half a second (the validation's tolerance) costs 0.025, half the force error allowed.
    pub drop_time: f64,
    /// Cost of a different outcome or drop phase.
    pub drop_phase: f64,
    /// The task phases whose ticks the force error covers (default: from the grasp to the
    /// lowering, while the object is in the hand).
    pub phases: Vec<String>,
    /// Width of the moving average both traces are compared through \[s\] (0: tick by tick).
    pub smooth_s: f64,
    /// Ticks this long before the first drop of either run, and after it, are not compared \[s\].
    pub drop_margin_s: f64,
}

impl Default for Weights {
    fn default() -> Weights {
        Weights {
            force_rmse: 1.0,
            twine_motor: 2.0,
            drop_time: 0.05,
            drop_phase: 0.05,
            phases: ["grasp", "lift", "transfer", "lower"].map(String::from).to_vec(),
            smooth_s: 0.5,
            drop_margin_s: 1.0,
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
        if self.force_rmse + self.twine_motor + self.drop_time + self.drop_phase <= 0.0 {
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
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Residual {
    /// The recording's name.
    pub recording: String,
    /// RMS of simulated − recorded force over the compared ticks, tick by tick \[N\] (None: no
    /// tick compared).
    pub force_rmse_n: Option<f64>,
    /// The same through the moving average (what the objective uses) \[N\].
    pub smoothed_rmse_n: Option<f64>,
    /// RMS of simulated − recorded twine motor position over the same ticks \[rad\].
    pub twine_motor_rmse_rad: Option<f64>,
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

/// Linear interpolation of a simulated column (`value`) at `t` (held at the ends).
fn value_at(rows: &[TraceRow], t: f64, value: fn(&TraceRow) -> f64) -> f64 {
    let i = rows.partition_point(|r| r.time_s < t);
    if i == 0 {
        return rows.first().map_or(f64::NAN, value);
    }
    if i >= rows.len() {
        return rows.last().map_or(f64::NAN, value);
    }
    let (a, b) = (value(&rows[i - 1]), value(&rows[i]));
    let (ta, tb) = (rows[i - 1].time_s, rows[i].time_s);
    if tb - ta <= 0.0 { b } else { a + (b - a) * (t - ta) / (tb - ta) }
}

/// The RMS force error of `rows` against the recorded `ticks` in `phases` (by the recording's
/// phase) before `until` \[s\]: tick by tick, and through a centred moving average `window` ticks
/// wide. None when no tick is compared.
pub fn force_rmse(
    ticks: &[Tick],
    rows: &[TraceRow],
    phases: &[String],
    until: f64,
    window: usize,
) -> Option<(f64, f64)> {
    trace_rmse(ticks, rows, phases, until, window, |t| t.force_n, |r| r.force_n)
}

/// As [`force_rmse`], for the column `recorded` reads from a tick and `simulated` from a row.
pub fn trace_rmse(
    ticks: &[Tick],
    rows: &[TraceRow],
    phases: &[String],
    until: f64,
    window: usize,
    recorded: fn(&Tick) -> f64,
    simulated: fn(&TraceRow) -> f64,
) -> Option<(f64, f64)> {
    if rows.is_empty() {
        return None;
    }
    let pairs: Vec<(f64, f64)> = ticks
        .iter()
        .filter(|t| t.time_s < until && phases.contains(&t.phase))
        .map(|t| (recorded(t), value_at(rows, t.time_s, simulated)))
        .filter(|(a, b)| a.is_finite() && b.is_finite())
        .collect();
    if pairs.is_empty() {
        return None;
    }
    let rms = |d: &mut dyn Iterator<Item = f64>| {
        let (s, n) = d.fold((0.0, 0usize), |(s, n), d| (s + d * d, n + 1));
        (s / n.max(1) as f64).sqrt()
    };
    let raw = rms(&mut pairs.iter().map(|(a, b)| b - a));
    let diffs: Vec<f64> = pairs.iter().map(|(a, b)| b - a).collect();
    let smoothed = rms(&mut moving_average(&diffs, window).into_iter());
    Some((raw, smoothed))
}

/// Centred moving average over `window` samples (shorter at the ends), the calibration's
/// [`smooth`](tendril_fbg::calibration::smooth) over `window / 2` each side; `window` ≤ 1 copies.
fn moving_average(x: &[f64], window: usize) -> Vec<f64> {
    if window <= 1 { x.to_vec() } else { tendril_fbg::calibration::smooth(x, window / 2) }
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
    let dt = ticks.windows(2).next().map_or(0.01, |p| (p[1].time_s - p[0].time_s).max(1e-6));
    let window = (w.smooth_s / dt).round() as usize;
    let rmse = force_rmse(ticks, rows, &w.phases, first_drop_at - w.drop_margin_s, window);
    let motor = trace_rmse(
        ticks,
        rows,
        &w.phases,
        first_drop_at - w.drop_margin_s,
        1,
        |t| t.twine_motor_rad,
        |r| r.twine_motor_rad,
    )
    .map(|m| m.0);
    let drop_time_error_s = match (recorded.drop_cell_time_s, events.drop_cell_time_s) {
        (None, None) => None,
        (a, b) => Some(b.unwrap_or(events.sim_time_s) - a.unwrap_or(recorded.sim_time_s)),
    };
    let same_outcome = recorded.outcome == events.outcome && recorded.drop_phase == events.drop_phase;
    // A run with nothing to compare scores as the recording's RMS force (as if it read zero).
    let rmse_term = rmse.map(|r| r.1).unwrap_or_else(|| {
        (ticks.iter().map(|t| t.force_n * t.force_n).sum::<f64>() / ticks.len().max(1) as f64).sqrt()
    });
    let score = w.force_rmse * rmse_term
        + w.twine_motor * motor.unwrap_or(0.0)
        + w.drop_time * drop_time_error_s.map_or(0.0, f64::abs)
        + w.drop_phase * f64::from(u8::from(!same_outcome));
    Residual {
        recording: name.into(),
        force_rmse_n: rmse.map(|r| r.0),
        smoothed_rmse_n: rmse.map(|r| r.1),
        twine_motor_rmse_rad: motor,
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
    use tendril_control::task::Phase;

    fn row(t: f64, f: f64) -> TraceRow {
        TraceRow::at(t, Phase::Grasp, f)
    }

    fn tick(t: f64, f: f64, phase: &str) -> Tick {
        Tick { time_s: t, phase: phase.into(), force_n: f, twine_motor_rad: 0.0 }
    }

    fn held(end: f64) -> Events {
        Events { outcome: "held".into(), drop_cell_time_s: None, drop_time_s: None, drop_phase: None, sim_time_s: end }
    }

    #[test]
    fn rmse_interpolates_and_keeps_to_the_phases() {
        let rows = [row(0.0, 0.0), row(1.0, 1.0), row(2.0, 1.0)];
        let ticks = [tick(0.5, 0.5, "grasp"), tick(1.5, 2.0, "grasp"), tick(1.8, 100.0, "home")];
        let phases = vec!["grasp".to_string()];
        let (r, s) = force_rmse(&ticks, &rows, &phases, f64::INFINITY, 1).unwrap();
        assert!((r - (0.5f64).sqrt()).abs() < 1e-12, "{r}");
        assert_eq!(r, s);
        assert_eq!(force_rmse(&ticks, &rows, &phases, 0.1, 1), None);
        // A jitter of alternating sign averages out; an offset does not.
        let jitter = [0.1, -0.1, 0.1, -0.1, 0.1, -0.1];
        assert!(moving_average(&jitter, 2).iter().all(|v| v.abs() < 0.05));
        assert!(moving_average(&[0.2; 6], 4).iter().all(|v| (v - 0.2).abs() < 1e-12));
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
