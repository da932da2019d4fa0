//! `[disturbance]` and `task.minimum_durations` on the twin: each does something measurable on the
//! short grasp-hold-lift (scenarios/short-lift.toml, ≈ 12 s of cell time, about a second of wall
//! time), leaves the run untouched before it starts, and bad values are refused by key.

use crate::common::short_lift;
use std::path::Path;
use tendril_config::ScenarioError;
use tendril_control::task::Phase;
use tendril_drivers::RealCellConfig;
use tendril_run::execute::run_on_twin;
use tendril_run::real::run_on_real;
use tendril_run::runner::RunReport;
use tendril_run::scenario::PickPlaceScenario;
use tendril_run::trace::TraceRow;

fn run(overrides: &[&str]) -> RunReport {
    run_on_twin(&short_lift(overrides), &Default::default(), None).unwrap().1
}

fn phase_start(rows: &[TraceRow], phase: Phase) -> f64 {
    rows.iter().find(|r| r.phase == phase).unwrap().time_s
}

/// The rows up to (not including) cell time `t` are bit-identical.
fn same_until(a: &[TraceRow], b: &[TraceRow], t: f64) {
    for (x, y) in a.iter().zip(b).take_while(|(x, _)| x.time_s < t - 1e-9) {
        assert_eq!(format!("{x:?}"), format!("{y:?}"), "differ at t = {} s, before the disturbance", x.time_s);
    }
}

#[test]
fn a_push_in_the_lift_moves_the_object_and_nothing_before_it() {
    let calm = run(&[]);
    let push = ["disturbance.push.impulse_n_s=0.3", "disturbance.push.phase=\"lift\"", "disturbance.push.offset_s=1.5"];
    let pushed = run(&push);
    let onset = phase_start(&calm.rows, Phase::Lift) + 1.5;
    assert_eq!(phase_start(&pushed.rows, Phase::Lift) + 1.5, onset);
    same_until(&calm.rows, &pushed.rows, onset + 0.005);
    // Within half a second of the knock the object slides in the hand and the pad's force changes.
    let window = |r: &&TraceRow| r.time_s > onset && r.time_s < onset + 0.5;
    let slip = |rep: &RunReport| rep.rows.iter().filter(window).map(|r| r.slip_speed_m_s).fold(0.0, f64::max);
    let force_change = calm
        .rows
        .iter()
        .zip(&pushed.rows)
        .filter(|(r, _)| window(r))
        .map(|(a, b)| (a.true_force_n - b.true_force_n).abs())
        .fold(0.0, f64::max);
    assert!(slip(&pushed) > 5.0 * slip(&calm) && slip(&pushed) > 0.05, "slip {} vs {} m/s", slip(&pushed), slip(&calm));
    assert!(force_change > 0.05, "largest change of the pad force {force_change} N");
}

#[test]
fn a_push_at_a_time_starts_then() {
    let calm = run(&[]);
    let pushed = run(&[
        "disturbance.push.impulse_n_s=0.05",
        "disturbance.push.time_s=10.0",
        "disturbance.push.direction_deg=90.0",
    ]);
    same_until(&calm.rows, &pushed.rows, 10.005);
    let differs = calm.rows.iter().zip(&pushed.rows).any(|(a, b)| a.true_force_n != b.true_force_n);
    assert!(differs, "a 0.05 N·s push changed nothing");
}

#[test]
fn a_dropout_holds_the_estimate_flat_for_the_gap() {
    let calm = run(&[]);
    let gap = run(&[
        "disturbance.dropout.duration_s=0.5",
        "disturbance.dropout.phase=\"grasp\"",
        "disturbance.dropout.offset_s=1.0",
    ]);
    let start = phase_start(&calm.rows, Phase::Grasp) + 1.0;
    // Up to the tick before the onset: whether the onset tick itself still got a sample depends on
    // how the phase's start time and the offset round (both are sums of 10 ms ticks).
    same_until(&calm.rows, &gap.rows, start - 0.005);
    let held: Vec<&TraceRow> =
        gap.rows.iter().filter(|r| r.time_s > start - 0.005 && r.time_s < start + 0.5 - 0.005).collect();
    // The tick at the onset still got the sample of the step before it; the 49 after it hold it.
    assert!(held.len() >= 49, "{}", held.len());
    assert!(
        held.iter().all(|r| r.force_n == held[0].force_n && r.fbg1_nm == held[0].fbg1_nm),
        "estimate moved in the gap"
    );
    // The true force did move meanwhile (the grasp is rising), so the hold is the sensor's.
    assert!(held.iter().any(|r| r.true_force_n != held[0].true_force_n));
    // 0.5 s at 100 Hz: 50 ticks, or 49 when the onset tick rounds to the sample before it (above).
    assert!((49..=50).contains(&gap.dropped_samples), "ticks without a new sample: {}", gap.dropped_samples);
    assert_eq!(gap.invalid_samples, 0, "a missing sample is not an invalid one");
    assert_eq!(calm.dropped_samples, 0);
    // After the gap the estimate moves again.
    let after: Vec<f64> =
        gap.rows.iter().filter(|r| r.time_s > start + 0.5 && r.time_s < start + 0.6).map(|r| r.force_n).collect();
    assert!(after.iter().any(|f| *f != held[0].force_n));
}

