//! The twin thread (SimCell in real time) and the Dynamixel bus on a pseudo-terminal.

use crate::cell::physics::SceneModel;
use crate::cell::real::HardwareConfig;
use crate::cell::real::protocol::dynamixel::control_table::addr;
use crate::cell::real::protocol::dynamixel::units::{baud_rate_code, rad_to_ticks, ticks_to_rad};
use crate::cell::real::protocol::dynamixel::{StreamDecoder, VirtualBus};
use crate::cell::real::protocol::hyperion::{InterrogatorConfig, PeakFrame, PeakHeader, VirtualInterrogator};
use crate::cell::real::protocol::rtde::state::RUNTIME_STATE_PLAYING;
use crate::cell::real::protocol::rtde::{RobotOutputs, SharedInputs};
use crate::cell::real::realtime::RealtimeOptions;
use crate::cell::real::urscript::{ENABLE_REGISTER, FOLLOWING_REGISTER, TARGET_REGISTER};
use crate::cell::sim::SimCell;
use crate::hardware::{ARM_JOINTS, Cell, CellCommand, GroundTruth};
use crate::run::scenario::PickPlaceScenario;
use crate::signals::Wavelengths;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// What the twin last computed (for tests and the serve printout).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TwinStatus {
    /// Twin time \[s\].
    pub time_s: f64,
    /// Arm joints \[rad\].
    pub arm_q: [f64; ARM_JOINTS],
    /// Growth, twine motor angles \[rad\].
    pub motors_rad: [f64; 2],
    /// Latest interrogator sample.
    pub wavelengths: Wavelengths,
    /// The simulation's ground truth.
    pub truth: GroundTruth,
    /// Ticks run.
    pub ticks: u64,
}

impl Default for TwinStatus {
    fn default() -> Self {
        TwinStatus {
            time_s: 0.0,
            arm_q: [0.0; ARM_JOINTS],
            motors_rad: [0.0; 2],
            wavelengths: Wavelengths { fbg1_nm: 0.0, fbg2_nm: 0.0 },
            truth: GroundTruth::default(),
            ticks: 0,
        }
    }
}

/// Everything the protocol servers and the twin share.
pub struct DeviceState {
    /// What the virtual UR5e reports.
    pub outputs: RobotOutputs,
    /// What RTDE clients wrote.
    pub inputs: SharedInputs,
    /// Whether a complete program came in on the secondary interface.
    pub program_loaded: bool,
    /// The MX-106 pair.
    pub bus: VirtualBus,
    /// The interrogator.
    pub interrogator: VirtualInterrogator,
    /// The twin's latest status.
    pub status: TwinStatus,
    /// Next RTDE session number.
    pub next_session: u64,
}

/// The shared state and the tick channel (the twin sends its tick count after each update): the
/// motors at `hardware`'s IDs and bus speed, an interrogator with enough channels for its FBG channel.
pub fn shared_state(
    hardware: &HardwareConfig,
) -> anyhow::Result<(Arc<Mutex<DeviceState>>, tokio::sync::watch::Sender<u64>)> {
    let mut bus = VirtualBus::with_ids(&hardware.motor_ids()).map_err(|e| anyhow::anyhow!("virtual bus: {e}"))?;
    let baud = baud_rate_code(hardware.dxl_baud)
        .ok_or_else(|| anyhow::anyhow!("virtual bus: the MX-106 has no {} bit/s setting", hardware.dxl_baud))?;
    for id in hardware.motor_ids() {
        if let Some(t) = bus.table_mut(id) {
            t.put(addr::BAUD_RATE, &[baud]);
        }
    }
    // The si255 has 1, 4, 8 or 16 channels: the virtual one keeps its default 4 unless the FBG
    // channel needs more.
    let channel_count = [4, 8, 16].into_iter().find(|&n| n >= hardware.fbg.channel).unwrap_or(16) as u32;
    let interrogator = VirtualInterrogator::new(InterrogatorConfig { channel_count, ..InterrogatorConfig::default() })
        .map_err(|e| anyhow::anyhow!("virtual interrogator: {e}"))?;
    let state = DeviceState {
        outputs: RobotOutputs::default(),
        inputs: SharedInputs::new(),
        program_loaded: false,
        bus,
        interrogator,
        status: TwinStatus::default(),
        next_session: 1,
    };
    Ok((Arc::new(Mutex::new(state)), tokio::sync::watch::channel(0).0))
}

fn lock(state: &Mutex<DeviceState>) -> std::sync::MutexGuard<'_, DeviceState> {
    state.lock().unwrap_or_else(|p| p.into_inner())
}

