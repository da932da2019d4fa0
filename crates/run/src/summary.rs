//! `summary.json`: the one-record result of a run, also the row of a sweep's `results.csv`.

use super::metrics::ControlMetrics;
use super::runner::RunReport;
use serde::{Deserialize, Serialize};

/// PID gains as reported.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Gains {
    /// Proportional gain [(°/s)/N].
    pub kp: f64,
    /// Integral gain [(°/s)/(N·s)].
    pub ki: f64,
    /// Derivative gain [(°/s)/(N/s)].
    pub kd: f64,
}

/// What identifies a run besides its report.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct RunIdentity {
    /// Scenario name.
    pub scenario: String,
    /// Object name.
    pub object: String,
    /// Object mass \[kg\].
    pub mass_kg: f64,
    /// Force control kept on while the arm moves.
    pub feedback: bool,
    /// The force controller's `type` (`"pid"`, ...).
    #[serde(default)]
    pub controller_type: String,
    /// PID gains.
    pub gains: Gains,
    /// Force setpoint \[N\].
    pub setpoint_n: f64,
    /// Seed of every random process in the run.
    pub seed: u64,
    /// Which cell ran it ("mujoco", "real", ...).
    pub backend: String,
}

/// What a long hold did (`task.hold`) and how far the twine motor went.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct HoldSummary {
    /// Times the grasp let go of the object waiting on the table and wrapped it again.
    pub releases: u32,
    /// Cell time at which the twine motor first reached the end of its travel \[s\] (absent: it
    /// never did).
    pub travel_end_cell_time_s: Option<f64>,
    /// The largest twine motor angle during the grasp, as a fraction of its travel [-].
    pub max_grasp_travel: f64,
    /// The largest over the run [-].
    pub max_travel: f64,
}

/// The summary of one run. Times are in seconds; `drop_time_s` counts from the moment the arm
/// started moving the object (the paper's Fig. 9 time axis), `drop_cell_time_s` from activation.
/// The identity and the control metrics are flattened into the record (and the CSV row).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct RunSummary {
    /// Scenario, object, gains, seed, backend.
    #[serde(flatten)]
    pub run: RunIdentity,
    /// "held", "dropped", "error" or "not_grasped" (a settled grasp that timed out: let go
    /// without lifting).
    pub outcome: String,
    /// Time of the drop after the arm started moving \[s\].
    pub drop_time_s: Option<f64>,
    /// Time of the drop since activation \[s\].
    pub drop_cell_time_s: Option<f64>,
    /// Phase of the drop.
    pub drop_phase: Option<String>,
    /// When the sensor-based detector saw slip start, after the arm started moving \[s\].
    pub slip_detected_s: Option<f64>,
    /// When the sensor-based detector raised its first drop alarm (the pad's sudden fall or loss;
    /// with a wrist force sensor, once it reads the object's weight, the tool's load falling),
    /// after the arm started moving \[s\].
    #[serde(default)]
    pub drop_alarm_s: Option<f64>,
    /// Slip-warning episodes (the estimate below half the setpoint; [`tendril_control::slip`]).
    #[serde(default)]
    pub slip_warnings: u64,
    /// Drop-alarm episodes.
    #[serde(default)]
    pub drop_alarms: u64,
    /// On the twin: from the true drop to the first drop alarm at most 0.5 s before it \[s\]
    /// (negative: the alarm came first; absent: no drop, or the sensor did not see it).
    #[serde(default)]
    pub drop_detection_delay_s: Option<f64>,
    /// On the twin: drop alarms that no drop followed (absent on the real cell, which cannot tell).
    #[serde(default)]
    pub false_alarms: Option<u64>,
    /// Rise time, overshoot, fluctuation, estimate error, oscillation.
    #[serde(flatten)]
    pub metrics: ControlMetrics,
    /// Simulated (or cell) time covered \[s\].
    pub sim_time_s: f64,
    /// Wall-clock time of the run \[s\].
    pub wall_time_s: f64,
    /// Simulated seconds per wall second.
    pub real_time_factor: f64,
    /// CPU time of the thread that ran the task \[s\]: on the twin, the physics and the control
    /// code, unaffected by what else the machine runs (on the real cell, the control loop only).
    #[serde(default)]
    pub cpu_time_s: f64,
    /// Simulated seconds per CPU second of that thread: the speed the benchmarks and speed charts
    /// compare, since it does not change with the machine's load.
    #[serde(default)]
    pub sim_s_per_cpu_s: f64,
    /// The error that ended the run, with its time.
    pub error: Option<String>,
    /// Sensor samples that gave no force estimate (non-finite, or below the calibration curve) and
    /// were skipped, the last valid estimate held (see
    /// [`crate::runner::MAX_CONSECUTIVE_INVALID_SAMPLES`]).
    #[serde(default)]
    pub invalid_samples: u64,
    /// Control ticks that got no new interrogator sample (a `[disturbance.dropout]`): the last
    /// estimate was held. Not invalid samples: they do not count towards the consecutive limit.
    #[serde(default)]
    pub dropped_samples: u64,
    /// On a real cell: how old each device stream's samples were when the ticks read them, and
    /// how late the ticks were, against the watchdog's limits.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub device_timing: Option<tendril_cell::DeviceTiming>,
    /// With a sensor array: each pad's figures and the array's slip cue (absent with the paper's
    /// single pad).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub array: Option<super::array_summary::ArraySummary>,
    /// With `task.settled_grasp`: how long the grasp lasted until it settled or timed out \[s\]
    /// (absent with the paper's fixed grasp).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grasp_duration_s: Option<f64>,
    /// A long hold's record: present when the grasp let go and re-wrapped (`task.hold`) or the
    /// twine reached the end of its travel.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hold: Option<HoldSummary>,
    /// With a `[detector]`: the class it reported and whose settings the run used.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub detection: Option<super::detector::Detection>,
    /// With a produce item: the damage the grip did and the harvest's end (absent for a rigid
    /// object).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub produce: Option<super::produce_summary::ProduceSummary>,
    /// MuJoCo's warnings during the run (see [`tendril_twin::mujoco_log`]), at most
    /// [`tendril_twin::mujoco_log::MAX_KEPT`]; in `results.csv` joined by `; `.
    #[serde(default)]
    pub warnings: Vec<String>,
}