#[test]
fn without_minimum_durations_the_lift_is_planned_at_the_limits() {
    // short-lift's lift is 3 s; its largest joint travel, 10°, takes 2 √(10/15) = 1.63 s at 15 °/s².
    let stretched = run(&[]);
    let fast = run(&["task.minimum_durations=false"]);
    let lift_s = |rep: &RunReport| phase_start(&rep.rows, Phase::Transfer) - phase_start(&rep.rows, Phase::Lift);
    assert!((lift_s(&stretched) - 3.0).abs() < 0.02, "{}", lift_s(&stretched));
    assert!((lift_s(&fast) - 1.63).abs() < 0.02, "{}", lift_s(&fast));
}

fn refused(overrides: &[&str]) -> (String, String) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(crate::common::SHORT_LIFT);
    let overrides: Vec<tendril_config::Override> = overrides.iter().map(|o| o.parse().unwrap()).collect();
    match tendril_config::load::<PickPlaceScenario>(&path, &overrides) {
        Err(ScenarioError::Invalid { key, reason, .. }) => (key, reason),
        other => panic!("{overrides:?}: not refused: {other:?}"),
    }
}

#[test]
fn bad_disturbances_are_refused_by_key() {
    let push = |extra: &str| vec!["disturbance.push.impulse_n_s=0.3".to_string(), extra.to_string()];
    for (overrides, key) in [
        (
            vec!["disturbance.push.impulse_n_s=-0.3".into(), "disturbance.push.time_s=1.0".into()],
            "disturbance.push.impulse_n_s",
        ),
        (
            vec!["disturbance.push.impulse_n_s=50.0".into(), "disturbance.push.time_s=1.0".into()],
            "disturbance.push.impulse_n_s",
        ),
        (push("disturbance.push.duration_s=0.0"), "disturbance.push.duration_s"),
        (push("disturbance.push.direction_deg=nan"), "disturbance.push.direction_deg"),
        (push("disturbance.push.offset_s=1.0"), "disturbance.push.phase"),
        (push("disturbance.push.phase=\"home\""), "disturbance.push.phase"),
        (push("disturbance.push.phase=\"nowhere\""), "disturbance.push.phase"),
        (push("disturbance.push.strength=1.0"), "disturbance.push.strength"),
        (
            vec!["disturbance.dropout.duration_s=60.0".into(), "disturbance.dropout.time_s=1.0".into()],
            "disturbance.dropout.duration_s",
        ),
        (
            vec!["disturbance.dropout.duration_s=0.5".into(), "disturbance.dropout.time_s=-1.0".into()],
            "disturbance.dropout.time_s",
        ),
        (vec!["disturbance.quake.duration_s=0.5".into()], "disturbance.quake"),
    ] {
        let overrides: Vec<&str> = overrides.iter().map(String::as_str).collect();
        let (k, reason) = refused(&overrides);
        assert_eq!(k, key, "{overrides:?}: {reason}");
    }
    // A missing field is reported on its section, naming the field.
    let (k, reason) = refused(&["disturbance.push.time_s=1.0"]);
    assert_eq!(k, "disturbance.push");
    assert!(reason.contains("impulse_n_s"), "{reason}");
    let (k, reason) = refused(&["disturbance.dropout.phase=\"lift\""]);
    assert_eq!(k, "disturbance.dropout");
    assert!(reason.contains("duration_s"), "{reason}");
    let (k, reason) = refused(&[
        "disturbance.push.impulse_n_s=0.3",
        "disturbance.push.time_s=1.0",
        "disturbance.push.phase=\"lift\"",
    ]);
    assert_eq!(k, "disturbance.push.time_s");
    assert!(reason.contains("not both"), "{reason}");
    let (k, reason) =
        refused(&["disturbance.push.impulse_n_s=0.3", "disturbance.push.time_s=1.0", "physics.backend=\"rapier\""]);
    assert_eq!(k, "disturbance.push");
    assert!(reason.contains("rapier"), "{reason}");
}

#[test]
fn the_real_cell_refuses_a_scenario_with_disturbances() {
    let scenario = short_lift(&["disturbance.push.impulse_n_s=0.3", "disturbance.push.phase=\"transfer\""]);
    // Nothing listens on these ports: the refusal comes before any device is contacted.
    let config = RealCellConfig::new("127.0.0.1", "/dev/null", "127.0.0.1");
    let err = run_on_real(&scenario, config, None).unwrap_err().to_string();
    assert!(err.contains("disturbance.push") && err.contains("simulated"), "{err}");
}
