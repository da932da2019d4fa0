//! `controllers.csv` (`tendril chart controllers`): one row per run of the controller study.

use super::PlotError;
use super::input::Table;
use std::path::Path;

/// The columns of `controllers.csv`, in order.
pub const COLUMNS: [&str; 15] = [
    "controller",
    "object",
    "disturbance",
    "seed",
    "outcome",
    "drop_phase",
    "drop_time_s",
    "rise_time_s",
    "overshoot_pct",
    "max_fluctuation_pct",
    "fluctuation_outside_push_pct",
    "peak_force_n",
    "drop_detection_delay_s",
    "false_alarms",
    "error",
];

/// One run of the controller study (a row of `controllers.csv`).
#[derive(Debug, Clone, PartialEq)]
pub struct ControllerRow {
    /// The controller's `type` (`pid`, `feedforward`, `slip_margin`).
    pub controller: String,
    /// Object name.
    pub object: String,
    /// Disturbance set name.
    pub disturbance: String,
    /// The run's seed.
    pub seed: u64,
    /// "held", "dropped" or "error".
    pub outcome: String,
    /// Phase of the drop, if dropped.
    pub drop_phase: Option<String>,
    /// Drop time after the arm started moving \[s\].
    pub drop_time_s: Option<f64>,
    /// Rise time to 90 % of the setpoint \[s\].
    pub rise_time_s: Option<f64>,
    /// Overshoot during the grasp \[% of the setpoint\] (None when the run did not start).
    pub overshoot_pct: Option<f64>,
    /// Largest |F − setpoint| / setpoint while the arm moves \[%\] (None unless held).
    pub fluctuation_pct: Option<f64>,
    /// The same, leaving out a push's impact and the object set down early
    /// (`tendril_run::metrics::fluctuation_outside_push_pct`) \[%\]; equal to `fluctuation_pct`
    /// without a push.
    pub fluctuation_outside_push_pct: Option<f64>,
    /// Largest (despiked) estimate while holding \[N\].
    pub peak_force_n: Option<f64>,
    /// From the true drop to the slip detector's drop alarm \[s\] (None: no drop, or not seen).
    pub drop_detection_delay_s: Option<f64>,
    /// The slip detector's drop alarms that no drop followed.
    pub false_alarms: Option<u64>,
    /// The error that ended the run, if any.
    pub error: Option<String>,
}

/// Reads `controllers.csv` (the [`COLUMNS`]; `error`, the detector's columns and
/// `fluctuation_outside_push_pct` may be absent: files of earlier versions).
pub fn read(path: &Path) -> Result<Vec<ControllerRow>, PlotError> {
    let t = Table::read(path)?;
    let col = |name: &str| t.column(name);
    let (controller, object, disturbance, seed) =
        (col("controller")?, col("object")?, col("disturbance")?, col("seed")?);
    let (outcome, drop_phase, drop_time) = (col("outcome")?, col("drop_phase")?, col("drop_time_s")?);
    let (rise, overshoot, fluctuation, peak) =
        (col("rise_time_s")?, col("overshoot_pct")?, col("max_fluctuation_pct")?, col("peak_force_n")?);
    let error = t.optional_column("error");
    let (delay, false_alarms) = (t.optional_column("drop_detection_delay_s"), t.optional_column("false_alarms"));
    let outside_push = t.optional_column("fluctuation_outside_push_pct");
    let rows = t
        .iter()
        .map(|r| {
            let seed_text = r.text(seed);
            let seed_value = seed_text
                .parse::<u64>()
                .map_err(|_| r.error(format!("column `seed`: `{seed_text}` is not a whole number ≥ 0")))?;
            let phase = r.text(drop_phase);
            let fluctuation_pct = r.opt_f64(fluctuation)?;
            Ok(ControllerRow {
                controller: r.text(controller).to_string(),
                object: r.text(object).to_string(),
                disturbance: r.text(disturbance).to_string(),
                seed: seed_value,
                outcome: r.one_of(outcome, &["held", "dropped", "error"])?,
                drop_phase: (!phase.is_empty()).then(|| phase.to_string()),
                drop_time_s: r.opt_f64(drop_time)?,
                rise_time_s: r.opt_f64(rise)?,
                overshoot_pct: r.opt_f64(overshoot)?,
                fluctuation_pct,
                fluctuation_outside_push_pct: match outside_push {
                    Some(c) => r.opt_f64(c)?,
                    None => fluctuation_pct,
                },
                peak_force_n: r.opt_f64(peak)?,
                drop_detection_delay_s: match delay {
                    Some(c) => r.opt_f64(c)?,
                    None => None,
                },
                false_alarms: match false_alarms {
                    Some(c) => r.opt_f64(c)?.map(|n| n as u64),
                    None => None,
                },
                error: error.map(|c| r.text(c)).filter(|e| !e.is_empty()).map(str::to_string),
            })
        })
        .collect::<Result<Vec<_>, PlotError>>()?;
    if rows.is_empty() {
        return Err(t.empty("no rows to plot"));
    }
    Ok(rows)
}
