//! `tendril serve`: the twin behind the real devices' protocols.

use super::emit;
use std::net::IpAddr;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;
use tendril_config::Override;
use tendril_ros2::ClockMode;
use tendril_run::scenario::PickPlaceScenario;
use tendril_serve::jitter::Link;
use tendril_serve::{Jitter, JitterProfile, ProgramState, Ros2Serving, ServeConfig, start};

/// Arguments of `tendril serve`.
#[derive(Debug, clap::Args)]
pub struct ServeArgs {
    /// The scenario file (object, sensor, physics of the twin).
    scenario: PathBuf,
    /// Address to listen on; loopback unless asked otherwise.
    #[arg(long, default_value = "127.0.0.1")]
    bind: IpAddr,
    /// Ports N (RTDE), N+1 (URScript, secondary), N+2 (HYPERION commands), N+3 (peaks), N+4 (UR
    /// dashboard), N+5 (URScript, real-time), N+6 (UR primary interface) instead of the devices'
    /// 30004, 30002, 51971, 51972, 29999, 30003, 30001.
    #[arg(long, value_parser = port_base)]
    port_base: Option<u16>,
    /// A host the UR5e's programs may open sockets to besides loopback (repeatable; an IP
    /// address, as a program names it).
    #[arg(long = "allow-host")]
    allow_host: Vec<IpAddr>,
    /// Stop after this many seconds, up to a week (default: until Ctrl-C, SIGTERM or SIGHUP).
    #[arg(long, value_parser = super::seconds_arg)]
    seconds: Option<f64>,
    /// Scenario keys from a file (what `tendril fit` and `tendril tune` write), applied after the
    /// scenario file and before `--set`.
    #[arg(long)]
    overlay: Option<PathBuf>,
    /// Override a scenario value: `--set key.path=value` (repeatable).
    #[arg(long = "set")]
    set: Vec<Override>,
    /// Timing faults the devices inject into their links, to try a client against an ordinary PC
    /// or a Wi-Fi link: `loopback`, `busy-pc` or `wifi` (each stated in
    /// docs/cell/timing.md#injected-jitter) [default: none].
    #[arg(long, value_enum, default_value = "none")]
    jitter: JitterProfile,
    /// Seed of the injected jitter's delays.
    #[arg(long, default_value_t = 1)]
    jitter_seed: u64,
    /// Inject the jitter into this link only (`rtde-out`, `rtde-in`, `peaks`, `bus`) [default: all].
    #[arg(long, value_enum)]
    jitter_link: Option<Link>,
    /// Put the twin on the scenario's ROS 2 graph too (`[ros2]`: joint states, FBG peaks and
    /// force estimates, `/clock`; commands on the joint command topic; docs/cell/ros2.md).
    #[arg(long)]
    ros2: bool,
    /// With `--ros2`: lock step instead of real time (`[ros2] clock = "lockstep"`): the twin
    /// advances one publish period per command, as fast as the commander goes; the device
    /// protocols are not served then.
    #[arg(long, requires = "ros2")]
    lockstep: bool,
    /// With `--ros2`: record the node's topics (what it publishes and the commands it receives)
    /// into a rosbag2 bag (MCAP) in this folder, which must not exist.
    #[arg(long, requires = "ros2")]
    bag: Option<PathBuf>,
    #[command(flatten)]
    realtime: super::realtime::RealtimeArgs,
}

/// Parses `--port-base N`: seven ports N..N+6 must fit below 65536.
fn port_base(text: &str) -> Result<u16, String> {
    let base: u16 = text.parse().map_err(|e| format!("{e}"))?;
    if base == 0 || base > u16::MAX - 6 {
        return Err(format!("must be 1-{} (ports N..N+6)", u16::MAX - 6));
    }
    Ok(base)
}

