//! [`RealCell`]: the UR5e, the two MX-106 servos and the HYPERION behind the [`Cell`] trait.
//!
//! IO: no tick waits on a device. A small tokio runtime owns the RTDE and peak-stream reader tasks,
//! whose latest samples the control thread reads; RTDE inputs are written without blocking
//! ([`UrClient::try_send`]); the Dynamixel bus is driven by an IO thread while the cell is active
//! ([`GripperLink`]), directly at set-up and stop. Time is the wall clock since [`Cell::activate`];
//! [`Cell::wait_until`] asks for the motors' positions [`PREFETCH_BEFORE_TICK`] early, then sleeps
//! to just before the deadline and spins the rest ([`super::realtime::sleep_until`]), with the
//! activating thread's timer slack at 1 ns.
//!
//! Safety on our side (the controller's and the servos' own limits still apply):
//! - watchdog ([`Watchdog`]): a sensor, arm or motor sample older than its limit, the arm
//!   leaving running/normal mode, or the follow program no longer playing (stopped on the
//!   pendant), fails `read`; the runner then calls [`Cell::deactivate`];
//! - Ctrl-C (when [`RealCellConfig::handle_ctrl_c`]) fails the next `read` the same way (the CLI
//!   uses [`tendril_cell::interrupt`] instead, which the runner checks every tick: Ctrl-C, SIGTERM and
//!   SIGHUP alike);
//! - `deactivate` (every exit path): enable flag 0 → the URScript program `stopj`s the arm; the
//!   bus's IO thread stops and the gripper's goal = present position with torque ON (holds the
//!   object); see [`super::dxl`].
//!
//! Joint speed/acceleration limits and the force ceiling are the `tendril_control::limits::LimitedCell`
//! decorator's job.

use super::config::HardwareConfig;
use super::dashboard;
use super::dxl::GripperBus;
use super::dxl_link::{GripperLink, LinkStats};
use super::interrogator::{self, PeakFeed};
use super::ur::{self, ArmSample, UrClient};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use tendril_cell::{
    ARM_JOINTS, BLIND_TICKS, Cell, CellCommand, CellError, CellState, DeviceTiming, Lifecycle, Spread, require_state,
};
use tendril_fbg::array::ArrayPeaks;
use tendril_fbg::signals::Wavelengths;
use tendril_rtde::state::{ROBOT_MODE_RUNNING, RUNTIME_STATE_PLAYING, SAFETY_MODE_NORMAL};
use tendril_urscript::FOLLOW_SCRIPT;

/// How long before a tick [`Cell::wait_until`] asks the motors for their positions. Over the
/// virtual devices' pty the round trip takes about 0.1 ms, so the answer is there by the tick
/// unless the machine stalls (then the tick uses the previous tick's, see [`GripperLink`]); on a
/// real bus (wire time, the motors' return delay, a USB adapter's latency timer) it takes a
/// millisecond or more, of which this hides half. Short against the motors' motion: at the
/// MX-106's 45 rpm no-load speed, 0.14° in 0.5 ms.
pub const PREFETCH_BEFORE_TICK: Duration = Duration::from_micros(500);

/// The control tick the defaults assume \[s\]: 100 Hz, every shipped scenario's
/// `control_rate_hz` ([`RealCellConfig::with_control_rate`] sets another).
pub const DEFAULT_CONTROL_PERIOD_S: f64 = 0.01;

