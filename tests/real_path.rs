//! The real path (`RealCell` behind `LimitedCell`, RTDE + URScript + Dynamixel pty + HYPERION)
//! in-process against the virtual devices running the twin in real time, on the short grasp-hold-
//! lift scenario (about 13 s of wall time), compared with the same scenario on the simulated path
//! within the tolerances of `common::phases`. `tests/serve_run_e2e.rs` does the same with the two
//! binaries; here the twin's ground truth is at hand, and the devices' state after a stop.

use tendril_cell::Cell;
use tendril_control::task::Phase;
use tendril_drivers::{RealCell, RealCellConfig, Watchdog};
use tendril_run::execute::run_on_twin;
use tendril_run::real::run_on_real;
use tendril_run::runner::Outcome;
use tendril_serve::jitter::Link;
use tendril_serve::{Jitter, JitterModel, ServeConfig, ServeHandle, start};

use crate::common::{one_at_a_time, phases, short_lift};

#[test]
fn real_path_against_virtual_devices_matches_the_twin() {
    let _turn = one_at_a_time();
    let scenario = short_lift(&[]);
    let (_, sim) = run_on_twin(&scenario, &Default::default(), None).unwrap();
    assert_eq!(sim.outcome, Outcome::Held, "the short scenario must hold on the twin: {:?}", sim.error);

    let serve = start(&scenario, &ServeConfig::loopback().with_port_base(21710)).unwrap();
    // The default watchdogs, as a user's run has them.
    let config = serve.real_cell_config();
    // The real path has no ground truth; the twin behind the devices has. Sample its contact
    // flag through the run, to judge the outcome as the simulated path does: the object counts as
    // lost after 0.3 s without contact once grasped, while the arm carries it (from the release
    // on, the finger lets go on purpose).
    let watch = serve.state.clone();
    let done = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let monitor = {
        let done = done.clone();
        std::thread::spawn(move || {
            let mut samples = Vec::new();
            while !done.load(std::sync::atomic::Ordering::SeqCst) {
                let s = watch.lock().unwrap().status;
                samples.push((s.time_s, s.truth.in_contact));
                std::thread::sleep(std::time::Duration::from_millis(5));
            }
            samples
        })
    };
    let (summary, real) = run_on_real(&scenario, config, None).unwrap();
    done.store(true, std::sync::atomic::Ordering::SeqCst);
    let samples = monitor.join().unwrap();
    let twin_end_s = serve.state.lock().unwrap().status.time_s;
    serve.stop().unwrap();

    assert_eq!(real.error, None);
    assert_eq!(summary.run.backend, "real");
    // The real path's cell time is the arm's (the twin's) clock, up to the last tick's lag.
    let lag_s = twin_end_s - real.rows.last().unwrap().time_s;
    let release = real.rows.iter().find(|r| r.phase == Phase::Release).expect("the task reached its release");
    let carried = samples.iter().take_while(|(t, _)| *t < release.time_s + lag_s);
    let (grasped, longest_no_contact_s) = longest_gap_after_grasp(carried);
    assert!(grasped, "the finger never touched the object");
    assert!(longest_no_contact_s < 0.3, "object lost: {longest_no_contact_s:.2} s without contact before the release");
    // Not compared: the sensor-based slip detector's events, which near its thresholds are decided
    // by noise; the ground truth above is the outcome.
    phases::assert_phases_agree(&phases::from_report(&sim), &phases::from_report(&real));
    // The wrist's load reaches the real path over RTDE (`actual_TCP_force`): once lifted, the mean
    // of the lift's last second is the crimper's weight, within 0.25 N (the noise of a tick's
    // reading, 0.78 N, over 100 ticks: 0.08 N).
    let weight = summary.run.mass_kg * 9.81;
    let end = real.rows.iter().rev().find(|r| r.phase == Phase::Lift).unwrap().time_s;
    let last_second: Vec<f64> =
        real.rows.iter().filter(|r| r.phase == Phase::Lift && r.time_s > end - 1.0).map(|r| r.tool_load_n).collect();
    let mean = last_second.iter().sum::<f64>() / last_second.len() as f64;
    assert!((mean - weight).abs() < 0.25, "tool load {mean:.3} N in the lift's last second, m g = {weight:.3} N");
}

