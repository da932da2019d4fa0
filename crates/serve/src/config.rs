//! [`ServeConfig`]: where the virtual devices listen, how fast the twin runs, what timing faults
//! they inject.

use super::controller::VirtualUrSetup;
use super::jitter::Jitter;
use super::ros2::Ros2Serving;
use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::time::Duration;
use tendril_drivers::realtime::RealtimeOptions;

/// Where the virtual devices listen and how fast the twin runs.
#[derive(Debug, Clone, PartialEq)]
pub struct ServeConfig {
    /// Address to bind (loopback unless asked otherwise).
    pub bind: IpAddr,
    /// RTDE port.
    pub rtde_port: u16,
    /// URScript secondary interface port (30002).
    pub script_port: u16,
    /// Primary interface port (30001): robot state and messages, and URScript.
    pub primary_port: u16,
    /// Hosts a program's `socket_open` may reach besides loopback (none by default; see
    /// [`crate::sockets`]).
    pub script_hosts: Vec<IpAddr>,
    /// URScript real-time interface port (30003): takes programs as the secondary one does.
    pub realtime_script_port: u16,
    /// UR Dashboard Server port (29999).
    pub dashboard_port: u16,
    /// The state the virtual UR5e starts in: remote or local control, robot mode, PolyScope
    /// version ([`crate::dashboard`]).
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
    /// closed (default [`IDLE_TIMEOUT`]); see `docs/cell/virtual-devices.md`.
    pub idle_timeout: Duration,
    /// Timing faults injected into the RTDE streams (both ways), the peak stream and the Dynamixel
    /// bus ([`crate::jitter`]; default none).
    pub jitter: Option<Jitter>,
    /// Put the twin on the scenario's ROS 2 graph too (`--ros2`, [`crate::ros2`]; default off).
    pub ros2: Option<Ros2Serving>,
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
            primary_port: 30001,
            script_hosts: Vec::new(),
            realtime_script_port: 30003,
            dashboard_port: 29999,
            ur: VirtualUrSetup::default(),
            command_port: 51971,
            stream_port: 51972,
            period_s: 1e-3,
            realtime: RealtimeOptions::default(),
            idle_timeout: IDLE_TIMEOUT,
            jitter: None,
            ros2: None,
        }
    }

    /// [`ServeConfig::loopback`] on ports the system picks (each listener its own free port; the
    /// [`crate::ServeHandle`] tells which): for runs and tests side by side that must not collide.
    pub fn ephemeral() -> ServeConfig {
        ServeConfig {
            rtde_port: 0,
            script_port: 0,
            primary_port: 0,
            realtime_script_port: 0,
            dashboard_port: 0,
            command_port: 0,
            stream_port: 0,
            ..ServeConfig::loopback()
        }
    }

    /// Ports `base`, `base+1`, `base+2`, `base+3`, `base+4`, `base+5`, `base+6` for RTDE, URScript
    /// (secondary), HYPERION commands and stream, the dashboard server, URScript (real-time) and
    /// the primary interface (tests and benchmarks use distinct bases so they never collide).
    pub fn with_port_base(mut self, base: u16) -> ServeConfig {
        self.rtde_port = base;
        self.script_port = base + 1;
        self.command_port = base + 2;
        self.stream_port = base + 3;
        self.dashboard_port = base + 4;
        self.realtime_script_port = base + 5;
        // Saturating: a base past 65529 leaves the primary port on the real-time one's, which
        // then fails to bind with a clear error (`tendril serve --port-base` refuses such bases).
        self.primary_port = base.saturating_add(6);
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
    /// Primary interface (30001).
    pub primary: SocketAddr,
}