/// How old the latest sample of each device stream may be when a tick reads it before the cell
/// stops (`read` fails with a watchdog error; the runner then stops the cell safely).
///
/// The limits come from what the control needs, not from how fast a device can stream: the loop
/// may run [`BLIND_TICKS`] ticks on held values (the same budget as for invalid sensor samples),
/// and a fresh sample is up to one of its stream's periods old when a tick reads it. A stock
/// (not real-time) Linux PC does not run a process for several milliseconds every few seconds
/// (7-16 ms seen on loopback, tens of ms on a shared virtual machine), so limits of a few device
/// periods (once 5 ms for the 1 kHz peak stream, 10 ms for RTDE) stopped most runs on a healthy
/// cell; a stream that really stops is still caught within the limit plus one tick. docs/cell/timing.md#watchdogs
/// gives each limit and the measurements behind them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Watchdog {
    /// Peak samples (HYPERION stream) older than this stop the cell \[s\].
    pub sensor_stale_s: f64,
    /// Arm samples (RTDE output stream) older than this stop the cell \[s\].
    pub arm_stale_s: f64,
    /// Motor positions older than this stop the cell \[s\]; also the longest wait for a motor's
    /// reply on the bus.
    pub motor_stale_s: f64,
}

impl Watchdog {
    /// The limits for a loop ticking every `control_period_s` \[s\] that may miss [`BLIND_TICKS`]
    /// ticks' samples, with the interrogator sampling every `sensor_period_s` \[s\]: at 100 Hz and
    /// 1 kHz, 101 ms for the peaks, 102 ms for RTDE (500 Hz), 100.5 ms for the motors (asked
    /// [`PREFETCH_BEFORE_TICK`] before each tick).
    pub fn for_control(control_period_s: f64, sensor_period_s: f64) -> Watchdog {
        let blind_s = f64::from(BLIND_TICKS) * control_period_s;
        Watchdog {
            sensor_stale_s: blind_s + sensor_period_s,
            arm_stale_s: blind_s + 1.0 / ur::OUTPUT_RATE_HZ,
            motor_stale_s: blind_s + PREFETCH_BEFORE_TICK.as_secs_f64(),
        }
    }

    /// Every limit set to `stale_s` \[s\].
    pub fn uniform(stale_s: f64) -> Watchdog {
        Watchdog { sensor_stale_s: stale_s, arm_stale_s: stale_s, motor_stale_s: stale_s }
    }

    /// The motors' reply timeout.
    pub fn motor_reply_timeout(&self) -> Duration {
        Duration::from_secs_f64(self.motor_stale_s)
    }
}

/// Where the devices are and how strict the watchdog is.
#[derive(Debug, Clone, PartialEq)]
pub struct RealCellConfig {
    /// UR controller host (IP or name).
    pub ur_host: String,
    /// RTDE port (30004 on a real controller).
    pub rtde_port: u16,
    /// Secondary interface port for the URScript program (30002).
    pub script_port: u16,
    /// Dashboard server port (29999): the UR5e's preconditions are checked there before the
    /// program is uploaded ([`super::dashboard`]).
    pub dashboard_port: u16,
    /// Dynamixel serial port (`/dev/ttyUSB0`, or the pty `tendril serve` prints).
    pub dxl_port: String,
    /// Interrogator host.
    pub interrogator_host: String,
    /// HYPERION command port (51971).
    pub command_port: u16,
    /// HYPERION peak stream port (51972).
    pub stream_port: u16,
    /// Motor IDs, bus speed, FBG windows (the scenario's `[hardware]`; with a sensor array, every
    /// pad's windows, as `tendril_run::real::hardware_for` resolves them: the cell reads as many
    /// further pads as [`FbgWindows::pads`](tendril_hyperion::FbgWindows::pads) lists).
    pub hardware: HardwareConfig,
    /// Interrogator sample period \[s\] (1 kHz on the si255, docs/facts.md#hyperion-scan-rate).
    pub sensor_period_s: f64,
    /// How old each stream's latest sample may be before the cell stops.
    pub watchdog: Watchdog,
    /// Check the UR5e's preconditions on its dashboard server, then send [`RealCellConfig::program`]
    /// to the controller, at configure.
    pub upload_program: bool,
    /// The URScript program sent at configure: the follow program ([`FOLLOW_SCRIPT`]) unless a
    /// variant of it is given (it must read the registers [`tendril_urscript::input_names`] lists).
    pub program: String,
    /// Turn Ctrl-C into a clean stop (CLI runs; not in tests).
    pub handle_ctrl_c: bool,
}