impl RunSummary {
    /// A summary for a run that could not start (its scenario failed to build): outcome
    /// "error" with the cause, so a sweep records it and goes on.
    pub fn failed_to_start(scenario: &str, cause: String) -> RunSummary {
        RunSummary {
            run: RunIdentity { scenario: scenario.into(), ..Default::default() },
            outcome: "error".into(),
            error: Some(cause),
            ..Default::default()
        }
    }

    /// The column names of a flattened summary, in order (nested fields dotted: `gains.kp`).
    pub fn columns() -> Vec<String> {
        // A sensor array's and a produce item's columns too, so that one results file holds runs
        // with and without them (empty for the paper's single pad and a rigid object); a real
        // cell's device timing is not a sweep's.
        let with_array = RunSummary {
            array: Some(Default::default()),
            grasp_duration_s: Some(0.0),
            hold: Some(Default::default()),
            detection: Some(Default::default()),
            produce: Some(Default::default()),
            ..RunSummary::default()
        };
        flatten_summary(&with_array).into_iter().map(|(k, _)| k).collect()
    }

    /// The cells of this summary in [`RunSummary::columns`]' order (empty where it has no value).
    pub fn cells(&self) -> Vec<String> {
        let mut values: std::collections::HashMap<String, String> = flatten_summary(self).into_iter().collect();
        RunSummary::columns().into_iter().map(|k| values.remove(&k).unwrap_or_default()).collect()
    }

    /// Builds the summary from a run's identity, report, wall time and CPU time.
    pub fn new(id: RunIdentity, report: &RunReport, wall_time_s: f64, cpu_time_s: f64) -> RunSummary {
        let since_motion = |t: f64| report.motion_start_s.map(|m| t - m);
        RunSummary {
            run: id,
            outcome: report.outcome.name().to_string(),
            drop_time_s: report.drop.and_then(|d| since_motion(d.cell_time_s)),
            drop_cell_time_s: report.drop.map(|d| d.cell_time_s),
            drop_phase: report.drop.map(|d| d.phase.name().to_string()),
            slip_detected_s: report.slip.slip_start_s.and_then(since_motion),
            drop_alarm_s: report.slip.drop_alarm_s.and_then(since_motion),
            slip_warnings: report.alarms.warnings_s.len() as u64,
            drop_alarms: report.alarms.drops_s.len() as u64,
            drop_detection_delay_s: report.detection.and_then(|j| j.detection_delay_s),
            false_alarms: report.detection.map(|j| j.false_alarms),
            metrics: report.metrics,
            sim_time_s: report.cell_time_s,
            wall_time_s,
            real_time_factor: if wall_time_s > 0.0 { report.cell_time_s / wall_time_s } else { f64::INFINITY },
            cpu_time_s,
            sim_s_per_cpu_s: if cpu_time_s > 0.0 { report.cell_time_s / cpu_time_s } else { f64::INFINITY },
            error: report.error.clone(),
            invalid_samples: report.invalid_samples,
            dropped_samples: report.dropped_samples,
            device_timing: report.device_timing,
            array: report.array.clone(),
            grasp_duration_s: None,
            hold: hold_summary(report),
            detection: None,
            produce: report.produce.as_ref().map(|p| {
                super::produce_summary::ProduceSummary::new(
                    p,
                    report.outcome,
                    report.drop,
                    report.motion_start_s,
                    &report.rows,
                )
            }),
            warnings: Vec::new(),
        }
    }
}

