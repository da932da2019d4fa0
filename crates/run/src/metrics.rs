//! The figures the paper reports for a pick-and-place run, computed from the tick records.

use super::trace::TraceRow;
use serde::{Deserialize, Serialize};
use tendril_control::task::Phase;
use tendril_twin::disturbance::PushConfig;

/// Closed-loop figures of one run (all from the sensor's estimate, as the paper measures).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct ControlMetrics {
    /// Time from the start of force control to the first estimate ≥ 90 % of the setpoint, read
    /// through a [`SPIKE_FILTER_TICKS`] median so that a one-tick impact does not count \[s\].
    pub rise_time_90_s: Option<f64>,
    /// Largest estimate above the setpoint during the grasp (through the same median), in % of the
    /// setpoint (0 if none).
    pub overshoot_pct: f64,
    /// Largest |F − setpoint| / setpoint while the arm moves [%] (None when nothing was held).
    pub max_fluctuation_pct: Option<f64>,
    /// As `max_fluctuation_pct`, leaving out a push on the object (`[disturbance.push]`), the
    /// [`PUSH_IMPACT_S`] after it and the object set down on the table early
    /// ([`SET_DOWN_HEIGHT_M`]) [%]: how well the grip holds the setpoint once the knock's impact
    /// has passed through the pad. Equal to `max_fluctuation_pct` without a push.
    #[serde(default)]
    pub max_fluctuation_outside_push_pct: Option<f64>,
    /// Smallest estimate while the arm moves \[N\].
    pub min_moving_force_n: Option<f64>,
    /// RMS of estimate − true force from the grasp to the release \[N\] (None without ground truth).
    pub force_rmse_n: Option<f64>,
    /// Whether the loop oscillates on its own: during the grasp (arm still), after first
    /// reaching 90 % of the setpoint, the estimate swings across a ±10 % band around the
    /// setpoint at least [`OSCILLATION_SWINGS`] times.
    pub oscillating: bool,
    /// Largest estimate from the start of the grasp to the release (or the drop), through the
    /// same [`SPIKE_FILTER_TICKS`] median as the overshoot so that the pad's first-touch impact
    /// does not count \[N\] (None when nothing was grasped). How hard the object was squeezed.
    #[serde(default)]
    pub peak_force_n: Option<f64>,
}

/// Swings across the ±10 % band that make a grasp count as oscillating: two full periods.
pub const OSCILLATION_SWINGS: usize = 4;

/// Counts alternations between above +10 % and below −10 % of the setpoint.
fn band_swings(rows: &[&TraceRow]) -> usize {
    let mut last: Option<bool> = None;
    let mut swings = 0;
    for r in rows {
        let side = if r.controlled_n() > 1.1 * r.setpoint_n {
            Some(true)
        } else if r.controlled_n() < 0.9 * r.setpoint_n {
            Some(false)
        } else {
            None
        };
        if let Some(side) = side {
            if last.is_some_and(|l| l != side) {
                swings += 1;
            }
            last = Some(side);
        }
    }
    swings
}

/// Width of the median filter the rise time and the overshoot are read through \[control
/// ticks\]: five (50 ms at 100 Hz), which removes any excursion of one or two ticks. The pad's first
/// touch can be an impact: the strip, already wrapped and tight, snaps the pad onto the object and
/// one sample reads several times the setpoint before the force falls back near zero (seen at 16
/// and 32 links: 3.8 N for one tick on a 0.8 N setpoint). That sample is not the controller's rise,
/// and counting it made the rise time 0 s on a finer finger and 3-4 s on the default one. A median,
/// unlike a minimum over a window, still crosses a level where the noisy signal does, so a slow
/// approach is timed as before.
pub const SPIKE_FILTER_TICKS: usize = 5;

/// The rows' estimates through [`despiked`].
fn despiked_force(rows: &[&TraceRow]) -> Vec<f64> {
    despiked(&rows.iter().map(|r| r.controlled_n()).collect::<Vec<_>>())
}

