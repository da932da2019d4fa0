//! Virtual devices: the twin ([`crate::cell::sim::SimCell`] stepped in real time) behind the real protocols.
//!
//! - RTDE on `rtde_port` (30004) and URScript on `script_port` (30002) and `realtime_script_port`
//!   (30003), a dashboard server on `dashboard_port` (29999, [`dashboard`]): the virtual
//!   controller runs an uploaded program with its URScript interpreter
//!   ([`crate::cell::real::urscript`], [`program`]), our follow program and SDU ur_rtde's control
//!   script alike. Its `rtde_set_watchdog` call is honoured (the program stops or pauses when the
//!   watched input is not written in time); setpoints beyond the UR5e's joint range or speed, or
//!   non-finite, put the arm in a protective stop ([`safety`]) until unlocked on the dashboard or a
//!   fresh program upload. IO outputs and the speed slider follow RTDE inputs ([`io`]).
//!   `actual_TCP_pose` and `target_TCP_pose` come from [`pose`].
//! - Dynamixel: two MX-106 at the scenario's `hardware.growth_id` and `hardware.twine_id` (1, 2 by
//!   default) on a pseudo-terminal (its path in [`ServeHandle::pty_path`]); Goal Position drives
//!   the twin's motors, Present Position reports them; Baud Rate reads `hardware.dxl_baud`.
//! - HYPERION: commands on `command_port` (51971), one scan per twin tick (a new interrogator
//!   sample each, the pad force held between physics steps), every scan streamed on `stream_port`
//!   (51972) to a reader that keeps up (serial numbers consecutive; every n-th with the streaming
//!   divider); FBG1 and FBG2 on channel `hardware.fbg.channel`, at the wavelengths the twin's
//!   sensor model gives; `#GetSpectrum` draws them with the scenario's spectral line model.
//!
//! Malformed input: RTDE and HYPERION connections are closed on a framing error (after the
//! device's error reply where the protocol has one); the bus drops corrupt packets as a device does.
//! Nothing here panics on input.

pub mod dashboard;
pub mod io;
pub mod jitter;
mod net;
pub mod pose;
pub mod program;
pub mod safety;
mod setpoint;
mod twin;

use crate::cell::real::HardwareConfig;
use crate::cell::real::realtime::RealtimeOptions;
use crate::run::scenario::PickPlaceScenario;
use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

pub use dashboard::{UrController, VirtualUrSetup};
pub use jitter::{Jitter, JitterModel, JitterProfile};
pub use twin::{DeviceState, ProgramState, TwinStatus};

/// Where the virtual devices listen and how fast the twin runs.
#[derive(Debug, Clone, PartialEq)]
pub struct ServeConfig {
    /// Address to bind (loopback unless asked otherwise).
    pub bind: IpAddr,
    /// RTDE port.
    pub rtde_port: u16,
    /// URScript secondary interface port (30002).
    pub script_port: u16,
    /// URScript real-time interface port (30003): takes programs as the secondary one does.
    pub realtime_script_port: u16,
    /// UR Dashboard Server port (29999).
    pub dashboard_port: u16,
    /// The state the virtual UR5e starts in: remote or local control, robot mode, PolyScope
    /// version ([`dashboard`]).
    pub ur: VirtualUrSetup,
    /// HYPERION command port.
    pub command_port: u16,
    /// HYPERION peak stream port.
    pub stream_port: u16,
    /// Twin tick \[s\]: the RTDE output and peak stream period. 1 ms = the si255's 1 kHz scan rate.
    pub period_s: f64,
    /// Scheduling of the twin, bus and network threads (default: normal). The virtual devices
    /// stand in for dedicated hardware; on a shared machine a `SCHED_FIFO` priority keeps them from
    /// waiting behind other processes, and a CPU of their own keeps them off the control thread's.
    pub realtime: RealtimeOptions,
    /// An RTDE or HYPERION command connection on which nothing is received or sent for this long is
    /// closed (default [`IDLE_TIMEOUT`]); see `docs/hardware.md`.
    pub idle_timeout: Duration,
    /// Timing faults injected into the RTDE streams (both ways), the peak stream and the Dynamixel
    /// bus ([`jitter`]; default none).
    pub jitter: Option<Jitter>,
}

/// How long an RTDE or HYPERION command connection may stay silent both ways before the virtual
/// device closes it: 30 s. Why: a live client talks far more often (ours sends RTDE inputs every
/// tick and takes an RTDE output package every millisecond once started; a HYPERION command is a
/// request and its reply on a fresh connection), so 30 s of silence is a client that is gone
/// or stuck, and each such connection would otherwise hold a socket and a task for ever.
pub const IDLE_TIMEOUT: Duration = Duration::from_secs(30);

impl ServeConfig {
    /// The real devices' ports on 127.0.0.1.
    pub fn loopback() -> ServeConfig {
        ServeConfig {
            bind: IpAddr::V4(Ipv4Addr::LOCALHOST),
            rtde_port: 30004,
            script_port: 30002,
            realtime_script_port: 30003,
            dashboard_port: 29999,
            ur: VirtualUrSetup::default(),
            command_port: 51971,
            stream_port: 51972,
            period_s: 1e-3,
            realtime: RealtimeOptions::default(),
            idle_timeout: IDLE_TIMEOUT,
            jitter: None,
        }
    }

