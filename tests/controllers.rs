//! The `feedforward` and `slip_margin` controllers on the twin's short grasp-hold-lift
//! (scenarios/short-lift.toml: crimper, 0.6 N, a 3 s grasp and a 3 s lift): both hold the object,
//! and both grip harder than the paper's PID where their schedules say they should.

use crate::common::short_lift;
use tendril_control::task::Phase;
use tendril_run::execute::run_on_twin;
use tendril_run::runner::{Outcome, RunReport};

fn run(overrides: &[&str]) -> RunReport {
    run_on_twin(&short_lift(overrides), &Default::default(), None).unwrap().1
}

/// Mean force estimate over the rows of `phase` whose time since the phase began lies in `from..to` [s]
/// (negative: before the phase, counted back from its start).
fn mean_force(rep: &RunReport, phase: Phase, from: f64, to: f64) -> f64 {
    let start = rep.rows.iter().find(|r| r.phase == phase).unwrap().time_s;
    let f: Vec<f64> =
        rep.rows.iter().filter(|r| (start + from..start + to).contains(&r.time_s)).map(|r| r.force_n).collect();
    assert!(!f.is_empty());
    f.iter().sum::<f64>() / f.len() as f64
}

#[test]
fn feedforward_raises_the_grip_ahead_of_and_during_the_lift() {
    let pid = run(&[]);
    // A 20 % margin (0.12 N on the 0.6 N setpoint), ramped in over the last 2 s of the grasp.
    let ff = run(&["controller.type=\"feedforward\"", "controller.margin=0.2", "controller.accel_gain=0.0"]);
    assert_eq!(pid.outcome, Outcome::Held);
    assert_eq!(ff.outcome, Outcome::Held);
    // Identical until the ramp begins (the schedule is zero before it: the same PID).
    let before = |r: &RunReport| mean_force(r, Phase::Lift, -2.5, -2.0);
    assert_eq!(before(&ff), before(&pid));
    // Tighter in the last half-second before the lift, and through the lift (seen: 0.52 vs 0.47 N
    // and 0.71 vs 0.60 N).
    let ahead = |r: &RunReport| mean_force(r, Phase::Lift, -0.5, 0.0);
    assert!(ahead(&ff) > ahead(&pid) + 0.02, "before the lift: {} vs {} N", ahead(&ff), ahead(&pid));
    let lift = |r: &RunReport| mean_force(r, Phase::Lift, 0.0, 3.0);
    assert!(lift(&ff) > lift(&pid) + 0.06, "lift: {} vs {} N", lift(&ff), lift(&pid));
}

#[test]
fn slip_margin_holds_and_tightens_for_a_lift_at_the_limits() {
    let at_limits = ["task.minimum_durations=false"];
    let pid = run(&at_limits);
    let sm = run(&["task.minimum_durations=false", "controller.type=\"slip_margin\"", "controller.lever_m=1.5"]);
    assert_eq!(sm.outcome, Outcome::Held);
    // The lift's peak joint speed and acceleration (the wrist's 10° in 1.63 s: 12.2 °/s, 15 °/s²)
    // at a 1.5 m lever give a load factor of 1.047: a 4.7 % (28 mN) higher target while moving.
    let lift = |r: &RunReport| mean_force(r, Phase::Lift, 0.0, 1.6);
    assert!(lift(&sm) > lift(&pid) + 0.01, "lift: {} vs {} N", lift(&sm), lift(&pid));
    let rest = |r: &RunReport| mean_force(r, Phase::Lift, -2.5, -2.0);
    assert_eq!(rest(&sm), rest(&pid), "at rest, with the default margins, it is the PID");
}

#[test]
fn a_knock_in_the_transfer_is_survived_by_its_size_whatever_the_controller() {
    // The crimper (seed 1) with the arm at the paper's limits and a knock 1 s into the transfer.
    // On the 8-link finger the feedforward (which does not loosen while the arm moves) kept the
    // crimper through a 0.3 N·s knock that the PID lost; on the converged finger the knock decides
    // alone: 0.2 N·s is carried by both, 0.3 N·s knocks it out within half a second under either,
    // before any controller acts (docs/studies/controllers.md#why-the-goal-is-out-of-reach-under-the-knock).
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/crimper.toml");
    let knocked = |controller: &str, impulse: f64| {
        let overrides: Vec<tendril_config::Override> = [
            format!("controller.type=\"{controller}\""),
            "task.minimum_durations=false".into(),
            format!("disturbance.push.impulse_n_s={impulse}"),
            "disturbance.push.phase=\"transfer\"".into(),
            "disturbance.push.offset_s=1.0".into(),
        ]
        .iter()
        .map(|o| o.parse().unwrap())
        .collect();
        let scenario = tendril_config::load(&path, &overrides).unwrap();
        run_on_twin(&scenario, &Default::default(), None).unwrap().1
    };
    for controller in ["pid", "feedforward"] {
        assert_eq!(knocked(controller, 0.2).outcome, Outcome::Held, "{controller}, 0.2 N·s");
        let hard = knocked(controller, 0.3);
        assert_eq!(hard.outcome, Outcome::Dropped, "{controller}, 0.3 N·s");
        assert_eq!(hard.drop.unwrap().phase, Phase::Transfer);
    }
}