/// Opens the pseudo-terminal pair and serves the bus on its master side until `stop`.
pub fn open_bus(
    state: Arc<Mutex<DeviceState>>,
    stop: Arc<AtomicBool>,
    realtime: RealtimeOptions,
) -> anyhow::Result<(PathBuf, std::thread::JoinHandle<()>)> {
    use std::os::unix::io::AsRawFd;
    let (mut master, slave) = serial2::SerialPort::pair()?;
    // serial2 opens the slave by name; /proc tells which /dev/pts/N it is.
    let path = std::fs::read_link(format!("/proc/self/fd/{}", slave.as_raw_fd()))?;
    master.set_read_timeout(Duration::from_millis(20))?;
    let handle = std::thread::Builder::new().name("dxl-bus".into()).spawn(move || {
        // Keeping the slave open means reads on the master never fail with EIO between clients.
        let _slave = slave;
        let _ = realtime.apply_to_current_thread();
        let mut decoder = StreamDecoder::new();
        let mut chunk = [0u8; 1024];
        while !stop.load(Ordering::SeqCst) {
            match master.read(&mut chunk) {
                Ok(n) if n > 0 => {
                    let reply = lock(&state).bus.respond_to_bytes(&mut decoder, &chunk[..n]);
                    if !reply.is_empty() && master.write_all(&reply).is_err() {
                        return;
                    }
                }
                Ok(_) => {}
                Err(e) if matches!(e.kind(), std::io::ErrorKind::TimedOut | std::io::ErrorKind::WouldBlock) => {}
                Err(_) => std::thread::sleep(Duration::from_millis(5)),
            }
        }
    })?;
    Ok((path, handle))
}

/// Runs the twin in real time on its own thread (the MuJoCo data stays on it).
pub fn spawn(
    scenario: PickPlaceScenario,
    period_s: f64,
    state: Arc<Mutex<DeviceState>>,
    ticks: tokio::sync::watch::Sender<u64>,
    stop: Arc<AtomicBool>,
    realtime: RealtimeOptions,
) -> anyhow::Result<std::thread::JoinHandle<Result<(), String>>> {
    let model = SceneModel::build(&scenario.scene_spec())?;
    let motors = scenario.hardware.motor_ids();
    let channel = scenario.hardware.fbg.channel;
    let run = move || -> Result<(), String> {
        let _ = realtime.apply_to_current_thread();
        // Built here: the simulation's data stays on this thread.
        let mut cell = SimCell::for_scenario(&scenario, model);
        let e = |e: crate::hardware::CellError| e.to_string();
        cell.configure().map_err(e)?;
        cell.activate().map_err(e)?;
        let first = cell.read().map_err(e)?;
        let mut command = CellCommand {
            arm_q: first.arm_q,
            growth_motor_rad: first.growth_motor_rad,
            twine_motor_rad: first.twine_motor_rad,
        };
        let mut previous_q = first.arm_q;
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
        }
        let mut packages_seen = 0;
        let started = Instant::now();
        for k in 1u64.. {
            if stop.load(Ordering::SeqCst) {
                return Ok(());
            }
            let new_arm_target = {
                let s = lock(&state);
                let regs = &s.inputs.values;
                let following = s.program_loaded && regs.int_registers[ENABLE_REGISTER] == 1;
                let targets: [f64; ARM_JOINTS] = std::array::from_fn(|j| regs.double_registers[TARGET_REGISTER + j]);
                // A target is new when a package came in: the arm then moves to it over the time
                // since the one before, the client's cadence, as the simulated path's arm does.
                let arrived = s.inputs.packages != packages_seen;
                packages_seen = s.inputs.packages;
                let new = following && arrived && targets.iter().all(|v| v.is_finite());
                if new {
                    command.arm_q = targets;
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
            {
                let mut s = lock(&state);
                let following = s.program_loaded && s.inputs.values.int_registers[ENABLE_REGISTER] == 1;
                // The uploaded program runs forever once loaded: PLAYING (2), else STOPPED (1).
                let runtime_state = if s.program_loaded { RUNTIME_STATE_PLAYING } else { 1 };
                let o = &mut s.outputs;
                o.runtime_state = runtime_state;
                o.timestamp_s = r.time_s;
                o.actual_qd = std::array::from_fn(|j| (r.arm_q[j] - previous_q[j]) / period_s);
                o.actual_q = r.arm_q;
                o.target_q = command.arm_q;
                o.int_registers[FOLLOWING_REGISTER] = i32::from(following);
                previous_q = r.arm_q;
                for (id, rad) in motors.into_iter().zip([r.growth_motor_rad, r.twine_motor_rad]) {
                    if let (Some(t), Ok(ticks)) = (s.bus.table_mut(id), rad_to_ticks(rad)) {
                        t.set_present_position(ticks);
                    }
                }
                let nanos = (r.time_s.fract() * 1e9) as u32;
                let frame = PeakFrame {
                    header: PeakHeader {
                        serial_number: k,
                        timestamp_s: r.time_s as u32,
                        timestamp_ns: nanos,
                        ..PeakHeader::default()
                    },
                    channels: (1..=channel)
                        .map(|c| if c == channel { vec![r.wavelengths.fbg1_nm, r.wavelengths.fbg2_nm] } else { vec![] })
                        .collect(),
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
            ticks.send_replace(k);
            let deadline = started + Duration::from_secs_f64(k as f64 * period_s);
            let now = Instant::now();
            if deadline > now {
                std::thread::sleep(deadline - now);
            }
        }
        Ok(())
    };
    Ok(std::thread::Builder::new().name("twin".into()).spawn(run)?)
}