/// The hold's record when there is something to report: a release, or the travel's end.
fn hold_summary(report: &RunReport) -> Option<HoldSummary> {
    let h = &report.hold;
    (h.releases > 0 || h.travel_end_s.is_some()).then_some(HoldSummary {
        releases: h.releases,
        travel_end_cell_time_s: h.travel_end_s,
        max_grasp_travel: h.max_grasp_travel,
        max_travel: h.max_travel,
    })
}

/// A short human-readable summary, a line per figure.
pub fn render_text(s: &RunSummary) -> String {
    let opt = |v: Option<f64>, unit: &str| v.map_or("-".to_string(), |v| format!("{v:.2} {unit}"));
    let mut out = format!(
        "{} ({}, {:.0} g, setpoint {} N, feedback {}, controller {}, Kp {} Ki {} Kd {}, seed {}, {})\n",
        s.run.scenario,
        s.run.object,
        s.run.mass_kg * 1e3,
        s.run.setpoint_n,
        if s.run.feedback { "on" } else { "off" },
        s.run.controller_type,
        s.run.gains.kp,
        s.run.gains.ki,
        s.run.gains.kd,
        s.run.seed,
        s.run.backend
    );
    out += &format!("  outcome            {}", s.outcome);
    if let (Some(t), Some(p)) = (s.drop_time_s, &s.drop_phase) {
        out += &format!(" at {t:.2} s after the arm started moving, during {p}");
    }
    out += "\n";
    if let Some(e) = &s.error {
        out += &format!("  error              {e}\n");
    }
    out += &format!("  slip detector      {} warning(s), {} drop alarm(s)", s.slip_warnings, s.drop_alarms);
    if let Some(d) = s.drop_detection_delay_s {
        out += &format!("; saw the drop {:.2} s {}", d.abs(), if d < 0.0 { "before it" } else { "after it" });
    } else if s.drop_time_s.is_some() && s.false_alarms.is_some() {
        out += "; did not see the drop";
    }
    if let Some(n) = s.false_alarms.filter(|&n| n > 0) {
        out += &format!("; {n} false");
    }
    out += "\n";
    if s.dropped_samples > 0 {
        out += &format!("  dropped samples    {} ticks without a new sample (estimate held)\n", s.dropped_samples);
    }
    if let Some(t) = &s.device_timing {
        let [sensor, arm, motors] = t.watchdog_ms;
        out += &format!(
            "  device streams     oldest sample at a tick: sensor {:.1} ms, arm {:.1} ms, motors {:.1} ms \
             (watchdog {sensor:.0} / {arm:.0} / {motors:.0} ms); ticks late p99 {:.2} ms, at most {:.2} ms\n",
            t.sensor_age.max_ms, t.arm_age.max_ms, t.motor_age.max_ms, t.tick_late.p99_ms, t.tick_late.max_ms
        );
    }
    if s.invalid_samples > 0 {
        out += &format!("  invalid samples    {} skipped (last valid estimate held)\n", s.invalid_samples);
    }
    if let Some(g) = s.grasp_duration_s {
        let how = if s.outcome == "not_grasped" { "timed out" } else { "settled" };
        out += &format!("  settled grasp      {how} after {g:.2} s\n");
    }
    if let Some(h) = &s.hold {
        out += &format!(
            "  long hold          {} release(s) and re-wrap(s); twine at most {:.0} % of its travel ({:.0} % in the grasp)",
            h.releases,
            100.0 * h.max_travel,
            100.0 * h.max_grasp_travel
        );
        if let Some(t) = h.travel_end_cell_time_s {
            out += &format!("; at the travel's end at {t:.1} s");
        }
        out += "\n";
    }
    out += &format!("  rise time (90 %)   {}\n", opt(s.metrics.rise_time_90_s, "s"));
    out += &format!("  overshoot          {:.1} %\n", s.metrics.overshoot_pct);
    out += &format!("  max fluctuation    {}\n", opt(s.metrics.max_fluctuation_pct, "%"));
    if s.metrics.max_fluctuation_outside_push_pct != s.metrics.max_fluctuation_pct {
        out += &format!("    outside the push  {}\n", opt(s.metrics.max_fluctuation_outside_push_pct, "%"));
    }
    out += &format!("  estimate RMSE      {}\n", opt(s.metrics.force_rmse_n, "N"));
    if let Some(a) = &s.array {
        out += &render_array(a);
    }
    if let Some(p) = &s.produce {
        out += &render_produce(p);
    }
    out += &format!(
        "  simulated {:.1} s in {:.2} s wall ({}x real time), {:.2} s of CPU ({}x)\n",
        s.sim_time_s,
        s.wall_time_s,
        speed_factor(s.real_time_factor),
        s.cpu_time_s,
        speed_factor(s.sim_s_per_cpu_s)
    );
    out
}

