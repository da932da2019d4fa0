//! `tendril latency --ros2`: what the ROS 2 path costs on this machine, on loopback: a topic's
//! latency at the control rate (publish to take, between two participants), the share of a core
//! the twin's ROS 2 node adds to `tendril serve`, and a lock-step run against the twin's own.

use super::emit;
use std::process::{Command, ExitCode, Stdio};
use std::time::{Duration, Instant};
use tendril_cell::Spread;
use tendril_ros2::{Node, QosProfile, Ros2Config};
use tendril_ros2msg::{Header, JointState, Time};
use tendril_run::execute::{Driver, run_on_twin};
use tendril_run::scenario::PickPlaceScenario;

/// A ROS domain of this measurement's own (below the tests' 20-199).
fn domain() -> u16 {
    200 + (std::process::id() % 30) as u16
}

/// Publish-to-take latency of `sensor_msgs/msg/JointState` (the twin's state, eight joints) at
/// `rate_hz` for `seconds`, between two participants of this process over loopback UDP.
fn topic_latency(rate_hz: f64, seconds: f64) -> anyhow::Result<(Spread, usize, usize)> {
    let config = Ros2Config { domain_id: domain(), ..Ros2Config::default() };
    let mut a = Node::new(&config, "latency_pub")?;
    let mut b = Node::new(&config, "latency_sub")?;
    let publisher = a.publisher::<JointState>("/latency", QosProfile::DEFAULT)?;
    let mut sub = b.subscription::<JointState>("/latency", QosProfile::DEFAULT)?;
    let epoch = Instant::now();
    let names: Vec<String> = config.joints.all().into_iter().map(String::from).collect();
    let message = |t: f64| JointState {
        header: Header { stamp: Time::from_secs_f64(t), frame_id: String::new() },
        name: names.clone(),
        position: vec![0.1; 8],
        velocity: vec![0.0; 8],
        effort: Vec::new(),
    };
    // Discovery first: until a sample comes through, nothing is measured.
    let until = Instant::now() + Duration::from_secs(10);
    while sub.take().is_empty() {
        anyhow::ensure!(Instant::now() < until, "the two participants did not meet within 10 s on loopback");
        publisher.publish(&message(epoch.elapsed().as_secs_f64()))?;
        std::thread::sleep(Duration::from_millis(10));
    }
    let period = Duration::from_secs_f64(1.0 / rate_hz);
    let ticks = (rate_hz * seconds).round() as usize;
    let mut latencies = Vec::with_capacity(ticks);
    let start = Instant::now();
    for k in 0..ticks {
        publisher.publish(&message(epoch.elapsed().as_secs_f64()))?;
        // Take until the next tick is due, timestamping each sample as it is taken.
        let due = start + period * (k as u32 + 1);
        while Instant::now() < due {
            for m in sub.take() {
                latencies.push(epoch.elapsed().as_secs_f64() - m?.header.stamp.as_secs_f64());
            }
            std::thread::sleep(Duration::from_micros(20));
        }
    }
    let received = latencies.len();
    Ok((Spread::of(&latencies), ticks, received))
}

/// CPU time of process `pid`'s threads so far \[s\] (the first field of each thread's
/// `/proc/PID/task/TID/schedstat`: nanoseconds on a CPU).
fn cpu_s(pid: u32) -> anyhow::Result<f64> {
    let mut ns = 0u64;
    for task in std::fs::read_dir(format!("/proc/{pid}/task"))? {
        let text = std::fs::read_to_string(task?.path().join("schedstat")).unwrap_or_default();
        ns += text.split_whitespace().next().and_then(|v| v.parse::<u64>().ok()).unwrap_or(0);
    }
    Ok(ns as f64 * 1e-9)
}

/// Share of a core `tendril serve` takes over `seconds`, with `extra` arguments.
fn serve_cpu(scenario_path: &str, extra: &[&str], seconds: f64) -> anyhow::Result<f64> {
    let exe = std::env::current_exe()?;
    let base = 39_500 + (std::process::id() % 50) as u16 * 8;
    let mut child = Command::new(exe)
        .args(["serve", scenario_path, "--port-base", &base.to_string(), "--seconds", &(seconds + 10.0).to_string()])
        .args(extra)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()?;
    // Past the start-up (model compile, discovery).
    std::thread::sleep(Duration::from_secs(3));
    let (c0, t0) = (cpu_s(child.id())?, Instant::now());
    std::thread::sleep(Duration::from_secs_f64(seconds));
    let share = (cpu_s(child.id())? - c0) / t0.elapsed().as_secs_f64();
    let _ = child.kill();
    let _ = child.wait();
    Ok(share)
}

/// `tendril latency --ros2`.
pub fn run(
    scenario_path: &std::path::Path,
    scenario: &PickPlaceScenario,
    rate_hz: f64,
    seconds: f64,
) -> anyhow::Result<ExitCode> {
    let (latency, sent, received) = topic_latency(rate_hz, seconds)?;
    emit(&format!(
        "topic latency, sensor_msgs/msg/JointState at {rate_hz} Hz for {seconds} s on loopback: p50 {:.3} ms, p99 {:.3} ms, max {:.3} ms ({received} of {sent} received)\n",
        latency.p50_ms, latency.p99_ms, latency.max_ms
    ));
    let path = scenario_path.to_string_lossy();
    let without = serve_cpu(&path, &[], seconds)?;
    let in_domain = format!("ros2.domain_id={}", domain());
    let with = serve_cpu(&path, &["--ros2", "--set", &in_domain], seconds)?;
    emit(&format!(
        "tendril serve: {:.1} % of a core without ROS 2, {:.1} % with --ros2 at {} Hz: the node adds {:.1} %\n",
        without * 100.0,
        with * 100.0,
        scenario.ros2.publish_rate_hz,
        (with - without) * 100.0
    ));
    // The same scenario in lock step against the twin's node, and on the twin alone.
    let mut locked = scenario.clone();
    locked.ros2.domain_id = domain();
    locked.ros2.use_sim_time = true;
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let twin = {
        let (s, stop) = (locked.clone(), stop.clone());
        std::thread::spawn(move || {
            tendril_serve::lockstep::serve_lockstep(
                &s,
                &Default::default(),
                &|| stop.load(std::sync::atomic::Ordering::SeqCst),
                None,
            )
        })
    };
    let t = Instant::now();
    let (ros, _) =
        tendril_run::ros2::run_on_ros2(&locked, tendril_run::ros2::ros2_cell_config(&locked), None, Driver::default())?;
    let ros_s = t.elapsed().as_secs_f64();
    stop.store(true, std::sync::atomic::Ordering::SeqCst);
    twin.join().map_err(|_| anyhow::anyhow!("the lock-step twin panicked"))??;
    let t = Instant::now();
    let (sim, _) = run_on_twin(scenario, &Default::default(), None)?;
    let sim_s = t.elapsed().as_secs_f64();
    emit(&format!(
        "lock step: {:.1} s of cell time in {ros_s:.2} s wall ({:.1}x real time, outcome {}); `tendril run` alone {sim_s:.2} s ({:.1}x): {:.2}x its time\n",
        ros.sim_time_s,
        ros.sim_time_s / ros_s,
        ros.outcome,
        sim.sim_time_s / sim_s,
        ros_s / sim_s
    ));
    Ok(ExitCode::SUCCESS)
}
