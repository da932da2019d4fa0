//! `tendril serve --ros2 --lockstep` (`[ros2] clock = "lockstep"`): the twin on the ROS 2 graph
//! alone, one publish period per command. It publishes the state at `t` (and `/clock` = `t`),
//! waits for a command stamped at `t` or later on `joint_commands`, applies it, steps to
//! `t + period` and publishes again: as fast as the commander and the twin go, and the same run
//! every time for a commander that keeps its time from `/clock` (`use_sim_time`). The device
//! protocols are real-time protocols and are not served in this mode.

use super::ros2::{Ros2Bridge, Ros2Serving};
use std::time::{Duration, Instant};
use tendril_cell::{Cell, CellCommand, CellState};
use tendril_ros2::bag::BagSummary;
use tendril_ros2::state::CellSample;
use tendril_run::scenario::PickPlaceScenario;
use tendril_twin::physics::SceneModel;

/// While it waits for a command, how often the twin publishes its state again \[s\]: 0.1 s, so
/// that a commander that joined after the last publish (discovery takes about a second on
/// loopback) still receives the state it must answer.
pub const REPUBLISH_S: f64 = 0.1;

/// What a lock-step session did.
#[derive(Debug, Clone, PartialEq)]
pub struct LockstepReport {
    /// Steps taken (commands acted on).
    pub steps: u64,
    /// Twin time reached \[s\].
    pub sim_s: f64,
    /// Wall time from the first publish to the end \[s\].
    pub wall_s: f64,
    /// The bag, when one was recorded.
    pub bag: Option<BagSummary>,
}

fn sample(cell: &tendril_twin::sim::SimCell, r: &CellState, previous: &CellState) -> CellSample {
    let dt = r.time_s - previous.time_s;
    let rate = |a: f64, b: f64| if dt > 0.0 { (a - b) / dt } else { 0.0 };
    CellSample {
        time_s: r.time_s,
        arm_q: r.arm_q,
        arm_qd: Some(std::array::from_fn(|j| rate(r.arm_q[j], previous.arm_q[j]))),
        motors_rad: [r.growth_motor_rad, r.twine_motor_rad],
        motors_rad_s: Some([
            rate(r.growth_motor_rad, previous.growth_motor_rad),
            rate(r.twine_motor_rad, previous.twine_motor_rad),
        ]),
        // The growth motor's load is not modelled; the twine motor's is the tendon's pull.
        motors_nm: Some([0.0, cell.tendon_tension_n() * cell.twine_spool_radius_m()]),
        wavelengths: r.wavelengths,
        array: r.array,
        pad_force_n: Vec::new(),
        tool_load_n: r.tool_load_n,
    }
}

/// Serves `scenario` in lock step until `stop` says so (or the twin reaches `until_s` \[s\] of its
/// time, when given).
pub fn serve_lockstep(
    scenario: &PickPlaceScenario,
    serving: &Ros2Serving,
    stop: &dyn Fn() -> bool,
    until_s: Option<f64>,
) -> anyhow::Result<LockstepReport> {
    let model = SceneModel::build(&scenario.scene_spec())?;
    let mut cell = scenario.sim_cell(model);
    cell.configure()?;
    cell.activate()?;
    let mut bridge = Ros2Bridge::new(scenario, serving.bag.as_deref())?;
    let period_s = bridge.publish_period_s();
    let mut state = cell.read()?;
    let mut command = CellCommand {
        arm_q: state.arm_q,
        growth_motor_rad: state.growth_motor_rad,
        twine_motor_rad: state.twine_motor_rad,
    };
    let mut published = sample(&cell, &state, &state);
    bridge.publish(published.clone())?;
    let started = Instant::now();
    let mut steps = 0u64;
    'serve: while until_s.is_none_or(|u| state.time_s < u - 1e-9) {
        // Wait for this tick's command, publishing the state again now and then.
        let t = state.time_s;
        let mut last_publish = Instant::now();
        let commands = loop {
            if stop() {
                break 'serve;
            }
            let commands = bridge.take_commands(t);
            if commands.iter().any(|c| c.stamp_s >= t - 1e-6) {
                break commands;
            }
            if last_publish.elapsed() >= Duration::from_secs_f64(REPUBLISH_S) {
                bridge.publish(published.clone())?;
                last_publish = Instant::now();
            }
            std::thread::sleep(Duration::from_micros(20));
        };
        if let Some(q) = commands.iter().rev().find_map(|c| c.arm) {
            match tendril_ur5e::safety::violation(&q, &state.arm_q) {
                None => command.arm_q = q,
                Some(why) => bridge.refuse(format!("arm target refused (the arm holds): {why}")),
            }
        }
        let motors = [command.growth_motor_rad, command.twine_motor_rad];
        if let Some([growth, twine]) = bridge.motor_targets(&commands, t, period_s, motors) {
            (command.growth_motor_rad, command.twine_motor_rad) = (growth, twine);
        }
        cell.write(&command)?;
        cell.wait_until(t + period_s)?;
        let next = cell.read()?;
        published = sample(&cell, &next, &state);
        bridge.publish(published.clone())?;
        state = next;
        steps += 1;
    }
    let wall_s = started.elapsed().as_secs_f64();
    let _ = cell.deactivate();
    Ok(LockstepReport { steps, sim_s: state.time_s, wall_s, bag: bridge.finish()? })
}