    /// [`ServeConfig::loopback`] on ports the system picks (each listener its own free port; the
    /// [`ServeHandle`] tells which): for runs and tests side by side that must not collide.
    pub fn ephemeral() -> ServeConfig {
        ServeConfig {
            rtde_port: 0,
            script_port: 0,
            realtime_script_port: 0,
            dashboard_port: 0,
            command_port: 0,
            stream_port: 0,
            ..ServeConfig::loopback()
        }
    }

    /// Ports `base`, `base+1`, `base+2`, `base+3`, `base+4`, `base+5` for RTDE, URScript
    /// (secondary), HYPERION commands and stream, the dashboard server and URScript (real-time)
    /// (tests and benchmarks use distinct bases so they never collide).
    pub fn with_port_base(mut self, base: u16) -> ServeConfig {
        self.rtde_port = base;
        self.script_port = base + 1;
        self.command_port = base + 2;
        self.stream_port = base + 3;
        self.dashboard_port = base + 4;
        self.realtime_script_port = base + 5;
        self
    }
}

/// The virtual UR5e's addresses besides RTDE and the secondary script port.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UrAddrs {
    /// Dashboard server (29999).
    pub dashboard: SocketAddr,
    /// Real-time interface script port (30003).
    pub realtime_script: SocketAddr,
}

/// The running virtual devices; dropping it stops them.
pub struct ServeHandle {
    /// Path of the Dynamixel pseudo-terminal.
    pub pty_path: PathBuf,
    /// Addresses bound: RTDE, URScript, HYPERION commands, HYPERION stream.
    pub addrs: [SocketAddr; 4],
    /// Addresses bound for the UR's dashboard server and real-time script port.
    pub ur_addrs: UrAddrs,
    /// The devices' shared state (for tests comparing with the twin).
    pub state: Arc<std::sync::Mutex<DeviceState>>,
    /// The motor IDs, bus speed and FBG channel served (the scenario's `[hardware]`).
    pub hardware: HardwareConfig,
    stop: Arc<AtomicBool>,
    twin: Option<std::thread::JoinHandle<Result<(), String>>>,
    bus: Option<std::thread::JoinHandle<()>>,
    runtime: Option<tokio::runtime::Runtime>,
}

impl ServeHandle {
    /// Whether the twin still runs (false after a physics failure or `stop`).
    pub fn running(&self) -> bool {
        self.twin.as_ref().is_some_and(|t| !t.is_finished())
    }

    /// Stops everything and returns the twin's error, if it failed.
    pub fn stop(mut self) -> Result<(), String> {
        self.shutdown()
    }

    fn shutdown(&mut self) -> Result<(), String> {
        self.stop.store(true, Ordering::SeqCst);
        if let Some(rt) = self.runtime.take() {
            rt.shutdown_background();
        }
        if let Some(b) = self.bus.take() {
            let _ = b.join();
        }
        match self.twin.take().map(|t| t.join()) {
            Some(Ok(r)) => r,
            Some(Err(_)) => Err("twin thread panicked".into()),
            None => Ok(()),
        }
    }
}

impl Drop for ServeHandle {
    fn drop(&mut self) {
        let _ = self.shutdown();
    }
}

/// Starts the twin and the virtual devices. Returns once everything listens.
pub fn start(scenario: &PickPlaceScenario, config: &ServeConfig) -> anyhow::Result<ServeHandle> {
    anyhow::ensure!(config.period_s > 0.0 && config.period_s <= 0.01, "twin period must be in (0, 10 ms]");
    let stop = Arc::new(AtomicBool::new(false));
    let hardware = scenario.hardware;
    let (state, ticks) = twin::shared_state(&hardware, &scenario.interrogator.spectral, &config.ur)?;
    let rt = config.realtime;
    // Fail early and clearly rather than in each thread.
    let probe = std::thread::spawn(move || rt.apply_to_current_thread());
    probe.join().map_err(|_| anyhow::anyhow!("scheduling probe panicked"))??;
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(1)
        .enable_all()
        .on_thread_start(move || {
            let _ = rt.apply_to_current_thread();
        })
        .build()?;
    // Time 0 of the injected jitter's clock.
    let epoch = std::time::Instant::now();
    let (addrs, ur_addrs) = runtime.block_on(net::listen_all(config, state.clone(), ticks.subscribe(), epoch))?;
    let (pty_path, bus) = twin::open_bus(state.clone(), stop.clone(), rt, config.jitter, epoch)?;
    let twin = twin::spawn(scenario.clone(), config.period_s, state.clone(), ticks, stop.clone(), rt)?;
    Ok(ServeHandle {
        pty_path,
        addrs,
        ur_addrs,
        state,
        hardware,
        stop,
        twin: Some(twin),
        bus: Some(bus),
        runtime: Some(runtime),
    })
}