impl RealCellConfig {
    /// Defaults for the given hosts and serial port: the devices' standard ports and the default
    /// `[hardware]` (IDs 1 growth, 2 twine at 57 600 baud, default FBG windows).
    pub fn new(ur_host: &str, dxl_port: &str, interrogator_host: &str) -> RealCellConfig {
        RealCellConfig {
            ur_host: ur_host.into(),
            rtde_port: 30004,
            script_port: 30002,
            dashboard_port: 29999,
            dxl_port: dxl_port.into(),
            interrogator_host: interrogator_host.into(),
            command_port: 51971,
            stream_port: 51972,
            hardware: HardwareConfig::default(),
            sensor_period_s: 1e-3,
            watchdog: Watchdog::for_control(DEFAULT_CONTROL_PERIOD_S, 1e-3),
            upload_program: true,
            program: FOLLOW_SCRIPT.to_string(),
            handle_ctrl_c: false,
        }
    }

    /// The watchdog for a control loop ticking at `rate_hz` \[Hz\] ([`Watchdog::for_control`]).
    pub fn with_control_rate(mut self, rate_hz: f64) -> RealCellConfig {
        self.watchdog = Watchdog::for_control(1.0 / rate_hz, self.sensor_period_s);
        self
    }

    /// Ports `base` (RTDE), `base+1` (URScript), `base+2` (HYPERION commands), `base+3` (peaks),
    /// `base+4` (dashboard), as `tendril serve --port-base` lays them out.
    pub fn with_port_base(mut self, base: u16) -> RealCellConfig {
        [self.rtde_port, self.script_port, self.command_port, self.stream_port, self.dashboard_port] =
            [0, 1, 2, 3, 4].map(|i| base + i);
        self
    }
}

/// The gripper bus: driven directly while the cell is inactive, by its IO thread while active.
enum Gripper {
    Direct(GripperBus),
    Linked(GripperLink),
    /// The IO thread could not be started or panicked; the bus went with it.
    Lost,
}

struct Devices {
    ur: UrClient,
    gripper: Gripper,
    peaks: Arc<Mutex<PeakFeed>>,
    peak_task: tokio::task::JoinHandle<()>,
}

/// The devices' latest samples, as a tick reads them.
struct Latest {
    arm: ArmSample,
    arm_age: Duration,
    wavelengths: Wavelengths,
    /// The further pads' peaks (a sensor array's; empty without one).
    array: ArrayPeaks,
    /// Why the newest scans could not be mapped to the pads, if they could not.
    unmapped: Option<String>,
    /// Scan serial number of the peak sample.
    serial: u64,
    sensor_age: Duration,
    motors_rad: [f64; 2],
    motor_age: Duration,
    tool_load_n: Option<f64>,
}

impl Devices {
    /// The streams' latest samples and their ages; an error when a stream has ended or brought
    /// nothing yet.
    fn latest(&self) -> Result<Latest, CellError> {
        let (arm, arm_age) =
            self.ur.latest().map_err(|e| device("UR5e", e))?.ok_or_else(|| device("UR5e", "no data"))?;
        let ((sample, sensor_at, serial), unmapped) = {
            let feed = self.peaks.lock().unwrap_or_else(|p| p.into_inner());
            if let Some(why) = &feed.closed {
                return Err(device("HYPERION", why));
            }
            let no_data = || device("HYPERION", feed.unmapped.as_deref().unwrap_or("no data"));
            (feed.latest.ok_or_else(no_data)?, feed.unmapped.clone())
        };
        let motors = self.gripper.link()?.latest().map_err(|e| device("MX-106", e))?;
        Ok(Latest {
            arm,
            arm_age,
            wavelengths: sample.first,
            array: sample.array,
            unmapped,
            serial,
            sensor_age: sensor_at.elapsed(),
            motors_rad: motors.rad,
            motor_age: motors.requested_at.elapsed(),
            tool_load_n: self.ur.take_tool_load(),
        })
    }
}