/// A produce item's lines of the text summary: the damage, and the harvest's end.
fn render_produce(p: &super::produce_summary::ProduceSummary) -> String {
    let mut out = format!(
        "  contact pressure   peak {:.0} kPa ({}), bruise threshold {:.0} kPa: {}\n",
        p.peak_pressure_kpa,
        if p.peak_at.is_empty() { "no contact" } else { p.peak_at.as_str() },
        p.bruise_threshold_kpa,
        if p.bruised {
            format!("bruised, {:.1} mm² above it at most, for {:.2} s", p.bruise_area_mm2, p.time_above_s)
        } else {
            "not bruised".into()
        }
    );
    if let Some(share) = p.bump_share {
        out += &format!("  pad on the item    the bump carries {:.0} % of the pad's force while held\n", 100.0 * share);
    }
    if let Some(h) = &p.harvest {
        out += &format!("  harvest            {h}");
        if let Some(t) = p.detached_s {
            out += &format!(", the stem let go {t:.2} s after the arm started moving");
        }
        if let (Some(max), Some(d)) = (p.max_stem_tension_n, p.detach_n) {
            out += &format!(" (stem tension up to {max:.2} N, lets go at {d:.2} N)");
        }
        out += "\n";
    }
    out
}

/// The array's lines of the text summary: each pad's forces, and the slip cue.
fn render_array(a: &super::array_summary::ArraySummary) -> String {
    let opt = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.2}"));
    let mut out = String::new();
    for p in &a.pad_figures {
        out += &format!(
            "  pad {}              true {} N, peak {} N, RMSE {} N while holding",
            p.pad,
            opt(p.mean_true_n),
            opt(p.peak_n),
            opt(p.estimate_rmse_n)
        );
        if let Some(over) = p.over_range_pct.filter(|&o| o > 0.0) {
            out += &format!("; over range {over:.0} % of it");
        }
        out += "\n";
    }
    out += &format!("  array cue          {} alarm(s)", a.cue_alarms);
    if let Some(d) = a.cue_detection_delay_s {
        out += &format!("; saw the drop {:.2} s {}", d.abs(), if d < 0.0 { "before it" } else { "after it" });
    }
    if let Some(n) = a.cue_false_alarms.filter(|&n| n > 0) {
        out += &format!("; {n} false");
    }
    if let Some(t) = a.retightened_s {
        out += &format!("; re-tightened {t:.2} s after the arm started moving");
    }
    out + "\n"
}

/// A speed ratio (simulated s per s) to two significant figures, so that a slow backend's 0.35x
/// does not print as 0x: 120, 21, 8.3, 0.35.
pub fn speed_factor(x: f64) -> String {
    match x.abs() {
        a if a >= 10.0 || a == 0.0 || !a.is_finite() => format!("{x:.0}"),
        a if a >= 1.0 => format!("{x:.1}"),
        a if a >= 0.1 => format!("{x:.2}"),
        _ => format!("{x:.1e}"),
    }
}

/// The summary's fields as flat (column, value) pairs; nested objects become dotted columns.
pub fn flatten_summary(summary: &RunSummary) -> Vec<(String, String)> {
    fn walk(prefix: &str, value: &serde_json::Value, out: &mut Vec<(String, String)>) {
        match value {
            serde_json::Value::Object(map) => {
                for (k, v) in map {
                    let name = if prefix.is_empty() { k.clone() } else { format!("{prefix}.{k}") };
                    walk(&name, v, out);
                }
            }
            serde_json::Value::Null => out.push((prefix.to_string(), String::new())),
            serde_json::Value::String(s) => out.push((prefix.to_string(), s.clone())),
            // A list of messages (the MuJoCo warnings) is one cell.
            serde_json::Value::Array(items) => out.push((
                prefix.to_string(),
                items
                    .iter()
                    .map(|v| v.as_str().map_or_else(|| v.to_string(), str::to_string))
                    .collect::<Vec<_>>()
                    .join("; "),
            )),
            other => out.push((prefix.to_string(), other.to_string())),
        }
    }
    let mut out = Vec::new();
    walk("", &serde_json::to_value(summary).expect("summaries serialise"), &mut out);
    out
}

#[cfg(test)]
mod tests {
    use super::speed_factor;

    #[test]
    fn speed_factors_keep_two_significant_figures() {
        let printed: Vec<String> = [120.4, 21.3, 8.27, 0.347, 0.0123, 0.0].map(speed_factor).into();
        assert_eq!(printed, ["120", "21", "8.3", "0.35", "1.2e-2", "0"]);
    }
}
