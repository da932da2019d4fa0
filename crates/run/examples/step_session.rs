//! Steps a run of the short lift tick by tick, acting in place of the PID during the grasp with a
//! bang-bang twine command, and prints, per phase, how far the sensor's estimate sits from the
//! twin's true pad force. `cargo run --example step_session` from the repository.

use std::path::Path;
use tendril_cell::Phase;
use tendril_run::execute::ModelCache;
use tendril_run::scenario::PickPlaceScenario;
use tendril_run::session::{Action, Session};

/// The twine speed of the bang-bang command [°/s], well inside the MX-106's limit.
const BANG_BANG_DEG_S: f64 = 15.0;

fn main() -> anyhow::Result<()> {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/short-lift.toml");
    let scenario: PickPlaceScenario = tendril_config::load(&file, &[])?;
    let cell = scenario.sim_cell(ModelCache::default().get(&scenario.scene_spec())?);
    let plan = scenario.control_plan();
    let mut session = Session::start(cell, &plan, plan.controller.build(), None);

    // Per phase: ticks, and the sum of |estimate - true pad force| [N].
    let mut error_by_phase: Vec<(Phase, u32, f64)> = Vec::new();
    while let Some(seen) = session.observation() {
        let action = match seen.phase {
            Phase::Grasp if seen.estimate.force_n < seen.setpoint_n => Action::TwineSpeed(BANG_BANG_DEG_S),
            Phase::Grasp => Action::TwineSpeed(-BANG_BANG_DEG_S),
            _ => Action::Controller,
        };
        if let Some(truth) = seen.truth {
            let gap = (seen.estimate.force_n - truth.sensor_force_n).abs();
            match error_by_phase.last_mut() {
                Some((phase, ticks, sum)) if *phase == seen.phase => {
                    *ticks += 1;
                    *sum += gap;
                }
                _ => error_by_phase.push((seen.phase, 1, gap)),
            }
        }
        session.step(action);
    }
    let (report, _) = session.finish();
    for (phase, ticks, sum) in error_by_phase {
        println!("{:>9}: {ticks:>5} ticks, mean |estimate - true| {:.3} N", phase.name(), sum / f64::from(ticks));
    }
    println!("outcome: {:?}", report.outcome);
    Ok(())
}