impl Watchdog {
    /// A watchdog error for the first stream whose latest sample is older than its limit.
    fn check(&self, l: &Latest) -> Result<(), CellError> {
        let streams = [
            ("UR5e", "RTDE sample", l.arm_age, self.arm_stale_s),
            ("HYPERION", "peak sample", l.sensor_age, self.sensor_stale_s),
            ("MX-106", "motor positions", l.motor_age, self.motor_stale_s),
        ];
        for (name, what, age, limit_s) in streams {
            if age.as_secs_f64() > limit_s {
                let (age_ms, limit_ms) = (age.as_secs_f64() * 1e3, limit_s * 1e3);
                let mut why = format!("watchdog: last {what} {age_ms:.1} ms old (limit {limit_ms:.0} ms)");
                // Peaks that arrive but do not map: say why.
                if let (true, Some(unmapped)) = (name == "HYPERION", &l.unmapped) {
                    why.push_str(&format!("; the newest do not map to the pads: {unmapped}"));
                }
                return Err(device(name, why));
            }
        }
        Ok(())
    }
}

/// What [`Cell::device_timing`] is made from: every tick's sample ages and lateness \[s\].
#[derive(Debug, Default)]
struct TimingLog {
    sensor_s: Vec<f64>,
    arm_s: Vec<f64>,
    motor_s: Vec<f64>,
    late_s: Vec<f64>,
}

impl TimingLog {
    fn record(&mut self, l: &Latest) {
        self.sensor_s.push(l.sensor_age.as_secs_f64());
        self.arm_s.push(l.arm_age.as_secs_f64());
        self.motor_s.push(l.motor_age.as_secs_f64());
    }

    fn summary(&self, w: &Watchdog) -> DeviceTiming {
        DeviceTiming {
            sensor_age: Spread::of(&self.sensor_s),
            arm_age: Spread::of(&self.arm_s),
            motor_age: Spread::of(&self.motor_s),
            tick_late: Spread::of(&self.late_s),
            watchdog_ms: [w.sensor_stale_s, w.arm_stale_s, w.motor_stale_s].map(|s| s * 1e3),
        }
    }
}

/// The real gripping cell.
pub struct RealCell {
    config: RealCellConfig,
    runtime: Option<tokio::runtime::Runtime>,
    devices: Option<Devices>,
    lifecycle: Lifecycle,
    started: Instant,
    stop: Arc<AtomicBool>,
    last_arm_q: Option<[f64; ARM_JOINTS]>,
    /// Cell time of the last `read` \[s\]: the time the next arm target is for.
    last_read_s: f64,
    /// Scan serial number of the peak sample the last `read` returned.
    last_serial: Option<u64>,
    /// Whether that sample is another scan than the one before ([`Cell::sample_is_new`]).
    sample_is_new: bool,
    /// Sample ages and tick lateness, for [`Cell::device_timing`].
    timing: TimingLog,
    /// The deadline the last `wait_until` waited for.
    deadline: Option<Instant>,
    /// Freshness of the motor positions of activations already ended.
    motor_stats: LinkStats,
    /// Serial number and channel count read at configure.
    pub identity: Option<interrogator::Identity>,
}

fn device(name: &str, cause: impl std::fmt::Display) -> CellError {
    CellError::Device { device: name.into(), cause: cause.to_string() }
}

impl RealCell {
    /// A cell for `config`; nothing is contacted until [`Cell::configure`].
    pub fn new(config: RealCellConfig) -> RealCell {
        RealCell {
            config,
            runtime: None,
            devices: None,
            lifecycle: Lifecycle::Unconfigured,
            started: Instant::now(),
            stop: Arc::new(AtomicBool::new(false)),
            last_arm_q: None,
            last_read_s: 0.0,
            timing: TimingLog::default(),
            deadline: None,
            last_serial: None,
            sample_is_new: true,
            motor_stats: LinkStats::default(),
            identity: None,
        }
    }

