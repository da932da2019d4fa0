//! `tendril latency`: the real path against the virtual devices on loopback, at 500 Hz.

use super::emit;
use std::path::PathBuf;
use std::process::ExitCode;
use tendril_drivers::RealCell;
use tendril_drivers::latency::{LatencyReport, measure, measure_idle};
use tendril_drivers::realtime::RealtimeOptions;
use tendril_run::scenario::PickPlaceScenario;
use tendril_serve::{ServeConfig, start};

/// Arguments of `tendril latency`.
#[derive(Debug, clap::Args)]
pub struct LatencyArgs {
    /// The scenario the twin serves.
    #[arg(default_value = "scenarios/crimper.toml")]
    scenario: PathBuf,
    /// How long to measure [s].
    #[arg(long, default_value_t = 60.0)]
    seconds: f64,
    /// Control rate [Hz] [default: 500; with --ros2 the scenario's `control_rate_hz`].
    #[arg(long)]
    rate_hz: Option<f64>,
    /// Ports of the virtual devices (N .. N+6 on 127.0.0.1).
    #[arg(long, default_value_t = 39400, value_parser = super::devices::port_base)]
    port_base: u16,
    /// Every watchdog limit [ms] (the sensor's, the arm's and the motors'); 500 ms by default, far
    /// looser than a run's, so that the thread not being run for a while (tens of ms on a shared
    /// virtual machine) shows up in the figures instead of ending the measurement.
    #[arg(long, default_value_t = 500.0)]
    stale_ms: f64,
    #[command(flatten)]
    realtime: super::realtime::RealtimeArgs,
    /// Run the virtual devices' threads (twin, bus, network) on this CPU only; with `--cpu` for
    /// the control thread, the two stop competing for one core.
    #[arg(long)]
    devices_cpu: Option<usize>,
    /// First run the same schedule with no work in a tick for as long, on the same thread: the
    /// latency and missed deadlines the machine alone gives.
    #[arg(long)]
    floor: bool,
    /// Measure the ROS 2 path instead (docs/cell/ros2.md): a topic's latency at the control rate,
    /// the CPU share the twin's ROS 2 node adds to `tendril serve`, and a lock-step run's speed
    /// against `tendril run`'s.
    #[arg(long)]
    ros2: bool,
}

