//! What the virtual devices share: the UR5e's RTDE inputs and outputs, its program and controller
//! state, the MX-106 pair, the interrogator, and the twin's latest status.

use super::arrival::ProgramInputs;
use super::controller::{UrController, VirtualUrSetup};
use std::sync::{Arc, Mutex};
use tendril_cell::{ARM_JOINTS, GroundTruth};
use tendril_drivers::HardwareConfig;
use tendril_dynamixel::VirtualBus;
use tendril_dynamixel::control_table::addr;
use tendril_dynamixel::units::baud_rate_code;
use tendril_fbg::SpectralConfig;
use tendril_fbg::signals::Wavelengths;
use tendril_hyperion::{InterrogatorConfig, VirtualInterrogator};
use tendril_rtde::{RobotOutputs, SharedInputs};
use tendril_urscript::{RtdeWatchdog, Setup};

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

/// The uploaded program's state, as `runtime_state` reports it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProgramState {
    /// No program, or it was stopped (by its RTDE watchdog or a protective stop): STOPPED (1).
    Stopped,
    /// Running: PLAYING (2).
    Playing,
    /// Paused by its RTDE watchdog (action "pause"): PAUSED (4).
    Paused,
}

/// Everything the protocol servers and the twin share.
pub struct DeviceState {
    /// What the virtual UR5e reports.
    pub outputs: RobotOutputs,
    /// What RTDE clients wrote, as they arrive.
    pub inputs: SharedInputs,
    /// What RTDE clients wrote, as the program sees it: from the twin time each package arrived at.
    pub program_inputs: ProgramInputs,
    /// The program's state: it plays from its upload until it ends, fails, or its RTDE watchdog,
    /// a protective stop or the dashboard stops it ([`super::program`]).
    pub program: ProgramState,
    /// The text of the last program uploaded (`None`: the follow program, as `load X.urp` gives).
    pub program_source: Option<String>,
    /// The watchdog the running program set with `rtde_set_watchdog`, if any.
    pub watchdog: Option<RtdeWatchdog>,
    /// Programs uploaded so far (each upload restarts the program and its watchdog).
    pub program_uploads: u64,
    /// The program's `textmsg`/`popup` lines and runtime errors, the latest
    /// [`super::program::LOG_LINES`].
    pub program_log: std::collections::VecDeque<String>,
    /// Why the arm is in a protective stop, if it is (cleared by `unlock protective stop` on the
    /// dashboard, or by a fresh program upload).
    pub protective_stop: Option<String>,
    /// Secondary programs (`sec`) received and not started yet.
    pub secondary_programs: std::collections::VecDeque<String>,
    /// The controller settings the running program made (TCP, payload, gravity, ...), as the
    /// devices report them; the defaults when no program has set them.
    pub program_setup: Setup,
    /// The program's sockets ([`super::sockets`]).
    pub sockets: super::sockets::ProgramSockets,
    /// The robot messages for the primary interface ([`super::robot_messages`]).
    pub robot_messages: super::robot_messages::RobotMessages,
    /// The wrench the twin's wrist sensor measures, before the program's `zero_ftsensor`
    /// offset (`outputs.actual_tcp_force` is after it) \[N, N·m\].
    pub tcp_force_raw: [f64; 6],
    /// Robot mode, remote control, PolyScope version, loaded program ([`super::dashboard`]).
    pub ur: UrController,
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
/// motors at `hardware`'s IDs and bus speed, an interrogator with enough channels for its FBG
/// channels (every pad's), whose `#GetSpectrum` draws lines as `spectral` describes them.
pub fn shared_state(
    hardware: &HardwareConfig,
    spectral: &SpectralConfig,
    ur: &VirtualUrSetup,
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
    // channels (pad 0's and a sensor array's further pads') need more.
    let channel_count = [4, 8, 16].into_iter().find(|&n| n >= hardware.fbg.highest_channel()).unwrap_or(16) as u32;
    let interrogator = VirtualInterrogator::new(InterrogatorConfig {
        channel_count,
        spectral: spectral.clone(),
        ..InterrogatorConfig::default()
    })
    .map_err(|e| anyhow::anyhow!("virtual interrogator: {e}"))?;
    let state = DeviceState {
        outputs: RobotOutputs::default(),
        inputs: SharedInputs::new(),
        program_inputs: ProgramInputs::default(),
        program: ProgramState::Stopped,
        program_source: None,
        watchdog: None,
        program_uploads: 0,
        program_log: std::collections::VecDeque::new(),
        protective_stop: None,
        secondary_programs: std::collections::VecDeque::new(),
        program_setup: Setup::default(),
        sockets: super::sockets::ProgramSockets::default(),
        robot_messages: super::robot_messages::RobotMessages::default(),
        tcp_force_raw: [0.0; 6],
        ur: UrController::new(ur),
        bus,
        interrogator,
        status: TwinStatus::default(),
        next_session: 1,
    };
    Ok((Arc::new(Mutex::new(state)), tokio::sync::watch::channel(0).0))
}

/// The devices' state, locked (a panicked holder's state is still used: it is plain data).
pub fn lock(state: &Mutex<DeviceState>) -> std::sync::MutexGuard<'_, DeviceState> {
    state.lock().unwrap_or_else(|p| p.into_inner())
}