    /// A flag that makes the next `read` fail (an operator stop); shared with signal handlers.
    pub fn stop_flag(&self) -> Arc<AtomicBool> {
        self.stop.clone()
    }

    /// How fresh the motor positions the ticks used were, over every activation so far.
    pub fn motor_stats(&self) -> LinkStats {
        let mut stats = self.motor_stats;
        if let Some(Devices { gripper: Gripper::Linked(link), .. }) = &self.devices {
            stats += link.stats();
        }
        stats
    }

    fn parts(&mut self) -> (&tokio::runtime::Runtime, &mut Devices) {
        let rt = self.runtime.as_ref().expect("configured: the lifecycle checks guarantee it");
        let d = self.devices.as_mut().expect("configured: the lifecycle checks guarantee it");
        (rt, d)
    }

    fn connect(&mut self) -> Result<(), CellError> {
        let c = self.config.clone();
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(1)
            .enable_all()
            .build()
            .map_err(|e| CellError::Configure(format!("tokio runtime: {e}")))?;
        let ur_addr = format!("{}:{}", c.ur_host, c.rtde_port);
        let script_addr = format!("{}:{}", c.ur_host, c.script_port);
        let dashboard_addr = format!("{}:{}", c.ur_host, c.dashboard_port);
        let cmd_addr = format!("{}:{}", c.interrogator_host, c.command_port);
        let stream_addr = format!("{}:{}", c.interrogator_host, c.stream_port);
        let (ur, identity, (peaks, peak_task)) = runtime
            .block_on(async {
                if c.upload_program {
                    dashboard::check_ready(&dashboard_addr).await.map_err(|e| e.to_string())?;
                }
                let ur = UrClient::connect(&ur_addr).await?;
                if c.upload_program {
                    ur::upload_program(&script_addr, &c.program).await?;
                }
                let identity = interrogator::identify(&cmd_addr, &c.hardware.fbg).await?;
                let stream = interrogator::stream(&stream_addr, c.hardware.fbg).await?;
                Ok::<_, String>((ur, identity, stream))
            })
            .map_err(CellError::Configure)?;
        if c.handle_ctrl_c {
            let stop = self.stop.clone();
            runtime.spawn(async move {
                if tokio::signal::ctrl_c().await.is_ok() {
                    stop.store(true, Ordering::SeqCst);
                }
            });
        }
        let h = c.hardware;
        let gripper = GripperBus::open(&c.dxl_port, h.dxl_baud, h.motor_ids(), c.watchdog.motor_reply_timeout())
            .map_err(CellError::Configure)?;
        self.identity = Some(identity);
        self.runtime = Some(runtime);
        self.devices = Some(Devices { ur, gripper: Gripper::Direct(gripper), peaks, peak_task });
        // The first samples of both streams must arrive before the cell counts as configured.
        let deadline = Instant::now() + Duration::from_secs(2);
        loop {
            let d = self.devices.as_ref().expect("just set");
            let arm = d.ur.latest().map_err(CellError::Configure)?;
            let sensor = d.peaks.lock().unwrap_or_else(|p| p.into_inner()).latest.is_some();
            // The follow program must be playing before the cell may move the arm.
            if let Some((s, _)) = arm
                && sensor
                && (s.runtime_state == RUNTIME_STATE_PLAYING || !c.upload_program)
            {
                self.last_arm_q = Some(s.q);
                return Ok(());
            }
            if Instant::now() > deadline {
                let why = match arm {
                    None => "no RTDE data package from the UR5e".to_string(),
                    Some(_) if !sensor => match d.peaks.lock().unwrap_or_else(|p| p.into_inner()).unmapped.clone() {
                        Some(why) => format!("no peak frame with every grating in its window ({why})"),
                        None => "no peak frame from the interrogator".to_string(),
                    },
                    Some((s, _)) => format!(
                        "the follow program is not playing (RTDE runtime_state {}, robot_mode {}, safety_mode {})",
                        s.runtime_state, s.robot_mode, s.safety_mode
                    ),
                };
                return Err(CellError::Configure(format!("within 2 s of connecting: {why}")));
            }
            std::thread::sleep(Duration::from_millis(2));
        }
    }
}