/// The comparison catches a command path that shakes the grip. The follow program as it was
/// before its targets were stamped (each target spread over as many cycles as the one before took
/// to arrive: `tests/fixtures/follow_by_arrival.script`), with the arm's commands held back in
/// 20-40 ms stalls four times a second (on the RTDE inputs alone), jerked the arm whenever a
/// package came late: the lift's force estimate read 0.155-0.164 N at its 5th percentile and up to
/// 1.45 N at its 95th against the twin's 0.540 and 0.580 N (three runs). The stamped program, under
/// the same stalls, kept the lift within 5 mN of the twin's (two runs).
#[test]
fn the_comparison_catches_a_follow_program_that_shakes_the_grip_on_late_commands() {
    let _turn = one_at_a_time();
    let scenario = short_lift(&[]);
    let (_, sim) = run_on_twin(&scenario, &Default::default(), None).unwrap();
    let mut devices = ServeConfig::ephemeral();
    let stalls = JitterModel { stall_rate_hz: 4.0, stall_s: (0.02, 0.04), latency_median_s: 0.0, latency_sigma: 0.0 };
    devices.jitter = Some(Jitter { model: stalls, seed: 1, only: Some(Link::RtdeIn) });
    let serve = start(&scenario, &devices).unwrap();
    let mut config = serve.real_cell_config();
    config.program = include_str!("fixtures/follow_by_arrival.script").into();
    let (_, real) = run_on_real(&scenario, config, None).unwrap();
    serve.stop().unwrap();
    let why = phases::disagreement(&phases::from_report(&sim), &phases::from_report(&real))
        .expect("a lift that shakes must not pass the comparison");
    assert!(why.starts_with("lift: force"), "{why}");
}

/// Whether the object was ever touched in `samples` (twin time \[s\], contact), and the longest
/// time \[s\] without contact after the first touch.
fn longest_gap_after_grasp<'a>(samples: impl Iterator<Item = &'a (f64, bool)>) -> (bool, f64) {
    let (mut grasped, mut since, mut longest) = (false, None::<f64>, 0.0f64);
    for &(t, contact) in samples {
        grasped |= contact;
        if grasped && !contact {
            longest = longest.max(t - *since.get_or_insert(t));
        } else {
            since = None;
        }
    }
    (grasped, longest)
}

#[test]
fn malformed_packets_close_the_connection_and_the_devices_keep_serving() {
    let _turn = one_at_a_time();
    use std::io::{Read, Write};
    let scenario = short_lift(&[]);
    let serve = start(&scenario, &ServeConfig::loopback().with_port_base(21720)).unwrap();
    let timeout = Some(std::time::Duration::from_secs(2));
    // RTDE: a size field below the header length.
    let mut s = std::net::TcpStream::connect(serve.addrs[0]).unwrap();
    s.set_read_timeout(timeout).unwrap();
    s.write_all(&[0x00, 0x01, 0x56, 0xFF, 0xFF]).unwrap();
    let mut buf = [0u8; 64];
    assert_eq!(s.read(&mut buf).unwrap_or(0), 0, "RTDE connection must be closed");
    // HYPERION: an unknown command gets an error response, garbage closes the connection.
    let mut s = std::net::TcpStream::connect(serve.addrs[2]).unwrap();
    s.set_read_timeout(timeout).unwrap();
    let req = tendril_hyperion::Request::new("#NoSuchCommand", "").encode().unwrap();
    s.write_all(&req).unwrap();
    let n = s.read(&mut buf).unwrap();
    assert!(n >= 8 && buf[0] != 0, "expected an error status, got {:?}", &buf[..n]);
    let mut s = std::net::TcpStream::connect(serve.addrs[2]).unwrap();
    s.set_read_timeout(timeout).unwrap();
    s.write_all(&[0, 0, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0x7F]).unwrap();
    assert_eq!(s.read(&mut buf).unwrap_or(0), 0, "HYPERION connection must be closed");
    // Still serving: a fresh, correct RTDE session negotiates.
    let mut s = std::net::TcpStream::connect(serve.addrs[0]).unwrap();
    s.set_read_timeout(timeout).unwrap();
    s.write_all(&[0x00, 0x05, 0x56, 0x00, 0x02]).unwrap();
    let mut reply = [0u8; 4];
    s.read_exact(&mut reply).unwrap();
    assert_eq!(reply, [0x00, 0x04, 0x56, 0x01]);
    assert!(serve.running());
    serve.stop().unwrap();
}

