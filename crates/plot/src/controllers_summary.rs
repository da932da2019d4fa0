//! The controller study's table: its runs aggregated per (controller, object, disturbance set),
//! the markdown it prints, and the goal judged on it.

use super::controller_runs::ControllerRow;
use super::grid::first_seen;

/// The bound on the largest fluctuation while the arm moves \[%\].
pub const GOAL_FLUCTUATION_PCT: f64 = 10.0;

/// How soon after the true drop the slip detector must raise its drop alarm for the drop to count
/// as seen \[s\] (the 0.3 s).
pub const SEEN_WITHIN_S: f64 = 0.3;

/// One (controller, object, disturbance set) over its seeds.
#[derive(Debug, Clone, PartialEq)]
pub struct SummaryRow {
    /// The controller's `type`.
    pub controller: String,
    /// Object name.
    pub object: String,
    /// Disturbance set name.
    pub disturbance: String,
    /// Runs (seeds).
    pub runs: usize,
    /// Runs whose outcome is "held".
    pub held: usize,
    /// Runs whose outcome is "error" (could not start or ended in an error).
    pub errors: usize,
    /// `held / runs` (0 when there are no runs).
    pub held_rate: f64,
    /// Mean over the held runs of the largest fluctuation while moving \[%\].
    pub fluctuation_mean_pct: Option<f64>,
    /// Largest over the held runs of the largest fluctuation while moving \[%\].
    pub fluctuation_worst_pct: Option<f64>,
    /// Mean over the held runs of the fluctuation outside a push's impact \[%\].
    pub outside_push_mean_pct: Option<f64>,
    /// Largest over the held runs of the fluctuation outside a push's impact \[%\].
    pub outside_push_worst_pct: Option<f64>,
    /// Mean rise time over the runs that rose \[s\].
    pub rise_mean_s: Option<f64>,
    /// Longest rise time \[s\].
    pub rise_worst_s: Option<f64>,
    /// Mean overshoot over the runs \[%\].
    pub overshoot_mean_pct: Option<f64>,
    /// Largest overshoot \[%\].
    pub overshoot_worst_pct: Option<f64>,
    /// Mean peak force over the runs that grasped \[N\].
    pub peak_force_mean_n: Option<f64>,
    /// Largest peak force \[N\].
    pub peak_force_worst_n: Option<f64>,
    /// Runs whose outcome is "dropped".
    pub drops: usize,
    /// Dropped runs whose drop the slip detector saw within [`SEEN_WITHIN_S`].
    pub drops_seen: usize,
    /// The slip detector's drop alarms that no drop followed, over the runs.
    pub false_alarms: u64,
}

/// Mean and largest of `values` (None for both when empty).
fn mean_max(values: &[f64]) -> (Option<f64>, Option<f64>) {
    if values.is_empty() {
        return (None, None);
    }
    let mean = values.iter().sum::<f64>() / values.len() as f64;
    (Some(mean), values.iter().copied().reduce(f64::max))
}