/// A signal sampled once per control tick through a centred running median of
/// [`SPIKE_FILTER_TICKS`] (shorter at the ends): one- and two-tick impacts removed, levels and
/// crossings kept.
pub fn despiked(values: &[f64]) -> Vec<f64> {
    let half = SPIKE_FILTER_TICKS / 2;
    (0..values.len())
        .map(|i| {
            let mut w = values[i.saturating_sub(half)..(i + half + 1).min(values.len())].to_vec();
            w.sort_by(f64::total_cmp);
            w[w.len() / 2]
        })
        .collect()
}

/// What [`ControlMetrics::max_fluctuation_outside_push_pct`] leaves out after a push ends \[s\].
/// A stated choice, from the knocked hammer's trace (PID, seed 1, 0.3 N·s over 20 ms 1 s into the
/// transfer, the arm at the paper's limits): the impact rings through the wrap for about 0.7 s
/// (the pad reads 1.0-3.4 N on a 1.6 N setpoint), then the estimate stays in the band the
/// controller works in (1.2-1.5 N, the hammer re-seated lower in the grip). Leaving out 0.5 /
/// 0.75 / 1.0 / 1.5 / 2.0 s gives 37 / 25 / 20.4 / 20.4 / 20.4 %: from 1 s on the figure is the
/// controller's answer to the changed grip, which the metric is meant to show.
pub const PUSH_IMPACT_S: f64 = 1.0;

/// Height above its resting place on the table below which an object counts as set down \[m\]
/// (2 mm: resting, or touching down within a tick at the lowering's speed). A knocked object
/// slides down the grip (the hammer by 15-18 mm where it is held) and the lowering, planned for
/// the object where it was, then sets it on the table early: the table pushes it into the pad
/// (the hammer's estimate 4.6 N on a 1.6 N setpoint, 190 %, on the whole-link default). That
/// reading is the table's, not the grip's.
pub const SET_DOWN_HEIGHT_M: f64 = 0.002;

/// Largest |F − setpoint| / setpoint \[%\] over the ticks the arm moves and `counts` accepts;
/// `None` when the object was dropped (`drop_time_s`) or no such tick exists.
pub fn max_fluctuation_pct(
    rows: &[TraceRow],
    drop_time_s: Option<f64>,
    counts: impl Fn(&TraceRow) -> bool,
) -> Option<f64> {
    let moving: Vec<&TraceRow> = rows.iter().filter(|r| r.phase.arm_moving() && counts(r)).collect();
    (drop_time_s.is_none() && !moving.is_empty()).then(|| {
        moving.iter().map(|r| 100.0 * (r.controlled_n() - r.setpoint_n).abs() / r.setpoint_n).fold(0.0, f64::max)
    })
}

/// [`ControlMetrics::max_fluctuation_outside_push_pct`] for a run pushed by `push`: the ticks from
/// the push's onset (its time, or the first tick of its phase plus the offset) to
/// [`PUSH_IMPACT_S`] after it ends are left out, and so are those with the object set down on the
/// table ([`SET_DOWN_HEIGHT_M`]; known on the twin only: on the real cell they stay in). A push
/// whose phase never came leaves out only the latter.
pub fn fluctuation_outside_push_pct(rows: &[TraceRow], drop_time_s: Option<f64>, push: &PushConfig) -> Option<f64> {
    let onset = push.onset().resolve(|phase| rows.iter().find(|r| r.phase == phase).map(|r| r.time_s));
    let impact = onset.map(|t| (t, t + push.duration_s + PUSH_IMPACT_S));
    let outside_impact = |r: &TraceRow| impact.is_none_or(|(from, to)| r.time_s < from || r.time_s >= to);
    let set_down = |r: &TraceRow| r.object_height_m < SET_DOWN_HEIGHT_M;
    max_fluctuation_pct(rows, drop_time_s, |r| outside_impact(r) && !set_down(r))
}