#[test]
fn a_stalled_sensor_stream_stops_the_run_with_a_watchdog_error() {
    let _turn = one_at_a_time();
    let (serve, mut cell) = active_cell(|_| {});
    let s = cell.read().unwrap();
    assert!(s.wavelengths.fbg1_nm > 1500.0);
    // Stop the whole virtual cell: the stream goes silent.
    serve.stop().unwrap();
    std::thread::sleep(std::time::Duration::from_millis(50));
    let err = cell.read().unwrap_err().to_string();
    assert!(err.contains("watchdog") || err.contains("closed"), "{err}");
    // Deactivation still terminates (devices gone: it reports, never hangs or panics).
    let _ = cell.deactivate();
}

/// Devices that stall without closing their connections (the whole virtual cell held still: no
/// RTDE sample, no peak, no motor reply) stop a run on the default watchdog within its limit and a
/// tick: 100.5-102 ms at 100 Hz (`Watchdog::for_control`), checked here as 90-150 ms.
#[test]
fn stalled_devices_stop_the_run_within_the_watchdog_limit_and_a_tick() {
    let _turn = one_at_a_time();
    use std::time::{Duration, Instant};
    let (serve, mut cell) = active_cell(|_| {});
    let limit = Watchdog::for_control(0.01, 1e-3);
    let mut t = 0.0;
    for _ in 0..20 {
        cell.read().unwrap();
        t += 0.01;
        cell.wait_until(t).unwrap();
    }
    let silenced = serve.state.lock().unwrap();
    let stalled = Instant::now();
    let err = loop {
        match cell.read() {
            Ok(_) => {
                t += 0.01;
                cell.wait_until(t).unwrap();
            }
            Err(e) => break e.to_string(),
        }
        assert!(stalled.elapsed() < Duration::from_secs(2), "still running 2 s into the stall");
    };
    let took = stalled.elapsed().as_secs_f64();
    drop(silenced);
    let least =
        [limit.sensor_stale_s, limit.arm_stale_s, limit.motor_stale_s].into_iter().fold(f64::INFINITY, f64::min);
    assert!(err.contains("watchdog") || err.contains("did not answer"), "{err}");
    assert!((least - 0.01..0.15).contains(&took), "stopped {:.0} ms into the stall: {err}", took * 1e3);
    let _ = cell.deactivate();
    serve.stop().unwrap();
}

#[test]
fn a_silent_gripper_bus_neither_holds_up_the_tick_nor_goes_unnoticed() {
    let _turn = one_at_a_time();
    use std::time::Duration;
    // Only the motors' watchdog may fire while the devices are silenced.
    let (serve, mut cell) = active_cell(|config| {
        config.watchdog = Watchdog { motor_stale_s: 0.25, ..Watchdog::uniform(1.0) };
    });
    let before = cell.read().unwrap();
    // Holding the virtual devices' state silences the bus (and pauses the twin) until released.
    let silenced = serve.state.lock().unwrap();
    cell.wait_until(0.01).unwrap();
    std::thread::sleep(Duration::from_millis(20));
    // The tick goes on with the positions it has (a read waiting on the bus would wait for this
    // thread to release the devices: until the reply timeout).
    let during = cell.read().unwrap();
    assert_eq!(during.twine_motor_rad, before.twine_motor_rad);
    assert_eq!(cell.motor_stats().behind, 1, "{:?}", cell.motor_stats());
    // Past the reply timeout the motors' watchdog stops the cell.
    std::thread::sleep(Duration::from_millis(300));
    let err = cell.read().unwrap_err().to_string();
    drop(silenced);
    assert!(err.contains("MX-106"), "{err}");
    assert!(err.contains("did not answer") || err.contains("watchdog"), "{err}");
    cell.deactivate().unwrap();
    serve.stop().unwrap();
}