/// Aggregates `rows` per (controller, object, disturbance), in the order the groups first
/// appear. Fluctuation is over held runs only (a dropped run's is undefined); rise, overshoot and
/// peak force are over every run that has them (they are measured before or up to the drop).
pub fn aggregate(rows: &[ControllerRow]) -> Vec<SummaryRow> {
    let keys = first_seen(rows.iter().map(|r| (&r.controller, &r.object, &r.disturbance)));
    keys.into_iter()
        .map(|(controller, object, disturbance)| {
            let group: Vec<&ControllerRow> = rows
                .iter()
                .filter(|r| r.controller == *controller && r.object == *object && r.disturbance == *disturbance)
                .collect();
            let held: Vec<&&ControllerRow> = group.iter().filter(|r| r.outcome == "held").collect();
            let fluctuation: Vec<f64> = held.iter().filter_map(|r| r.fluctuation_pct).collect();
            let outside_push: Vec<f64> = held.iter().filter_map(|r| r.fluctuation_outside_push_pct).collect();
            let rise: Vec<f64> = group.iter().filter_map(|r| r.rise_time_s).collect();
            let overshoot: Vec<f64> = group.iter().filter_map(|r| r.overshoot_pct).collect();
            let peak: Vec<f64> = group.iter().filter_map(|r| r.peak_force_n).collect();
            let (fluctuation_mean_pct, fluctuation_worst_pct) = mean_max(&fluctuation);
            let (outside_push_mean_pct, outside_push_worst_pct) = mean_max(&outside_push);
            let (rise_mean_s, rise_worst_s) = mean_max(&rise);
            let (overshoot_mean_pct, overshoot_worst_pct) = mean_max(&overshoot);
            let (peak_force_mean_n, peak_force_worst_n) = mean_max(&peak);
            let dropped: Vec<&&ControllerRow> = group.iter().filter(|r| r.outcome == "dropped").collect();
            SummaryRow {
                drops: dropped.len(),
                drops_seen: dropped
                    .iter()
                    .filter(|r| r.drop_detection_delay_s.is_some_and(|d| d <= SEEN_WITHIN_S))
                    .count(),
                false_alarms: group.iter().filter_map(|r| r.false_alarms).sum(),
                controller: controller.clone(),
                object: object.clone(),
                disturbance: disturbance.clone(),
                runs: group.len(),
                held: held.len(),
                errors: group.iter().filter(|r| r.outcome == "error").count(),
                held_rate: if group.is_empty() { 0.0 } else { held.len() as f64 / group.len() as f64 },
                fluctuation_mean_pct,
                fluctuation_worst_pct,
                outside_push_mean_pct,
                outside_push_worst_pct,
                rise_mean_s,
                rise_worst_s,
                overshoot_mean_pct,
                overshoot_worst_pct,
                peak_force_mean_n,
                peak_force_worst_n,
            }
        })
        .collect()
}

/// Whether a row meets the goal: every seed held, the worst fluctuation at most
/// [`GOAL_FLUCTUATION_PCT`].
pub fn meets_goal(r: &SummaryRow) -> bool {
    r.runs > 0 && r.held == r.runs && r.fluctuation_worst_pct.is_some_and(|f| f <= GOAL_FLUCTUATION_PCT)
}

/// The controllers that meet the goal for every object of `disturbance` (in order of appearance);
/// empty when none does or the set is not in the table.
pub fn controllers_meeting_goal(rows: &[SummaryRow], disturbance: &str) -> Vec<String> {
    let of_set: Vec<&SummaryRow> = rows.iter().filter(|r| r.disturbance == disturbance).collect();
    first_seen(of_set.iter().map(|r| r.controller.clone()))
        .into_iter()
        .filter(|c| of_set.iter().filter(|r| r.controller == *c).all(|r| meets_goal(r)))
        .collect()
}

/// One decimal, or `-` for nothing.
fn fmt(v: Option<f64>, digits: usize) -> String {
    v.map_or("-".to_string(), |v| format!("{v:.digits$}"))
}