pub fn run(a: ServeArgs) -> anyhow::Result<ExitCode> {
    let overlay = tendril_config::Overlay::load(a.overlay.as_deref())?;
    let mut set = a.set.clone();
    if a.lockstep {
        set.push(Override { key: "ros2.clock".into(), value: toml::Value::String("lockstep".into()) });
    }
    let scenario: PickPlaceScenario = overlay.load_scenario(&a.scenario, &set)?;
    let serving = a.ros2.then(|| Ros2Serving { bag: a.bag.clone() });
    if let Some(serving) = serving.as_ref().filter(|_| scenario.ros2.clock == ClockMode::Lockstep) {
        return serve_lockstep_cli(&scenario, serving, a.seconds);
    }
    let mut config = ServeConfig::loopback();
    config.ros2 = serving;
    config.bind = a.bind;
    config.realtime = a.realtime.options()?;
    if let Some(base) = a.port_base {
        config = config.with_port_base(base);
    }
    config.script_hosts = a.allow_host;
    config.jitter = Jitter::profile(a.jitter, a.jitter_seed).map(|j| Jitter { only: a.jitter_link, ..j });
    let handle = start(&scenario, &config)?;
    let [rtde, script, command, stream] = handle.addrs;
    let (dashboard, realtime_script, primary) =
        (handle.ur_addrs.dashboard, handle.ur_addrs.realtime_script, handle.ur_addrs.primary);
    let h = handle.hardware;
    emit(&format!(
        "tendril serve: {}\n  RTDE      {rtde}\n  URScript  {primary} (primary), {script} (secondary), {realtime_script}\n  Dashboard {dashboard}\n  HYPERION  {command} (commands), {stream} (peaks; FBG1, FBG2 on channel {})\n  Dynamixel {} (MX-106 IDs {} growth, {} twine; {} bit/s)\n",
        scenario.name,
        h.fbg.channel,
        handle.pty_path.display(),
        h.growth_id,
        h.twine_id,
        h.dxl_baud
    ));
    for (k, p) in h.fbg.pads.as_slice().iter().enumerate() {
        emit(&format!(
            "            pad {}: FBG1 in [{:.2}, {:.2}) nm{} on channel {}\n",
            k + 1,
            p.fbg1_min_nm,
            p.fbg1_max_nm,
            if p.fbg2().is_some() { ", its own FBG2" } else { ", pad 0's FBG2" },
            p.channel
        ));
    }
    if config.ros2.is_some() {
        emit(&ros2_banner(&scenario));
    }
    if let Some(j) = config.jitter {
        let link = j.only.map_or("every link".to_string(), |l| format!("{l:?}"));
        emit(&format!("  jitter    {:?} on {link}, seed {} (docs/cell/timing.md#injected-jitter)\n", a.jitter, j.seed));
    }
    // Ctrl-C, SIGTERM and SIGHUP alike: the devices are shut down and the status reported.
    crate::signals::install_signal_handlers()?;
    let started = std::time::Instant::now();
    // What the virtual UR5e's program and safety system last did, to report their changes.
    let mut reported = (ProgramState::Stopped, None::<String>);
    while tendril_cell::interrupt::requested().is_none() && handle.running() {
        if a.seconds.is_some_and(|s| started.elapsed().as_secs_f64() >= s) {
            break;
        }
        let now = handle.state.lock().map(|s| (s.program, s.protective_stop.clone())).unwrap_or(reported.clone());
        if now != reported {
            if let Some(why) = now.1.as_ref().filter(|_| now.1 != reported.1) {
                emit(&format!(
                    "UR5e protective stop: {why} (unlock it on the dashboard, or upload the program again)\n"
                ));
            }
            if now.0 != reported.0 {
                emit(&format!("UR5e program: {:?}\n", now.0));
            }
            reported = now;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let status = handle.state.lock().map(|s| s.status).unwrap_or_default();
    emit(&format!(
        "twin ran {:.2} s in {:.2} s wall ({} ticks)\n",
        status.time_s,
        started.elapsed().as_secs_f64(),
        status.ticks
    ));
    match handle.stop() {
        Ok(()) => Ok(ExitCode::SUCCESS),
        Err(e) => Err(anyhow::anyhow!("twin stopped: {e}")),
    }
}

/// What the twin's ROS 2 node publishes and takes, for the banner.
fn ros2_banner(scenario: &PickPlaceScenario) -> String {
    let r = &scenario.ros2;
    let t = &r.topics;
    format!(
        "  ROS 2     domain {}, {:?}{}, node {}_twin, {} Hz {:?}\n            publishes {} {} {} {} {}\n            takes     {} (sensor_msgs/msg/JointState: {})\n",
        r.domain_id,
        r.distro,
        if r.localhost_only { ", localhost only" } else { "" },
        r.node_name,
        r.publish_rate_hz,
        r.clock,
        r.resolve(&t.joint_states),
        r.resolve(&t.clock),
        r.resolve(&t.fbg_peaks),
        (0..=scenario.array.pads.len()).map(|k| r.resolve(&t.fbg_wrench_of(k))).collect::<Vec<_>>().join(" "),
        r.resolve(&t.tool_wrench),
        r.resolve(&t.joint_commands),
        r.joints.all().join(", ")
    )
}

/// `tendril serve --ros2 --lockstep`: the twin on the graph alone, until Ctrl-C or `seconds`.
fn serve_lockstep_cli(
    scenario: &PickPlaceScenario,
    serving: &Ros2Serving,
    seconds: Option<f64>,
) -> anyhow::Result<ExitCode> {
    emit(&format!("tendril serve: {} (ROS 2 only, lock step)\n", scenario.name));
    emit(&ros2_banner(scenario));
    crate::signals::install_signal_handlers()?;
    let started = std::time::Instant::now();
    let stop = || {
        tendril_cell::interrupt::requested().is_some() || seconds.is_some_and(|s| started.elapsed().as_secs_f64() >= s)
    };
    let report = tendril_serve::lockstep::serve_lockstep(scenario, serving, &stop, None)?;
    emit(&format!(
        "twin ran {:.2} s in {:.2} s wall ({} steps, {:.1}x real time)\n",
        report.sim_s,
        report.wall_s,
        report.steps,
        report.sim_s / report.wall_s.max(1e-9)
    ));
    if let Some(b) = report.bag {
        emit(&format!("wrote {} ({} messages)\n", b.dir.display(), b.messages));
    }
    Ok(ExitCode::SUCCESS)
}
