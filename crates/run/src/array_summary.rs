//! What a run with a sensor array reports of it (`summary.json`'s `array`): each pad's figures
//! and the array's slip cue judged against the true drop.

use super::metrics::despiked;
use super::trace::TraceRow;
use serde::{Deserialize, Serialize};
use tendril_control::slip::judge;

/// One pad's figures over the run's holding phases (grasp to lowering, up to a drop).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct PadFigures {
    /// The pad (0: the paper's).
    pub pad: usize,
    /// Mean true force on the pad while holding \[N\] (`None` without ground truth).
    pub mean_true_n: Option<f64>,
    /// Largest estimate while holding, single-tick spikes removed \[N\].
    pub peak_n: Option<f64>,
    /// Estimate error against the true force while holding, RMS \[N\] (`None` without ground truth).
    pub estimate_rmse_n: Option<f64>,
    /// Share of the holding ticks whose true force was beyond the sensor's range [%]: the pad
    /// bottomed out and read its range, whatever the force.
    pub over_range_pct: Option<f64>,
}

/// The array's part of a run's summary.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct ArraySummary {
    /// Each pad's figures, pad 0 first (`pad_figures`, not `pads`: a sweep over `array.pads`
    /// has a column of that name).
    pub pad_figures: Vec<PadFigures>,
    /// Alarm episodes of the array's slip cue.
    pub cue_alarms: u64,
    /// The cue's first alarm, from the start of the arm's motion \[s\].
    pub cue_first_alarm_s: Option<f64>,
    /// From the true drop to the cue's first alarm at most `slip::EARLY_S` before it \[s\]
    /// (negative: the cue came first).
    pub cue_detection_delay_s: Option<f64>,
    /// Cue alarms no drop followed (`None` without ground truth).
    pub cue_false_alarms: Option<u64>,
    /// When the run acted on the cue (`array.retighten_factor`), from the start of the motion \[s\].
    pub retightened_s: Option<f64>,
}

/// The run's array summary from its rows (which carry every pad), the cue's alarm times, the drop
/// (cell time), the start of the motion and the sensor's range \[N\].
pub fn summarise(
    rows: &[TraceRow],
    cue_alarms_s: &[f64],
    retightened_at_s: Option<f64>,
    drop_s: Option<f64>,
    motion_start_s: Option<f64>,
    range_n: f64,
) -> ArraySummary {
    let held: Vec<&TraceRow> =
        rows.iter().filter(|r| r.phase.holding() && drop_s.is_none_or(|d| r.time_s < d)).collect();
    let has_truth = held.first().is_some_and(|r| r.true_force_n.is_finite());
    let pads = rows.first().map_or(0, |r| r.array.pads.len());
    let figures = (0..=pads)
        .map(|k| {
            let (truth, estimate): (Vec<f64>, Vec<f64>) = held
                .iter()
                .map(|r| match k {
                    0 => (r.true_force_n, r.force_n),
                    _ => {
                        let p = r.array.pads.as_slice()[k - 1];
                        (p.true_force_n, p.force_n)
                    }
                })
                .unzip();
            let n = truth.len() as f64;
            let known = has_truth && !truth.is_empty();
            PadFigures {
                pad: k,
                mean_true_n: known.then(|| truth.iter().sum::<f64>() / n),
                peak_n: despiked(&estimate).into_iter().reduce(f64::max),
                estimate_rmse_n: known
                    .then(|| (truth.iter().zip(&estimate).map(|(t, e)| (e - t).powi(2)).sum::<f64>() / n).sqrt()),
                over_range_pct: known.then(|| 100.0 * truth.iter().filter(|&&t| t > range_n).count() as f64 / n),
            }
        })
        .collect();
    let since_motion = |t: f64| motion_start_s.map(|m| t - m);
    let judgement = has_truth.then(|| judge(cue_alarms_s, drop_s));
    ArraySummary {
        pad_figures: figures,
        cue_alarms: cue_alarms_s.len() as u64,
        cue_first_alarm_s: cue_alarms_s.first().and_then(|&t| since_motion(t)),
        cue_detection_delay_s: judgement.and_then(|j| j.detection_delay_s),
        cue_false_alarms: judgement.map(|j| j.false_alarms),
        retightened_s: retightened_at_s.and_then(since_motion),
    }
}