/// The table as markdown, one line per row.
pub fn markdown(rows: &[SummaryRow]) -> String {
    let mut s = String::from(
        "| object | disturbance | controller | held | fluctuation while moving, mean / worst [%] | \
         the same outside a knock's impact, mean / worst [%] | rise, mean [s] | \
         overshoot, mean / worst [%] | peak force, mean / worst [N] | drops seen ≤ 0.3 s | false alarms |\n\
         | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n",
    );
    for r in rows {
        s += &format!(
            "| {} | {} | {} | {}/{} | {} / {} | {} / {} | {} | {} / {} | {} / {} | {} | {} |\n",
            r.object,
            r.disturbance,
            r.controller,
            r.held,
            r.runs,
            fmt(r.fluctuation_mean_pct, 0),
            fmt(r.fluctuation_worst_pct, 0),
            fmt(r.outside_push_mean_pct, 0),
            fmt(r.outside_push_worst_pct, 0),
            fmt(r.rise_mean_s, 2),
            fmt(r.overshoot_mean_pct, 0),
            fmt(r.overshoot_worst_pct, 0),
            fmt(r.peak_force_mean_n, 2),
            fmt(r.peak_force_worst_n, 2),
            if r.drops == 0 { "-".to_string() } else { format!("{}/{}", r.drops_seen, r.drops) },
            r.false_alarms,
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(controller: &str, object: &str, outcome: &str, fluctuation: Option<f64>, peak: f64) -> ControllerRow {
        ControllerRow {
            controller: controller.into(),
            object: object.into(),
            disturbance: "knock".into(),
            seed: 1,
            outcome: outcome.into(),
            drop_phase: None,
            drop_time_s: None,
            rise_time_s: Some(peak),
            overshoot_pct: Some(10.0 * peak),
            fluctuation_pct: fluctuation,
            fluctuation_outside_push_pct: fluctuation.map(|f| f / 2.0),
            peak_force_n: Some(peak),
            // A drop seen 0.1 s after it; a held run with one false alarm.
            drop_detection_delay_s: (outcome == "dropped").then_some(0.1),
            false_alarms: Some(u64::from(outcome == "held")),
            error: None,
        }
    }

    #[test]
    fn groups_count_held_runs_and_average_only_held_fluctuations() {
        let rows = vec![
            run("pid", "crimper", "held", Some(8.0), 1.0),
            run("pid", "crimper", "dropped", None, 3.0),
            run("pid", "crimper", "held", Some(12.0), 2.0),
            run("pid", "crimper", "error", Some(99.0), 0.5),
            run("feedforward", "crimper", "held", Some(5.0), 1.0),
        ];
        let s = aggregate(&rows);
        assert_eq!(s.len(), 2);
        let pid = &s[0];
        assert_eq!((pid.controller.as_str(), pid.runs, pid.held, pid.errors), ("pid", 4, 2, 1));
        assert_eq!(pid.held_rate, 0.5);
        // The error's 99 % is not a held run's: it must not count.
        assert_eq!(pid.fluctuation_mean_pct, Some(10.0));
        assert_eq!(pid.fluctuation_worst_pct, Some(12.0));
        assert_eq!((pid.outside_push_mean_pct, pid.outside_push_worst_pct), (Some(5.0), Some(6.0)));
        assert_eq!(pid.peak_force_worst_n, Some(3.0));
        assert_eq!(pid.peak_force_mean_n, Some(6.5 / 4.0));
        assert_eq!(pid.overshoot_worst_pct, Some(30.0));
        assert_eq!((pid.drops, pid.drops_seen, pid.false_alarms), (1, 1, 2));
        assert!(!meets_goal(pid));
        assert!(meets_goal(&s[1]));
    }

    #[test]
    fn the_goal_needs_every_object_held_under_the_bound() {
        let mut rows = vec![
            run("pid", "crimper", "held", Some(8.0), 1.0),
            run("pid", "hammer", "held", Some(10.0), 1.0),
            run("slip_margin", "crimper", "held", Some(9.0), 1.0),
            run("slip_margin", "hammer", "held", Some(10.5), 1.0),
        ];
        assert_eq!(controllers_meeting_goal(&aggregate(&rows), "knock"), vec!["pid".to_string()]);
        assert!(controllers_meeting_goal(&aggregate(&rows), "none").is_empty());
        rows.push(run("pid", "hammer", "dropped", None, 1.0));
        assert!(controllers_meeting_goal(&aggregate(&rows), "knock").is_empty());
    }

    #[test]
    fn the_markdown_has_a_line_per_row() {
        let s = aggregate(&[run("pid", "crimper", "dropped", None, 1.0)]);
        let md = markdown(&s);
        assert_eq!(md.lines().count(), 3);
        assert!(md.contains("| crimper | knock | pid | 0/1 | - / - | - / - | 1.00 | 10 / 10 | 1.00 / 1.00 |"), "{md}");
    }
}