#[test]
fn an_operator_stop_leaves_the_arm_stopped_and_the_motors_holding_with_torque_on() {
    let _turn = one_at_a_time();
    use tendril_cell::CellCommand;
    let (serve, mut cell) = active_cell(|_| {});
    // Wind the twine motor for half a second, then stop as Ctrl-C does.
    for k in 1..=50 {
        let s = cell.read().unwrap();
        let c = CellCommand { arm_q: s.arm_q, growth_motor_rad: 0.0, twine_motor_rad: 0.04 * k as f64 };
        cell.write(&c).unwrap();
        cell.wait_until(k as f64 * 0.01).unwrap();
    }
    let following = serve.state.lock().unwrap().inputs.values.int_registers[24];
    assert_eq!(following, 1, "the enable register is set while active");
    cell.stop_flag().store(true, std::sync::atomic::Ordering::SeqCst);
    let err = cell.read().unwrap_err().to_string();
    assert!(err.contains("stop requested"), "{err}");
    cell.deactivate().unwrap();
    std::thread::sleep(std::time::Duration::from_millis(20));
    let s = serve.state.lock().unwrap();
    assert_eq!(s.inputs.values.int_registers[24], 0, "the follow program is told to stop the arm");
    for id in [1, 2] {
        let t = s.bus.table(id).unwrap();
        assert!(t.torque_enabled(), "motor {id} must keep torque on to hold the object");
    }
    // The twine motor holds where it was (goal = present at the stop, within the ticks it moved
    // between the read and the twin's next update).
    let twine = s.bus.table(2).unwrap();
    assert!(twine.goal_position() > 100, "the twine motor had wound: goal {}", twine.goal_position());
    assert!(
        (twine.goal_position() - twine.present_position()).abs() <= 30,
        "goal {} present {}",
        twine.goal_position(),
        twine.present_position()
    );
    drop(s);
    serve.stop().unwrap();
}

#[test]
fn the_scenarios_motor_ids_bus_speed_and_fbg_channel_are_served_and_driven() {
    let _turn = one_at_a_time();
    use tendril_cell::CellCommand;
    use tendril_drivers::HardwareConfig;
    use tendril_dynamixel::control_table::addr;
    let scenario = short_lift(&[
        "hardware.growth_id=11",
        "hardware.twine_id=12",
        "hardware.dxl_baud=1000000",
        "hardware.fbg.channel=3",
    ]);
    let serve = start(&scenario, &ServeConfig::loopback().with_port_base(21770)).unwrap();
    {
        let s = serve.state.lock().unwrap();
        assert_eq!(s.bus.ids(), [11, 12]);
        assert_eq!(s.bus.table(11).unwrap().read(addr::BAUD_RATE, 1).unwrap(), [3], "1 Mbit/s is Baud Rate 3");
    }
    // The real path with the same [hardware] finds both motors and both gratings on channel 3.
    let mut config = serve.real_cell_config();
    assert_eq!(config.hardware, scenario.hardware);
    let mut cell = RealCell::new(config.clone());
    cell.configure().unwrap();
    cell.activate().unwrap();
    for k in 1..=20 {
        let s = cell.read().unwrap();
        assert!(s.wavelengths.fbg1_nm > 1535.0 && s.wavelengths.fbg2_nm > 1547.8, "{:?}", s.wavelengths);
        let c = CellCommand { arm_q: s.arm_q, growth_motor_rad: 0.0, twine_motor_rad: 0.5 };
        cell.write(&c).unwrap();
        cell.wait_until(k as f64 * 0.01).unwrap();
    }
    let twine = serve.state.lock().unwrap().bus.table(12).unwrap().goal_position();
    assert!(twine > 250, "the twine motor (ID 12) is driven to 0.5 rad (326 ticks): goal {twine} ticks");
    cell.deactivate().unwrap();
    drop(cell);
    // The factory IDs are not on this bus: configuring for them fails and says which is missing.
    config.hardware = HardwareConfig { fbg: scenario.hardware.fbg, ..HardwareConfig::default() };
    let err = RealCell::new(config).configure().unwrap_err().to_string();
    assert!(err.contains("ID 1 did not answer"), "{err}");
    serve.stop().unwrap();
}

/// Virtual devices serving the short lift on free ports, and a real cell on them, its
/// configuration adjusted by `tune`, configured and activated.
fn active_cell(tune: impl FnOnce(&mut RealCellConfig)) -> (ServeHandle, RealCell) {
    let serve = start(&short_lift(&[]), &ServeConfig::ephemeral()).unwrap();
    let mut config = serve.real_cell_config();
    tune(&mut config);
    let mut cell = RealCell::new(config);
    cell.configure().unwrap();
    cell.activate().unwrap();
    (serve, cell)
}

