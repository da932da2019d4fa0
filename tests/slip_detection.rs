//! The slip detector against the twin's ground truth (`control::slip`): it sees the drops the pad
//! feels, stays quiet on a steady grip under a noisy interrogator, and, with the wrist's load
//! (`control::load`), sees the falls the pad cannot: an object that drops after the pad has already
//! lost it, and an object the hand never took up (a slick one). Without the wrist sensor the first
//! stays a finding, kept true here too.

use std::path::Path;
use tendril_run::execute::run_on_twin;
use tendril_run::runner::RunReport;
use tendril_run::summary::RunSummary;

/// `scenarios/NAME.toml` with `overrides`, run on the twin (nothing written).
fn run(name: &str, overrides: &[&str]) -> RunSummary {
    run_report(name, overrides).0
}

/// As [`run`], with the run's report (its rows).
fn run_report(name: &str, overrides: &[&str]) -> (RunSummary, RunReport) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios").join(format!("{name}.toml"));
    let overrides: Vec<tendril_config::Override> = overrides.iter().map(|o| o.parse().unwrap()).collect();
    let scenario = tendril_config::load(&path, &overrides).unwrap();
    run_on_twin(&scenario, &Default::default(), None).unwrap()
}

/// The knock: the arm at the paper's limits and 0.3 N·s along world +x, 1 s into the
/// transfer (as `scenarios/sweep-disturbed.toml`).
const KNOCK: [&str; 5] = [
    "task.minimum_durations=false",
    "disturbance.push.impulse_n_s=0.3",
    "disturbance.push.direction_deg=0",
    "disturbance.push.phase=\"transfer\"",
    "disturbance.push.offset_s=1.0",
];

#[test]
fn a_knock_that_drops_the_object_is_seen_within_three_tenths_of_a_second() {
    for object in ["crimper", "shampoo"] {
        let s = run(object, &KNOCK);
        assert_eq!(s.outcome, "dropped", "{object}: the knock is meant to drop it");
        let delay = s.drop_detection_delay_s.unwrap_or_else(|| panic!("{object}: drop not seen: {s:?}"));
        assert!(delay <= 0.3, "{object}: seen {delay} s after the drop");
        assert_eq!(s.false_alarms, Some(0), "{object}");
    }
}

#[test]
fn a_steady_grip_under_thirty_picometres_of_noise_raises_no_alarm() {
    // Before the cues were averaged against the noise, 20 of 30 held crimper and shampoo runs at
    // 30 pm flagged slip.
    for seed in ["seed=1", "seed=2"] {
        let s = run("crimper", &["interrogator.noise_pm=30", seed]);
        assert_eq!(s.outcome, "held", "{seed}: {s:?}");
        assert_eq!((s.slip_warnings, s.drop_alarms, s.false_alarms), (0, 0, Some(0)), "{seed}");
    }
}

#[test]
fn without_feedback_and_without_a_wrist_sensor_the_pad_loses_the_crimper_seconds_before_it_falls() {
    // The object then hangs on the palm's pinch (models/README.md): the sensor's loss is a false
    // alarm by the ground truth, and the drop itself is not seen. On the converged default the pad
    // lets go 2.5 s before the crimper falls (seed 1: alarm 7.32 s, drop 9.79 s; 2.2 s on the
    // whole-link default before it, 4-8 s on the coarser 32-link finger).
    let s = run("crimper", &["feedback=false", "wrist.present=false"]);
    assert_eq!(s.outcome, "dropped");
    let (drop, alarm) = (s.drop_time_s.unwrap(), s.drop_alarm_s.expect("the pad's loss is an alarm"));
    assert!(drop - alarm > 1.0, "alarm at {alarm} s, drop at {drop} s");
    assert_eq!((s.false_alarms, s.drop_detection_delay_s), (Some(1), None));
}

#[test]
fn without_feedback_the_wrist_sees_the_fall_the_pad_cannot() {
    // The same runs with the wrist's load: the pad's loss, seconds before the fall, only warns,
    // and the fall itself raises the drop alarm.
    for object in ["crimper", "shampoo"] {
        let s = run(object, &["feedback=false"]);
        assert_eq!(s.outcome, "dropped", "{object}");
        let drop = s.drop_time_s.unwrap();
        let delay = s.drop_detection_delay_s.unwrap_or_else(|| panic!("{object}: drop not seen: {s:?}"));
        assert!(delay <= 0.3, "{object}: seen {delay} s after the drop");
        assert_eq!(s.false_alarms, Some(0), "{object}");
        let warned = s.slip_detected_s.unwrap_or_else(|| panic!("{object}: the pad's loss warns"));
        assert!(drop - warned > 1.0, "{object}: warned at {warned} s, drop at {drop} s");
    }
}

#[test]
fn a_slick_object_the_hand_never_takes_up_is_seen_as_the_lift_leaves_it_behind() {
    // Grip friction 0.05: the grip slides up the object, which stays on the table; the pad keeps its
    // load and nothing the hand carried falls, so only the check of the object's weight once the
    // hand has risen 20 mm sees it (0.85-1.5 s late before that check).
    for object in ["crimper", "shampoo", "hammer"] {
        let s = run(object, &["object.friction=0.05"]);
        assert_eq!((s.outcome.as_str(), s.drop_phase.as_deref()), ("dropped", Some("lift")), "{object}");
        let delay = s.drop_detection_delay_s.unwrap_or_else(|| panic!("{object}: drop not seen: {s:?}"));
        assert!(delay <= 0.3, "{object}: seen {delay} s after the drop");
        assert_eq!(s.false_alarms, Some(0), "{object}");
    }
    // Without the sensor nothing in the hand tells it.
    let s = run("crimper", &["object.friction=0.05", "wrist.present=false"]);
    assert!(s.drop_detection_delay_s.is_none_or(|d| d > 0.3), "{s:?}");
}

#[test]
fn the_wrist_reads_the_carried_objects_weight() {
    // Noise off: the physics' load itself. Every tick with the object off the table, through the
    // arm's accelerations and the finger's creep, reads the object's weight within 1 %.
    for object in ["crimper", "hammer"] {
        let (s, report) = run_report(object, &["wrist.noise_n=0"]);
        let weight = s.run.mass_kg * 9.81;
        let carried: Vec<f64> = report
            .rows
            .iter()
            .filter(|r| r.phase.arm_moving() && r.object_height_m > 0.005)
            .map(|r| r.tool_load_n)
            .collect();
        assert!(carried.len() > 1500, "{object}: {} ticks carried", carried.len());
        for load in &carried {
            assert!((load / weight - 1.0).abs() < 0.01, "{object}: {load} N against m g = {weight} N");
        }
    }
}
