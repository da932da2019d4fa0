//! The slip detector against the twin's ground truth (`control::slip`): it sees the drops the pad
//! feels, stays quiet on a steady grip under a noisy interrogator, and (a finding, kept true by
//! this test) cannot see a drop that happens after the pad has already lost the object.

use std::path::Path;
use tendril::run::execute::run_on_twin;
use tendril::run::summary::RunSummary;

/// `scenarios/NAME.toml` with `overrides`, run on the twin (nothing written).
fn run(name: &str, overrides: &[&str]) -> RunSummary {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios").join(format!("{name}.toml"));
    let overrides: Vec<tendril::scenario::Override> = overrides.iter().map(|o| o.parse().unwrap()).collect();
    let scenario = tendril::scenario::load(&path, &overrides).unwrap();
    run_on_twin(&scenario, &Default::default(), None).unwrap().0
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
fn without_feedback_the_pad_loses_the_crimper_seconds_before_it_falls() {
    // The object then hangs on the palm's pinch (models/README.md): the sensor's loss is a false
    // alarm by the ground truth, and the drop itself is not seen. On the converged default the pad
    // lets go 2.2 s before the crimper falls (seed 1: alarm 7.83 s, drop 9.98 s; 4-8 s on the
    // coarser 32-link finger).
    let s = run("crimper", &["feedback=false"]);
    assert_eq!(s.outcome, "dropped");
    let (drop, alarm) = (s.drop_time_s.unwrap(), s.drop_alarm_s.expect("the pad's loss is an alarm"));
    assert!(drop - alarm > 1.0, "alarm at {alarm} s, drop at {drop} s");
    assert_eq!((s.false_alarms, s.drop_detection_delay_s), (Some(1), None));
}