/// Computes [`ControlMetrics`] from a run's rows. `drop_time_s` bounds the moving window: ticks
/// after a drop do not count as fluctuation.
pub fn control_metrics(rows: &[TraceRow], drop_time_s: Option<f64>) -> ControlMetrics {
    let grasp: Vec<&TraceRow> = rows.iter().filter(|r| r.phase == Phase::Grasp).collect();
    let despiked = despiked_force(&grasp);
    let rise_time_90_s = grasp.first().and_then(|start| {
        grasp.iter().zip(&despiked).find(|(r, f)| **f >= 0.9 * r.setpoint_n).map(|(r, _)| r.time_s - start.time_s)
    });
    let overshoot_pct =
        grasp.iter().zip(&despiked).map(|(r, f)| 100.0 * (f - r.setpoint_n) / r.setpoint_n).fold(0.0, f64::max);
    let moving: Vec<&TraceRow> =
        rows.iter().filter(|r| r.phase.arm_moving() && drop_time_s.is_none_or(|d| r.time_s < d)).collect();
    let max_fluctuation_pct = max_fluctuation_pct(rows, drop_time_s, |_| true);
    let min_moving_force_n = moving.iter().map(|r| r.controlled_n()).reduce(f64::min);
    let compared: Vec<f64> = rows
        .iter()
        .filter(|r| r.phase.holding() && r.true_force_n.is_finite())
        .map(|r| (r.force_n - r.true_force_n).powi(2))
        .collect();
    let force_rmse_n = (!compared.is_empty()).then(|| (compared.iter().sum::<f64>() / compared.len() as f64).sqrt());
    let settled: Vec<&TraceRow> = grasp.iter().copied().skip_while(|r| r.controlled_n() < 0.9 * r.setpoint_n).collect();
    let oscillating = band_swings(&settled) >= OSCILLATION_SWINGS;
    let held: Vec<&TraceRow> =
        rows.iter().filter(|r| r.phase.holding() && drop_time_s.is_none_or(|d| r.time_s < d)).collect();
    let peak_force_n = despiked_force(&held).into_iter().reduce(f64::max);
    ControlMetrics {
        rise_time_90_s,
        overshoot_pct,
        max_fluctuation_pct,
        // The rows do not say where a push was: `run_on_cell`, which knows the scenario, narrows it.
        max_fluctuation_outside_push_pct: max_fluctuation_pct,
        min_moving_force_n,
        force_rmse_n,
        oscillating,
        peak_force_n,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fluctuation_outside_a_push_leaves_out_its_impact_and_no_more() {
        // Transfer from 10 s, every 0.1 s: on the setpoint but for a spike of +200 % at 11.1 s
        // (the push, 1 s into the transfer) and +30 % at 12.5 s (after the impact window).
        let rows: Vec<TraceRow> = (0..40)
            .map(|k| {
                let t = 10.0 + 0.1 * k as f64;
                let f = if k == 11 {
                    3.0
                } else if k == 25 {
                    1.3
                } else {
                    1.0
                };
                TraceRow { object_height_m: 0.1, ..row(t, Phase::Transfer, f) }
            })
            .collect();
        let push: PushConfig = toml::from_str("impulse_n_s = 0.3\nphase = \"transfer\"\noffset_s = 1.0").unwrap();
        assert!((max_fluctuation_pct(&rows, None, |_| true).unwrap() - 200.0).abs() < 1e-9);
        let outside = fluctuation_outside_push_pct(&rows, None, &push).unwrap();
        assert!((outside - 30.0).abs() < 1e-9, "the 200 % impact left out, the 30 % after it kept: {outside}");
        // Set down on the table at 13.0 s and pushed into the pad there: left out too.
        let mut landed = rows.clone();
        landed[30].force_n = 2.5;
        landed[30].object_height_m = 0.001;
        assert!((fluctuation_outside_push_pct(&landed, None, &push).unwrap() - 30.0).abs() < 1e-9);
        // A push whose phase never came leaves out no impact; a dropped run has no fluctuation.
        let lowering: PushConfig = toml::from_str("impulse_n_s = 0.3\nphase = \"lower\"").unwrap();
        assert!((fluctuation_outside_push_pct(&rows, None, &lowering).unwrap() - 200.0).abs() < 1e-9);
        assert_eq!(fluctuation_outside_push_pct(&rows, Some(12.5), &push), None);
    }

    fn row(t: f64, phase: Phase, force: f64) -> TraceRow {
        TraceRow { true_force_n: force + 0.01, setpoint_n: 1.0, ..TraceRow::at(t, phase, force) }
    }

    #[test]
    fn metrics_of_a_known_trace() {
        let mut rows = vec![];
        for i in 0..100 {
            let t = 10.0 + i as f64 * 0.1;
            // Reaches 0.9 at 4.5 s and peaks at 1.98 on the last sample, which the median, whose
            // window is cut short at the end, reads as the one before (1.96).
            rows.push(row(t, Phase::Grasp, (t - 10.0) * 0.2));
        }
        rows.push(row(20.0, Phase::Lift, 0.75));
        rows.push(row(20.1, Phase::Lift, 1.2));
        let m = control_metrics(&rows, None);
        assert!((m.rise_time_90_s.unwrap() - 4.5).abs() < 1e-9);
        assert!((m.overshoot_pct - 96.0).abs() < 1e-6);
        assert!((m.max_fluctuation_pct.unwrap() - 25.0).abs() < 1e-9);
        assert!((m.force_rmse_n.unwrap() - 0.01).abs() < 1e-9);
        assert_eq!(control_metrics(&rows, Some(20.05)).max_fluctuation_pct, None);
        assert!(!m.oscillating);
        // Over the grasp and the lift together: the single-tick 1.98 never passes the median; the
        // window of the lift's first sample (cut to four at the trace's end: 1.96, 1.98, 0.75,
        // 1.2) takes its upper middle, 1.96, the peak.
        assert!((m.peak_force_n.unwrap() - 1.96).abs() < 1e-9, "{:?}", m.peak_force_n);
        assert_eq!(control_metrics(&[], None).peak_force_n, None);
    }

    #[test]
    fn a_one_tick_impact_at_first_touch_is_not_the_rise() {
        // The pad snaps on (one sample at 3.8 x the setpoint), falls back, then the loop rises
        // linearly from 0.1 to 1.0 over 2 s.
        let mut rows = vec![row(0.0, Phase::Grasp, 3.8)];
        rows.extend((1..=300).map(|i| {
            let t = i as f64 * 0.01;
            row(t, Phase::Grasp, (0.1 + 0.45 * t).min(1.0))
        }));
        let m = control_metrics(&rows, None);
        // 0.9 is reached at t = 16/9 s; the spike neither ends the rise nor counts as overshoot.
        assert!((m.rise_time_90_s.unwrap() - 1.78).abs() < 0.011, "{:?}", m.rise_time_90_s);
        assert_eq!(m.overshoot_pct, 0.0);
    }

    #[test]
    fn a_grasp_swinging_across_the_band_oscillates() {
        let swinging: Vec<TraceRow> =
            (0..500).map(|i| row(i as f64 * 0.01, Phase::Grasp, 1.0 + 0.3 * (i as f64 * 0.1).sin())).collect();
        assert!(control_metrics(&swinging, None).oscillating);
        let damped: Vec<TraceRow> = (0..500)
            .map(|i| {
                let t = i as f64 * 0.01;
                row(t, Phase::Grasp, 1.0 + 0.3 * (-t).exp() * (t * 10.0).sin())
            })
            .collect();
        assert!(!control_metrics(&damped, None).oscillating);
    }
}
