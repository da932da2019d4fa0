//! The twin thread: the SimCell stepped in real time, its state put into the devices each tick.

use super::config::ServeConfig;
use super::jitter::{DelayLine, Link};
use super::program::{ArmCommand, ProgramRunner};
use super::ros2::Ros2Bridge;
use super::setpoint::{ArmPath, servo_delay_s};
use super::state::{DeviceState, ProgramState, TwinStatus, lock};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use tendril_cell::{ARM_JOINTS, Cell, CellCommand};
use tendril_dynamixel::ControlTable;
use tendril_dynamixel::control_table::addr;
use tendril_dynamixel::units::{present_current_units, present_velocity_units, rad_to_ticks, ticks_to_rad};
use tendril_hyperion::{PeakFrame, PeakHeader};
use tendril_ros2::state::CellSample;
use tendril_rtde::state::{
    RUNTIME_STATE_PAUSED, RUNTIME_STATE_PLAYING, RUNTIME_STATE_STOPPED, SAFETY_MODE_NORMAL, SAFETY_MODE_PROTECTIVE_STOP,
};
use tendril_run::scenario::PickPlaceScenario;
use tendril_twin::physics::SceneModel;
use tendril_ur5e::pose::{tcp_pose, tcp_speed};
use tendril_urscript::interp::CONTROL_PERIOD_S;

/// Writes what an MX-106's sensors would measure into its table: Present Position, Present
/// Velocity and Moving from the motion, Present Current from the load on the output shaft (through
/// the gear ratio and torque constant, [`present_current_units`]), Realtime Tick from the twin's
/// time (milliseconds, wrapping at 32 767 as the device's does).
fn present_motion(table: &mut ControlTable, time_s: f64, rad: f64, rad_s: f64, torque_nm: f64) {
    let tick_ms = (time_s * 1e3).round().rem_euclid(32768.0) as u16;
    table.put(addr::REALTIME_TICK, &tick_ms.to_le_bytes());
    if let Ok(ticks) = rad_to_ticks(rad) {
        table.set_present_position(ticks);
    }
    let velocity = present_velocity_units(rad_s);
    table.set_present_velocity(velocity);
    let threshold = table.u32_at(addr::MOVING_THRESHOLD);
    table.set_moving(velocity.unsigned_abs() > threshold);
    let limit = table.u16_at(addr::CURRENT_LIMIT);
    table.set_present_current(present_current_units(torque_nm, limit));
}

/// The arm RTDE reports at twin time `t` \[s\]: interpolated linearly between the physics states
/// `before` and `after` (time \[s\], joints \[rad\]), `t` clamped to the span between them.
///
/// Why: the physics moves the arm once per step (2.5 ms at the default), so reporting the latest
/// step gave a 500 Hz client the same sample in two packages running. Within a step the arm moves
/// at nearly a constant rate (exactly so with `physics.arm_mode = "kinematic"`; the servoed arm's
/// speed changes by a step's acceleration), so the interpolation is its path. The physics steps once a
/// tick's wait passes half of the step (`wait_until`), so the latest step ends within half a step
/// of the twin's clock either way; at half a step behind the clock the sample is always between
/// the last two steps: an interpolation, never an extrapolation. The cost: RTDE's samples are half a
/// step older on average, and each is stamped with its own time.
fn rtde_sample(before: (f64, [f64; 6]), after: (f64, [f64; 6]), t: f64) -> (f64, [f64; 6]) {
    let span = after.0 - before.0;
    if span <= 0.0 {
        return (after.0, after.1);
    }
    let t = t.clamp(before.0, after.0);
    let f = (t - before.0) / span;
    (t, std::array::from_fn(|j| before.1[j] + (after.1[j] - before.1[j]) * f))
}

