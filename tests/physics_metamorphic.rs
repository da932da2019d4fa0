//! Metamorphic physics tests over seeds: relations between runs that must hold whatever the
//! calibration, because they follow from friction and grip, not from tuned numbers.
//!
//! - a grip friction near zero never carries an object;
//! - without feedback, a higher setpoint (a tighter frozen grip) drops later or not at all;
//! - a higher grip friction drops later or not at all.
//!
//! The steps between the compared settings are large (setpoint and friction well apart) because
//! a no-feedback drop time scatters by a few tenths of a second between seeds.

use tendril::study::{StudyRun, run_all, set};
use tendril_config::Override;

const SEEDS: [u64; 3] = [1, 2, 3];

fn runs(scenario: &str, sets: Vec<Vec<Override>>) -> Vec<StudyRun> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(scenario);
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    run_all(&path, sets, threads).expect("scenarios load")
}

/// Drop time after the arm starts, infinity when held (so "later or not at all" is `>=`).
fn drop_or_never(run: &StudyRun) -> f64 {
    assert_ne!(run.summary.outcome, "error", "{:?}", run.summary.error);
    run.summary.drop_time_s.unwrap_or(f64::INFINITY)
}

#[test]
fn a_grip_without_friction_never_carries_the_object() {
    for object in ["crimper", "shampoo", "hammer"] {
        let sets = SEEDS.iter().map(|&s| vec![set("seed", s), set("object.friction", 0.02)]).collect();
        for (run, seed) in runs(&format!("scenarios/{object}.toml"), sets).iter().zip(SEEDS) {
            assert_eq!(
                run.summary.outcome, "dropped",
                "{object}, seed {seed}, grip friction 0.02 with feedback: {:?}",
                run.summary
            );
        }
    }
}

#[test]
fn without_feedback_a_higher_setpoint_drops_later_or_not_at_all() {
    let sets = SEEDS
        .iter()
        .flat_map(|&s| [0.6, 1.2].map(|f| vec![set("seed", s), set("feedback", false), set("setpoint_n", f)]))
        .collect();
    let runs = runs("scenarios/crimper.toml", sets);
    for (pair, seed) in runs.chunks(2).zip(SEEDS) {
        let (low, high) = (drop_or_never(&pair[0]), drop_or_never(&pair[1]));
        assert!(low.is_finite(), "seed {seed}: the crimper at 0.6 N without feedback should drop (paper)");
        assert!(high >= low, "seed {seed}: dropped at {high} s with 1.2 N, earlier than at {low} s with 0.6 N");
    }
}

#[test]
fn a_higher_grip_friction_drops_later_or_not_at_all() {
    for (object, low_mu, high_mu) in [("crimper", 0.85, 1.1), ("shampoo", 0.55, 0.75)] {
        let sets = SEEDS
            .iter()
            .flat_map(|&s| {
                [low_mu, high_mu].map(|mu| vec![set("seed", s), set("feedback", false), set("object.friction", mu)])
            })
            .collect();
        let runs = runs(&format!("scenarios/{object}.toml"), sets);
        for (pair, seed) in runs.chunks(2).zip(SEEDS) {
            let (low, high) = (drop_or_never(&pair[0]), drop_or_never(&pair[1]));
            assert!(low.is_finite(), "{object} seed {seed}: the calibrated friction should drop it without feedback");
            assert!(high >= low, "{object} seed {seed}: μ {high_mu} dropped at {high} s, before μ {low_mu} at {low} s");
        }
    }
}