impl Cell for RealCell {
    fn backend(&self) -> &str {
        "real"
    }

    fn lifecycle(&self) -> Lifecycle {
        self.lifecycle
    }

    fn configure(&mut self) -> Result<(), CellError> {
        require_state(self.lifecycle, Lifecycle::Unconfigured, "configure")?;
        self.connect()?;
        self.lifecycle = Lifecycle::Inactive;
        Ok(())
    }

    fn activate(&mut self) -> Result<(), CellError> {
        require_state(self.lifecycle, Lifecycle::Inactive, "activate")?;
        // The thread that activates is the one that runs the ticks: its sleeps should end on time,
        // and the bus's IO thread, started from it, runs at its priority on its CPU.
        super::realtime::set_timer_slack_ns(1);
        let (_, d) = self.parts();
        let linked;
        (d.gripper, linked) = std::mem::replace(&mut d.gripper, Gripper::Lost).start_link();
        linked.map_err(|e| device("MX-106", e))?;
        self.started = Instant::now();
        self.lifecycle = Lifecycle::Active;
        Ok(())
    }

    fn deactivate(&mut self) -> Result<(), CellError> {
        if self.lifecycle != Lifecycle::Active {
            return Ok(());
        }
        self.lifecycle = Lifecycle::Inactive;
        let q = self.last_arm_q.unwrap_or([0.0; ARM_JOINTS]);
        let stamp_s = self.last_read_s;
        let (rt, d) = self.parts();
        // Both stops are attempted even if the first fails.
        let arm = rt.block_on(d.ur.send(q, stamp_s, false)).map_err(|e| device("UR5e", e));
        let (hand, stats);
        (d.gripper, stats, hand) = std::mem::replace(&mut d.gripper, Gripper::Lost).stop_link_and_hold();
        self.motor_stats += stats;
        arm.and(hand.map_err(|e| device("MX-106", e)))
    }

    fn read(&mut self) -> Result<CellState, CellError> {
        require_state(self.lifecycle, Lifecycle::Active, "read")?;
        if self.stop.load(Ordering::SeqCst) {
            return Err(device("operator", "stop requested (Ctrl-C)"));
        }
        let now = Instant::now();
        let time_s = now.duration_since(self.started).as_secs_f64();
        if let Some(deadline) = self.deadline.take() {
            self.timing.late_s.push(now.saturating_duration_since(deadline).as_secs_f64());
        }
        let upload = self.config.upload_program;
        let watchdog = self.config.watchdog;
        let (_, d) = self.parts();
        let latest = d.latest()?;
        self.timing.record(&latest);
        let arm = latest.arm;
        watchdog.check(&latest)?;
        if arm.robot_mode != ROBOT_MODE_RUNNING || arm.safety_mode != SAFETY_MODE_NORMAL {
            return Err(device("UR5e", format!("robot mode {} safety mode {}", arm.robot_mode, arm.safety_mode)));
        }
        if upload && arm.runtime_state != RUNTIME_STATE_PLAYING {
            return Err(device("UR5e", format!("follow program not playing (runtime state {})", arm.runtime_state)));
        }
        self.last_arm_q = Some(arm.q);
        self.last_read_s = time_s;
        self.sample_is_new = self.last_serial != Some(latest.serial);
        self.last_serial = Some(latest.serial);
        let [growth_motor_rad, twine_motor_rad] = latest.motors_rad;
        Ok(CellState {
            time_s,
            arm_q: arm.q,
            growth_motor_rad,
            twine_motor_rad,
            wavelengths: latest.wavelengths,
            array: latest.array,
            tool_load_n: latest.tool_load_n,
        })
    }