/// Issue 18: RTDE and HYPERION command connections that stay silent are closed after the idle
/// timeout (30 s by default, 300 ms here); one that keeps talking stays open.
#[test]
fn idle_command_connections_are_closed() {
    let _turn = one_at_a_time();
    use std::io::{Read, Write};
    let mut config = ServeConfig::loopback().with_port_base(21780);
    config.idle_timeout = std::time::Duration::from_millis(300);
    let serve = start(&short_lift(&[]), &config).unwrap();
    let mut buf = [0u8; 64];
    for addr in [serve.addrs[0], serve.addrs[2]] {
        let mut s = std::net::TcpStream::connect(addr).unwrap();
        s.set_read_timeout(Some(std::time::Duration::from_secs(5))).unwrap();
        let started = std::time::Instant::now();
        assert_eq!(s.read(&mut buf).unwrap_or(usize::MAX), 0, "{addr}: an idle connection must be closed");
        let waited = started.elapsed().as_secs_f64();
        assert!((0.25..3.0).contains(&waited), "{addr}: closed after {waited} s");
    }
    // An RTDE client that asks for the protocol version every 100 ms keeps its connection.
    let mut s = std::net::TcpStream::connect(serve.addrs[0]).unwrap();
    s.set_read_timeout(Some(std::time::Duration::from_secs(2))).unwrap();
    for _ in 0..8 {
        s.write_all(&[0x00, 0x05, 0x56, 0x00, 0x02]).unwrap();
        let mut reply = [0u8; 4];
        s.read_exact(&mut reply).unwrap();
        assert_eq!(reply, [0x00, 0x04, 0x56, 0x01]);
        std::thread::sleep(std::time::Duration::from_millis(100));
    }
    serve.stop().unwrap();
}

/// A three-pad sensor array (`scenarios/hammer-array.toml`) on the real path: `serve` puts every
/// grating on channel 1, the real cell maps each peak to its pad by the windows derived from the
/// layout and reads all three pads, as the twin does; windows that miss a pad's peak stop the
/// configure with the pad, grating, window and channel named.
#[test]
fn a_three_pad_array_is_served_and_read_on_every_pad() {
    let _turn = one_at_a_time();
    use tendril_cell::CellCommand;
    use tendril_hyperion::PadWindowList;
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/hammer-array.toml");
    let scenario: tendril_run::scenario::PickPlaceScenario = tendril_config::load(&path, &[]).unwrap();
    let serve = start(&scenario, &ServeConfig::ephemeral()).unwrap();
    let mut config = serve.real_cell_config();
    assert_eq!(config.hardware.fbg.pads.len(), 2, "the further pads' windows, derived from [array]");
    assert_eq!(config.hardware, tendril_run::real::hardware_for(&scenario).unwrap());
    let mut cell = RealCell::new(config);
    cell.configure().unwrap();
    cell.activate().unwrap();
    for k in 1..=20 {
        let s = cell.read().unwrap();
        let [one, two] = s.array.as_slice() else { panic!("two further pads: {:?}", s.array) };
        // Unloaded at home: each strain grating near its wavelength, the shared reference pad 0's.
        assert!((one.fbg1_nm - 1525.0).abs() < 0.5 && (two.fbg1_nm - 1560.0).abs() < 0.5, "{:?}", s.array);
        assert!((s.wavelengths.fbg1_nm - 1540.0).abs() < 0.5, "{:?}", s.wavelengths);
        assert_eq!((one.fbg2_nm, two.fbg2_nm), (s.wavelengths.fbg2_nm, s.wavelengths.fbg2_nm));
        let c = CellCommand { arm_q: s.arm_q, growth_motor_rad: 0.0, twine_motor_rad: 0.0 };
        cell.write(&c).unwrap();
        cell.wait_until(k as f64 * 0.01).unwrap();
    }
    cell.deactivate().unwrap();
    drop(cell);
    // Pad 2's FBG1 window moved off its peak: no scan maps, and the error says which window.
    config = serve.real_cell_config();
    let mut pads = config.hardware.fbg.pads.as_slice().to_vec();
    pads[1].fbg1_min_nm = 1570.0;
    config.hardware.fbg.pads = PadWindowList::new(&pads).unwrap();
    let err = RealCell::new(config).configure().unwrap_err().to_string();
    assert!(err.contains("pad 2: no FBG1 peak in [1570.00, 1600.00) nm on channel 1"), "{err}");
    serve.stop().unwrap();
}
