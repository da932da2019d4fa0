//! `tendril latency`: the real path against the virtual devices on loopback, at 500 Hz.

use super::emit;
use crate::cell::real::latency::measure;
use crate::cell::real::serve::{ServeConfig, start};
use crate::cell::real::{RealCell, RealCellConfig};
use crate::run::scenario::PickPlaceScenario;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `tendril latency`.
#[derive(Debug, clap::Args)]
pub struct LatencyArgs {
    /// The scenario the twin serves.
    #[arg(default_value = "scenarios/crimper.toml")]
    scenario: PathBuf,
    /// How long to measure [s].
    #[arg(long, default_value_t = 60.0)]
    seconds: f64,
    /// Control rate [Hz].
    #[arg(long, default_value_t = 500.0)]
    rate_hz: f64,
    /// Ports of the virtual devices (N .. N+3 on 127.0.0.1).
    #[arg(long, default_value_t = 39400)]
    port_base: u16,
    /// Sensor watchdog [interrogator periods]; looser than a run's 5 so a scheduling hiccup of a
    /// loaded machine shows up in the figures instead of ending the measurement.
    #[arg(long, default_value_t = 50.0)]
    sensor_stale_samples: f64,
    /// Run the control thread and the twin/bus threads under SCHED_FIFO at this priority (1-99;
    /// needs root or CAP_SYS_NICE); 0 leaves normal scheduling.
    #[arg(long, default_value_t = 0)]
    rt_priority: i32,
}

pub fn run(a: LatencyArgs) -> anyhow::Result<ExitCode> {
    anyhow::ensure!(a.seconds > 0.0 && a.seconds <= 3600.0, "--seconds must be in (0, 3600]");
    anyhow::ensure!(a.rate_hz > 0.0 && a.rate_hz <= 2000.0, "--rate-hz must be in (0, 2000]");
    let scenario: PickPlaceScenario = crate::scenario::load(&a.scenario, &[])?;
    let mut serve_config = ServeConfig::loopback().with_port_base(a.port_base);
    serve_config.rt_priority = a.rt_priority;
    let serve = start(&scenario, &serve_config)?;
    let mut config = RealCellConfig::new("127.0.0.1", &serve.pty_path.to_string_lossy(), "127.0.0.1");
    config.rtde_port = serve.addrs[0].port();
    config.script_port = serve.addrs[1].port();
    config.command_port = serve.addrs[2].port();
    config.stream_port = serve.addrs[3].port();
    config.sensor_stale_samples = a.sensor_stale_samples;
    config.arm_stale_s = a.sensor_stale_samples * 2e-3;
    if a.rt_priority > 0 {
        crate::cell::real::latency::set_realtime_priority(a.rt_priority)
            .map_err(|e| anyhow::anyhow!("--rt-priority {}: {e}", a.rt_priority))?;
    }
    let mut cell = RealCell::new(config);
    let r = measure(&mut cell, a.rate_hz, a.seconds)?;
    drop(cell);
    serve.stop().map_err(|e| anyhow::anyhow!("twin: {e}"))?;
    emit(&format!(
        "real path vs virtual devices, {} Hz for {} s ({} ticks): latency p50 {:.3} ms, p99 {:.3} ms, max {:.3} ms; missed deadlines {}; read+write alone p99 {:.3} ms\n",
        a.rate_hz,
        a.seconds,
        r.ticks,
        r.p50_s * 1e3,
        r.p99_s * 1e3,
        r.max_s * 1e3,
        r.missed_deadlines,
        r.work_p99_s * 1e3
    ));
    Ok(ExitCode::SUCCESS)
}
