//! Starting the virtual devices ([`start`]) and the handle that stops them ([`ServeHandle`]).

use super::config::{ServeConfig, UrAddrs};
use super::state::{DeviceState, shared_state};
use super::{bus, net, twin};
use std::net::SocketAddr;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use tendril_drivers::{HardwareConfig, RealCellConfig};
use tendril_run::scenario::PickPlaceScenario;

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
    /// The motor IDs, bus speed and FBG windows served (the scenario's `[hardware]`, with a sensor
    /// array's further pads' windows).
    pub hardware: HardwareConfig,
    stop: Arc<AtomicBool>,
    twin: Option<std::thread::JoinHandle<Result<(), String>>>,
    bus: Option<std::thread::JoinHandle<()>>,
    runtime: Option<tokio::runtime::Runtime>,
}

impl ServeHandle {
    /// A real cell's configuration for these devices: their loopback ports, their pty, the
    /// `[hardware]` they serve, the default watchdogs.
    pub fn real_cell_config(&self) -> RealCellConfig {
        let ip = self.addrs[0].ip();
        let host = if ip.is_unspecified() { "127.0.0.1".to_string() } else { ip.to_string() };
        let mut c = RealCellConfig::new(&host, &self.pty_path.to_string_lossy(), &host);
        [c.rtde_port, c.script_port, c.command_port, c.stream_port] = self.addrs.map(|a| a.port());
        c.dashboard_port = self.ur_addrs.dashboard.port();
        c.hardware = self.hardware;
        c
    }

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
    // With a sensor array, every pad's windows (given, or derived from the layout): the real
    // cell `real_cell_config` describes reads every pad.
    let hardware = tendril_run::real::hardware_for(scenario)?;
    let (state, ticks) = shared_state(&hardware, &scenario.interrogator.spectral, &config.ur)?;
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
    let (pty_path, bus) = bus::open_bus(state.clone(), stop.clone(), rt, config.jitter, epoch)?;
    let twin = twin::spawn(scenario.clone(), config, state.clone(), ticks, stop.clone())?;
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