pub fn run(a: LatencyArgs) -> anyhow::Result<ExitCode> {
    anyhow::ensure!(a.seconds > 0.0 && a.seconds <= 3600.0, "--seconds must be in (0, 3600], got {}", a.seconds);
    let scenario: PickPlaceScenario = tendril_config::load(&a.scenario, &[])?;
    let rate_hz = a.rate_hz.unwrap_or(if a.ros2 { scenario.control_rate_hz } else { 500.0 });
    // At least 1 Hz, and at least ten ticks in the measurement: at 0.001 Hz the first tick's wait
    // alone was 1000 s, and the command printed nothing for as long.
    anyhow::ensure!((1.0..=2000.0).contains(&rate_hz), "--rate-hz must be in [1, 2000], got {rate_hz}");
    anyhow::ensure!(
        rate_hz * a.seconds >= 10.0,
        "--seconds {} at --rate-hz {rate_hz} gives fewer than 10 ticks to measure",
        a.seconds
    );
    if a.ros2 {
        return super::ros2_latency::run(&a.scenario, &scenario, rate_hz, a.seconds);
    }
    anyhow::ensure!(
        a.stale_ms.is_finite() && (2.0..=10_000.0).contains(&a.stale_ms),
        "--stale-ms must be 2-10000 (one RTDE period to 10 s), got {}",
        a.stale_ms
    );
    let control = a.realtime.options()?;
    let label = format!("{rate_hz} Hz for {} s", a.seconds);
    let floor = if a.floor {
        // On a thread scheduled as the control thread will be, before the devices start.
        let idle =
            std::thread::spawn(move || control.apply_to_current_thread().map(|()| measure_idle(rate_hz, a.seconds)));
        let r = idle.join().map_err(|_| anyhow::anyhow!("the empty-tick thread panicked"))??;
        emit(&format!("empty ticks (the machine alone), {label}: {}\n", describe(&r)));
        Some(r)
    } else {
        None
    };
    let mut serve_config = ServeConfig::loopback().with_port_base(a.port_base);
    // The devices one level below the control thread: a real cell's devices have processors of
    // their own, so here they must not hold up the tick they stand in for.
    serve_config.realtime = RealtimeOptions {
        priority: (control.priority - 1).max(control.priority.min(1)),
        cpu: a.devices_cpu,
        lock_memory: control.lock_memory,
    };
    let serve = start(&scenario, &serve_config)?;
    let mut config = serve.real_cell_config();
    config.sensor_period_s = 1.0 / scenario.interrogator.sample_rate_hz;
    config.watchdog = tendril_drivers::Watchdog::uniform(a.stale_ms * 1e-3);
    // After the devices started, so that they do not inherit the control thread's CPU.
    control.apply_to_current_thread()?;
    let mut cell = RealCell::new(config);
    let r = measure(&mut cell, rate_hz, a.seconds)?;
    let motors = cell.motor_stats();
    drop(cell);
    serve.stop().map_err(|e| anyhow::anyhow!("twin: {e}"))?;
    emit(&format!(
        "real path vs virtual devices, {label}: {}; read+write alone p99 {:.3} ms; \
         motor positions a tick late in {} of {} reads\n",
        describe(&r),
        r.work_p99_s * 1e3,
        motors.behind,
        motors.reads,
    ));
    emit(&verdict(&r, floor.as_ref()));
    Ok(ExitCode::SUCCESS)
}

/// The goals (p99 under 1 ms, no missed deadline), met or not, with the machine's own
/// misses beside them when measured.
fn verdict(r: &LatencyReport, floor: Option<&LatencyReport>) -> String {
    let met = |ok: bool| if ok { "met" } else { "not met" };
    let p99 = format!("p99 < 1 ms {} ({:.3} ms)", met(r.p99_s < 1e-3), r.p99_s * 1e3);
    let missed = format!("no missed deadline {} ({} missed)", met(r.missed_deadlines == 0), r.missed_deadlines);
    let machine = match floor {
        Some(f) => format!("; empty ticks alone missed {}", f.missed_deadlines),
        None => String::new(),
    };
    format!("goals: {p99}; {missed}{machine}\n")
}

fn describe(r: &LatencyReport) -> String {
    format!(
        "{} ticks, latency p50 {:.3} ms, p99 {:.3} ms, max {:.3} ms; missed deadlines {} ({:.2} %) from {} {}",
        r.ticks,
        r.p50_s * 1e3,
        r.p99_s * 1e3,
        r.max_s * 1e3,
        r.missed_deadlines,
        100.0 * r.missed_deadlines as f64 / r.ticks.max(1) as f64,
        r.missed_runs,
        if r.missed_runs == 1 { "stall" } else { "stalls" }
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn report(p99_s: f64, missed_deadlines: usize) -> LatencyReport {
        LatencyReport {
            ticks: 30_000,
            p50_s: 2e-5,
            p99_s,
            max_s: 5e-3,
            missed_deadlines,
            missed_runs: missed_deadlines,
            work_p99_s: 4e-5,
        }
    }

    #[test]
    fn the_verdict_names_each_goal_met_or_not() {
        assert_eq!(
            verdict(&report(6e-5, 0), None),
            "goals: p99 < 1 ms met (0.060 ms); no missed deadline met (0 missed)\n"
        );
        let v = verdict(&report(1.5e-3, 23), Some(&report(0.0, 3)));
        assert!(v.contains("p99 < 1 ms not met (1.500 ms)"), "{v}");
        assert!(v.contains("no missed deadline not met (23 missed); empty ticks alone missed 3"), "{v}");
    }
}