/// Runs the twin in real time on its own thread (the MuJoCo data stays on it), ticking every
/// `config.period_s` with `config.realtime`'s scheduling; `config.jitter`, if it names
/// [`Link::Twin`], stalls that thread; `config.ros2` puts its ROS 2 node on it.
pub fn spawn(
    scenario: PickPlaceScenario,
    config: &ServeConfig,
    state: Arc<Mutex<DeviceState>>,
    ticks: tokio::sync::watch::Sender<u64>,
    stop: Arc<AtomicBool>,
) -> anyhow::Result<std::thread::JoinHandle<Result<(), String>>> {
    let (period_s, realtime, jitter, ros2) = (config.period_s, config.realtime, config.jitter, config.ros2.clone());
    let model = SceneModel::build(&scenario.scene_spec())?;
    let motors = scenario.hardware.motor_ids();
    // Where each pad's gratings are: every peak of the layout is served on its channel.
    let windows = tendril_run::real::hardware_for(&scenario)?.fbg;
    let (ready, started) = std::sync::mpsc::sync_channel(1);
    let run = move || -> Result<(), String> {
        let _ = realtime.apply_to_current_thread();
        // Built here: the simulation's data stays on this thread.
        let mut cell = scenario.sim_cell(model);
        // A new interrogator sample every tick (one scan period at the default 1 ms), not only when
        // the physics steps: the peak stream then carries a new sample in each frame.
        cell.sample_every_wait();
        let e = |e: tendril_cell::CellError| e.to_string();
        cell.configure().map_err(e)?;
        cell.activate().map_err(e)?;
        let first = cell.read().map_err(e)?;
        let mut command = CellCommand {
            arm_q: first.arm_q,
            growth_motor_rad: first.growth_motor_rad,
            twine_motor_rad: first.twine_motor_rad,
        };
        // The physics moves the arm once per step (several twin ticks): the joint velocities are
        // the last step's displacement over its duration (the arm moves at nearly a constant rate
        // within a step), held until the next step changes them.
        let mut last_step = (first.time_s, first.arm_q, [first.growth_motor_rad, first.twine_motor_rad]);
        // The arm at the step before: RTDE reports the arm interpolated between the two.
        let mut step_before = (first.time_s, first.arm_q);
        let mut actual_qd = [0.0; ARM_JOINTS];
        // The commanded joints at the last physics step and their speed; the TCP's twists (actual,
        // target) at the last step and their accelerations, differenced as `actual_qd` is.
        let mut last_target = first.arm_q;
        let mut target_qd = [0.0; ARM_JOINTS];
        let mut tcp_twists = ([0.0; 6], [0.0; 6]);
        let mut tcp_accelerations = ([0.0; 6], [0.0; 6]);
        // The motors' speeds, the same way (Present Velocity).
        let mut motor_rad_s = [0.0; 2];
        let mut measured_q = first.arm_q;
        // The virtual controller's program (the URScript interpreter).
        let mut program = ProgramRunner::default();
        // The path the arm's setpoint follows between program cycles (see `ArmPath`).
        let mut path: Option<ArmPath> = None;
        let timestep_s = scenario.physics.timestep_s;
        let servo_delay_s = servo_delay_s(period_s, timestep_s);
        // The twin's ROS 2 node (`--ros2`): commands taken and state published on this thread.
        let mut ros = match &ros2 {
            Some(r) => Some(Ros2Bridge::new(&scenario, r.bag.as_deref()).map_err(|e| format!("ROS 2: {e:#}"))?),
            None => None,
        };
        let publish_every = ros.as_ref().map_or(1, |r| ((r.publish_period_s() / period_s).round() as u64).max(1));
        {
            let mut s = lock(&state);
            for (id, rad) in motors.into_iter().zip([first.growth_motor_rad, first.twine_motor_rad]) {
                let ticks = rad_to_ticks(rad).map_err(|e| e.to_string())?;
                if let Some(t) = s.bus.table_mut(id) {
                    t.set_present_position(ticks);
                    t.put(addr::GOAL_POSITION, &ticks.to_le_bytes());
                }
            }
            s.outputs.actual_q = first.arm_q;
            s.outputs.target_q = first.arm_q;
            s.outputs.actual_tcp_pose = tcp_pose(&first.arm_q, &s.outputs.tcp_offset);
            s.outputs.target_tcp_pose = s.outputs.actual_tcp_pose;
        }
        // The devices now answer as the twin stands: `spawn` may return.
        let _ = ready.send(());
        let started = Instant::now();
        {
            let mut s = lock(&state);
            s.program_inputs.start_clock(started);
            s.sockets.start_clock(started);
        }
        // Injected stalls of this thread, on the twin's clock: a tick due in one waits for its end.
        let mut stalls =
            jitter.filter(|j| j.applies_to(Link::Twin)).map(|j| DelayLine::new(j.model, j.seed, Link::Twin));
        for k in 1u64.. {
            if stop.load(Ordering::SeqCst) {
                if let Some(bridge) = ros {
                    bridge.finish().map_err(|e| format!("ROS 2 bag: {e:#}"))?;
                }
                return Ok(());
            }
            let now_s = (k - 1) as f64 * period_s;
            let ros_commands = ros.as_mut().map(|r| r.take_commands(now_s)).unwrap_or_default();
            // When they came on the wall clock: a commander's delay is measured on it, not on the
            // twin's ticks, which run behind it while the twin catches up after a stall.
            let arrived_s = started.elapsed().as_secs_f64().max(now_s);
            let new_arm_target = {
                let mut s = lock(&state);
                // RTDEIOInterface and the like: the IO outputs each input package set.
                for package in s.inputs.take_io_packages() {
                    super::io::apply_io_package(&package, &mut s.outputs);
                }
                let mut new = match program.tick(&mut s, now_s, measured_q) {
                    ArmCommand::Keep => false,
                    ArmCommand::Track { q, qd, at_s } => {
                        // Never more than a step and a cycle ahead of the program's last setpoint.
                        path = Some(ArmPath::Track { q, qd, at_s, max_ahead_s: timestep_s + CONTROL_PERIOD_S });
                        false
                    }
                    ArmCommand::Servo { q, at_s } => {
                        path = Some(ArmPath::servo(path.take(), q, at_s, servo_delay_s, (command.arm_q, last_step.0)));
                        false
                    }
                    ArmCommand::Hold => {
                        path = None;
                        command.arm_q = measured_q;
                        true
                    }
                };
                // A ROS 2 arm command is a `servoj` target, due at its stamp on the twin's clock: the
                // setpoint passes it the commander's period and a servo delay later.
                for (q, due_s, lag_s) in ros
                    .as_mut()
                    .map(|r| r.arm_targets(&ros_commands, &mut s, now_s, arrived_s, measured_q))
                    .unwrap_or_default()
                {
                    let last = (command.arm_q, last_step.0);
                    path = Some(ArmPath::servo(path.take(), q, due_s, servo_delay_s + lag_s, last));
                }
                // ROS 2 motor commands set the MX-106s' Goal Position, as a bus write would.
                if let Some(r) = ros.as_mut() {
                    super::ros2::drive_motors(r, &ros_commands, &mut s, motors, now_s, period_s);
                }
                // The physics steps in this tick's wait: command the trajectory's setpoint at the
                // step's end (a step is due once the wait passes half of it, as `wait_until` runs).
                let physics_s = last_step.0;
                if let Some(p) = &path
                    && k as f64 * period_s - physics_s > 0.5 * timestep_s
                {
                    command.arm_q = p.at(physics_s + timestep_s);
                    new = true;
                    if p.settled_after(physics_s + timestep_s) {
                        path = None;
                    }
                }
                for (id, slot) in motors.into_iter().zip([&mut command.growth_motor_rad, &mut command.twine_motor_rad])
                {
                    if let Some(t) = s.bus.table(id)
                        && t.torque_enabled()
                    {
                        *slot = ticks_to_rad(t.goal_position());
                    }
                }
                new
            };
            if new_arm_target {
                cell.write(&command).map_err(e)?;
            } else {
                cell.write_motors(command.growth_motor_rad, command.twine_motor_rad).map_err(e)?;
            }
            cell.wait_until(k as f64 * period_s).map_err(e)?;
            let r = cell.read().map_err(e)?;
            let truth = cell.ground_truth().unwrap_or_default();
            let motors_rad = [r.growth_motor_rad, r.twine_motor_rad];
            let tcp_offset = lock(&state).outputs.tcp_offset;
            if r.time_s > last_step.0 + 1e-12 {
                let dt = r.time_s - last_step.0;
                actual_qd = std::array::from_fn(|j| (r.arm_q[j] - last_step.1[j]) / dt);
                motor_rad_s = std::array::from_fn(|m| (motors_rad[m] - last_step.2[m]) / dt);
                target_qd = std::array::from_fn(|j| (command.arm_q[j] - last_target[j]) / dt);
                last_target = command.arm_q;
                let twists =
                    (tcp_speed(&r.arm_q, &actual_qd, &tcp_offset), tcp_speed(&command.arm_q, &target_qd, &tcp_offset));
                tcp_accelerations = (
                    std::array::from_fn(|k| (twists.0[k] - tcp_twists.0[k]) / dt),
                    std::array::from_fn(|k| (twists.1[k] - tcp_twists.1[k]) / dt),
                );
                tcp_twists = twists;
                step_before = (last_step.0, last_step.1);
                last_step = (r.time_s, r.arm_q, motors_rad);
            }
            // What RTDE reports: the arm half a physics step behind the twin's clock, interpolated
            // between the last two steps (see `rtde_sample`).
            let (sample_s, sample_q) =
                rtde_sample(step_before, (r.time_s, r.arm_q), k as f64 * period_s - 0.5 * timestep_s);
            // The load on each motor's output shaft: the tendon's tension on the twine spool; the
            // growth motor's load is not modelled (0).
            let motor_torque_nm = [0.0, cell.tendon_tension_n() * cell.twine_spool_radius_m()];
            measured_q = r.arm_q;
            {
                let mut s = lock(&state);
                let runtime_state = match s.program {
                    ProgramState::Stopped => RUNTIME_STATE_STOPPED,
                    ProgramState::Playing => RUNTIME_STATE_PLAYING,
                    ProgramState::Paused => RUNTIME_STATE_PAUSED,
                };
                let robot_mode = s.ur.robot_mode.rtde();
                let safety_mode =
                    if s.protective_stop.is_some() { SAFETY_MODE_PROTECTIVE_STOP } else { SAFETY_MODE_NORMAL };
                // The wrist sensor's reading: the object's load pulls the tool down; the program's
                // `zero_ftsensor` offset comes off what is reported.
                let raw_force = [0.0, 0.0, -r.tool_load_n.unwrap_or(0.0), 0.0, 0.0, 0.0];
                s.tcp_force_raw = raw_force;
                let ft_zero = s.program_setup.ft_zero;
                let o = &mut s.outputs;
                o.runtime_state = runtime_state;
                o.robot_mode = robot_mode;
                o.safety_mode = safety_mode;
                o.timestamp_s = sample_s;
                o.actual_qd = actual_qd;
                o.actual_q = sample_q;
                o.target_q = command.arm_q;
                o.actual_tcp_pose = tcp_pose(&sample_q, &o.tcp_offset);
                o.actual_tcp_force = std::array::from_fn(|k| raw_force[k] - ft_zero[k]);
                o.target_tcp_pose = tcp_pose(&command.arm_q, &o.tcp_offset);
                o.target_qd = target_qd;
                (o.actual_tcp_speed, o.target_tcp_speed) = tcp_twists;
                (o.actual_tcp_acceleration, o.target_tcp_acceleration) = tcp_accelerations;
                for (m, id) in motors.into_iter().enumerate() {
                    if let Some(t) = s.bus.table_mut(id) {
                        present_motion(t, r.time_s, motors_rad[m], motor_rad_s[m], motor_torque_nm[m]);
                    }
                }
                // Scan k, stamped with its twin time (the physics may lag it by part of a step).
                let scan_s = k as f64 * period_s;
                let frame = PeakFrame {
                    header: PeakHeader {
                        serial_number: k,
                        timestamp_s: scan_s as u32,
                        timestamp_ns: (scan_s.fract() * 1e9) as u32,
                        ..PeakHeader::default()
                    },
                    // Every grating of the layout on its channel, each channel's peaks in ascending
                    // wavelength (pad 0's two; a further pad's FBG1, and its FBG2 if it has its own).
                    channels: windows.peak_channels(r.wavelengths, &r.array),
                };
                s.interrogator.set_peaks(frame).map_err(|e| e.to_string())?;
                s.status = TwinStatus {
                    time_s: r.time_s,
                    arm_q: r.arm_q,
                    motors_rad: [r.growth_motor_rad, r.twine_motor_rad],
                    wavelengths: r.wavelengths,
                    truth,
                    ticks: k,
                };
            }
            if let Some(bridge) = ros.as_mut()
                && k % publish_every == 0
            {
                let sample = CellSample {
                    time_s: sample_s,
                    arm_q: sample_q,
                    arm_qd: Some(actual_qd),
                    motors_rad,
                    motors_rad_s: Some(motor_rad_s),
                    motors_nm: Some(motor_torque_nm),
                    wavelengths: r.wavelengths,
                    array: r.array,
                    pad_force_n: Vec::new(),
                    tool_load_n: r.tool_load_n,
                };
                bridge.publish(sample).map_err(|e| format!("ROS 2: {e:#}"))?;
            }
            ticks.send_replace(k);
            let due_s = k as f64 * period_s;
            let due_s = stalls.as_mut().map_or(due_s, |line| line.release_s(due_s));
            let deadline = started + Duration::from_secs_f64(due_s);
            let now = Instant::now();
            if deadline > now {
                std::thread::sleep(deadline - now);
            } else {
                // Behind real time, the twin runs tick after tick; the devices' mutex is not fair,
                // so without a pause here the bus and network threads waiting for it could be
                // passed over tick after tick (the virtual MX-106 then missed replies for 200 ms).
                std::thread::yield_now();
            }
        }
        Ok(())
    };
    let twin = std::thread::Builder::new().name("twin".into()).spawn(run)?;
    // Until the twin has put its first state into the devices, they would answer with their
    // power-on defaults: a client that read the motors' positions then (seen on a loaded machine,
    // the twin thread not yet run) took 0 ticks, half a turn off, for the set-up position.
    if started.recv().is_err() {
        return match twin.join() {
            Ok(Err(e)) => Err(anyhow::anyhow!("twin: {e}")),
            _ => Err(anyhow::anyhow!("twin: stopped before it started")),
        };
    }
    Ok(twin)
}

#[cfg(test)]
mod tests {
    use super::rtde_sample;

    #[test]
    fn rtde_samples_interpolate_between_the_last_two_steps_and_never_extrapolate() {
        let (before, after) = ((0.010, [0.0; 6]), (0.015, [0.5; 6]));
        let (t, q) = rtde_sample(before, after, 0.012);
        assert_eq!(t, 0.012);
        assert!((q[3] - 0.2).abs() < 1e-12, "{q:?}");
        assert_eq!(rtde_sample(before, after, 0.020), (0.015, [0.5; 6]), "clamped to the latest step");
        assert_eq!(rtde_sample(before, after, 0.001), (0.010, [0.0; 6]), "clamped to the step before");
        assert_eq!(rtde_sample(after, after, 0.012), (0.015, [0.5; 6]), "no span: the latest step");
    }
}