    fn write(&mut self, c: &CellCommand) -> Result<(), CellError> {
        require_state(self.lifecycle, Lifecycle::Active, "write")?;
        if c.arm_q.iter().chain([&c.growth_motor_rad, &c.twine_motor_rad]).any(|v| !v.is_finite()) {
            return Err(device("command", format!("non-finite target {c:?}")));
        }
        // The target is the plan's at the last read: stamped with that read's time, the follow
        // program plays it back at that time, whenever the package arrives.
        let stamp_s = self.last_read_s;
        let (_, d) = self.parts();
        d.ur.try_send(c.arm_q, stamp_s, true).map_err(|e| device("UR5e", e))?;
        d.gripper.link()?.set_goal_rad([c.growth_motor_rad, c.twine_motor_rad]);
        Ok(())
    }

    fn device_timing(&self) -> Option<DeviceTiming> {
        Some(self.timing.summary(&self.config.watchdog))
    }

    /// No new scan came since the read before (the stream was late by a tick or more): the runner
    /// holds the last estimate rather than feeding the estimator the same scan twice.
    fn sample_is_new(&self) -> bool {
        self.sample_is_new
    }

    fn wait_until(&mut self, time_s: f64) -> Result<(), CellError> {
        require_state(self.lifecycle, Lifecycle::Active, "wait")?;
        let deadline = self.started + Duration::from_secs_f64(time_s.max(0.0));
        // The motors' positions are asked for shortly before the tick: `read` then finds the
        // replies waiting instead of waiting a bus round trip for them.
        if let Some(early) = deadline.checked_sub(PREFETCH_BEFORE_TICK) {
            let now = Instant::now();
            if early > now {
                std::thread::sleep(early - now);
            }
        }
        let (_, d) = self.parts();
        d.gripper.link()?.request_present();
        super::realtime::sleep_until(deadline);
        self.deadline = Some(deadline);
        Ok(())
    }
}

/// Why the gripper can no longer be driven.
const BUS_LOST: &str = "bus lost with its IO thread";

impl Gripper {
    /// Hands the bus to its IO thread, with positions read now as the first sample (the bus stays
    /// direct if they cannot be read).
    fn start_link(self) -> (Gripper, Result<(), String>) {
        match self {
            Gripper::Direct(mut bus) => match bus.present_rad() {
                Ok(first) => match GripperLink::start(bus, first) {
                    Ok(link) => (Gripper::Linked(link), Ok(())),
                    Err(why) => (Gripper::Lost, Err(why)),
                },
                Err(why) => (Gripper::Direct(bus), Err(why)),
            },
            linked @ Gripper::Linked(_) => (linked, Ok(())),
            Gripper::Lost => (Gripper::Lost, Err(BUS_LOST.into())),
        }
    }

    /// Stops the IO thread and puts the motors in their safe state directly; also returns how
    /// fresh the positions the ticks used were.
    fn stop_link_and_hold(self) -> (Gripper, LinkStats, Result<(), String>) {
        let (bus, stats) = match self {
            Gripper::Linked(link) => {
                let stats = link.stats();
                (link.stop(), stats)
            }
            Gripper::Direct(bus) => (Ok(bus), LinkStats::default()),
            Gripper::Lost => (Err(BUS_LOST.into()), LinkStats::default()),
        };
        match bus {
            Ok(mut bus) => {
                let held = bus.hold();
                (Gripper::Direct(bus), stats, held)
            }
            Err(why) => (Gripper::Lost, stats, Err(why)),
        }
    }

    /// The IO thread's end of the bus (the cell is active).
    fn link(&self) -> Result<&GripperLink, CellError> {
        match self {
            Gripper::Linked(link) => Ok(link),
            _ => Err(device("MX-106", "bus not driven while the cell is inactive")),
        }
    }
}

impl Drop for RealCell {
    fn drop(&mut self) {
        let _ = self.deactivate();
        if let Some(d) = self.devices.take() {
            d.peak_task.abort();
            drop(d);
        }
        if let Some(rt) = self.runtime.take() {
            rt.shutdown_background();
        }
    }
}
