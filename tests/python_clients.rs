//! Independent clients from PyPI against the virtual devices: SDU `ur_rtde` reads `actual_q`
//! from the virtual UR5e, drives its dashboard server, drives the arm through its own control
//! script (`RTDEControlInterface`: moveJ, moveL, servoJ, speedJ, stops) and sets IO outputs
//! (`RTDEIOInterface`), ROBOTIS `dynamixel-sdk` pings the virtual
//! MX-106, writes/reads Goal and Present Position over the pseudo-terminal, gets the e-manual's
//! status errors and sync/bulk reads the pair.
//!
//! `cargo xtask test` installs both (pinned) in `vendor/venv` and sets `TENDRIL_PYTHON`; under a
//! plain `cargo test` these tests say loudly that they are skipped.

use std::net::{IpAddr, Ipv4Addr};
use std::process::Command;
use tendril_serve::{ServeConfig, start};

use crate::common::{one_at_a_time, short_lift};

fn python() -> Option<String> {
    match std::env::var("TENDRIL_PYTHON") {
        Ok(p) if !p.is_empty() => Some(p),
        _ => {
            eprintln!(
                "SKIPPED: TENDRIL_PYTHON is not set; run `cargo xtask test` to install ur_rtde and dynamixel-sdk"
            );
            None
        }
    }
}

fn run_script(python: &str, script: &str, args: &[&str]) -> serde_json::Value {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/clients").join(script);
    let out = Command::new(python).arg(path).args(args).output().expect("python runs");
    assert!(
        out.status.success(),
        "{script} failed: {}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("the script prints JSON")
}

#[test]
fn ur_rtde_reads_actual_q_matching_the_twin() {
    let _turn = one_at_a_time();
    let Some(python) = python() else { return };
    // ur_rtde always connects to port 30004: a loopback address of its own avoids collisions.
    let mut config = ServeConfig::loopback().with_port_base(21740);
    config.bind = IpAddr::V4(Ipv4Addr::new(127, 0, 0, 74));
    config.rtde_port = 30004;
    let serve = start(&short_lift(&[]), &config).unwrap();
    let v = run_script(&python, "ur_rtde_receive.py", &["127.0.0.74"]);
    let twin = serve.state.lock().unwrap().status;
    serve.stop().unwrap();
    let q: Vec<f64> = serde_json::from_value(v["q"].clone()).unwrap();
    assert_eq!(q.len(), 6);
    // Nobody commands the arm: it holds the home pose, so any recent sample matches the twin's.
    for (a, b) in q.iter().zip(twin.arm_q) {
        assert!((a - b).abs() < 1e-3, "ur_rtde q {q:?}, twin {:?}", twin.arm_q);
    }
    assert!((q[0] + std::f64::consts::FRAC_PI_2).abs() < 1e-2, "home base joint is -90°: {q:?}");
    // The TCP pose is the forward kinematics of the same sample's joints (it was all zeros), and
    // the arm stands still.
    let q6: [f64; 6] = std::array::from_fn(|j| q[j]);
    let pose: Vec<f64> = serde_json::from_value(v["pose"].clone()).unwrap();
    let expected = tendril_ur5e::pose::tcp_pose(&q6, &[0.0; 6]);
    for (a, b) in pose.iter().zip(expected) {
        assert!((a - b).abs() < 1e-9, "ur_rtde pose {pose:?}, fk(q) {expected:?}");
    }
    assert!(pose[2] > 0.1, "{pose:?}");
    let qd: Vec<f64> = serde_json::from_value(v["qd"].clone()).unwrap();
    assert!(qd.iter().all(|v| v.abs() < 1e-6), "standing still: {qd:?}");
    assert_eq!(v["robot_mode"], 7);
    assert_eq!(v["safety_mode"], 1);
    assert!(v["t"].as_f64().unwrap() > 0.0);
}

#[test]
fn dynamixel_sdk_pings_model_321_and_moves_the_growth_motor() {
    let _turn = one_at_a_time();
    let Some(python) = python() else { return };
    let serve = start(&short_lift(&[]), &ServeConfig::loopback().with_port_base(21750)).unwrap();
    let pty = serve.pty_path.to_string_lossy().to_string();
    let goal = 300; // ticks: 0.46 rad, 5.5 mm of finger growth on the 12 mm pinion
    let v = run_script(&python, "dynamixel_sdk_client.py", &[&pty, &goal.to_string()]);
    let twin = serve.state.lock().unwrap().status;
    serve.stop().unwrap();
    assert_eq!(v["model"], 321);
    assert_eq!(v["goal"], goal);
    let present = v["present"].as_i64().unwrap();
    assert!((present - goal).abs() <= 20, "present {present}, goal {goal}: {v}");
    assert!((twin.motors_rad[0] - 300.0 * std::f64::consts::TAU / 4096.0).abs() < 0.05, "{twin:?}");
}

#[test]
fn dynamixel_sdk_gets_the_manuals_status_errors_and_syncs_and_bulk_reads_the_moving_pair() {
    let _turn = one_at_a_time();
    let Some(python) = python() else { return };
    let serve = start(&short_lift(&[]), &ServeConfig::loopback().with_port_base(21760)).unwrap();
    let pty = serve.pty_path.to_string_lossy().to_string();
    let v = run_script(&python, "dynamixel_sdk_bus.py", &[&pty]);
    let (twin, tension) = {
        let s = serve.state.lock().unwrap();
        (s.status, s.bus.table(2).unwrap().u16_at(126) as i16)
    };
    serve.stop().unwrap();
    eprintln!("{v}");
    // The e-manual's status errors, as dynamixel-sdk decodes them.
    assert_eq!(v["velocity_limit"], 360, "the control table's default");
    assert_eq!(v["data_length"], 5, "2 bytes to the 4-byte Goal Position");
    assert_eq!(v["range_goal"], 4, "Goal Position 5000 in position mode");
    assert_eq!(v["range_mode"], 4, "Operating Mode 9");
    assert_eq!(v["access_read_only"], 7, "Present Position is read-only");
    assert_eq!(v["access_undefined"], 7, "address 200 is not in the table");
    assert_eq!(v["crc"], 3, "a wrong CRC");
    assert_eq!(v["goal_after_errors"], v["goal_before_errors"], "no failed write changed Goal Position");
    // Sync write moved both motors most of the way (the twine motor against the tendon's pull,
    // which may stall it short of its goal, as on the real finger); sync read sees them there.
    // The growth motor (ID 1) runs free; the twine motor (ID 2) winds against the tendon path's
    // 6000 N/m and stalled at 472 of 600 ticks once, so it needs only half the way.
    for (id, share) in [("1", 8), ("2", 5)] {
        let (goal, present) = (v["goals"][id].as_i64().unwrap(), v["present"][id].as_i64().unwrap());
        assert!(present > goal * share / 10 && present <= goal + 10, "ID {id}: present {present}, goal {goal}: {v}");
    }
    // Bulk read saw them move: Present Velocity from the motion, Moving set on the way.
    for id in ["1", "2"] {
        assert!(v["max_velocity"][id].as_i64().unwrap() > 10, "ID {id} never reported a velocity: {v}");
    }
    assert_eq!(v["moving_seen"], true, "{v}");
    // Present Current of the twine motor is the tendon's load through gear and torque constant.
    let current = v["twine_current"].as_i64().unwrap();
    assert!(current >= 0, "the tendon pulls against the winding direction: {v}");
    assert!((current - i64::from(tension)).abs() <= 20, "last read {current}, table now {tension}: {v}");
    assert!(twine_rad_matches(&twin, v["present"]["2"].as_i64().unwrap()), "{twin:?} {v}");
}

fn twine_rad_matches(twin: &tendril_serve::TwinStatus, ticks: i64) -> bool {
    (twin.motors_rad[1] - ticks as f64 * std::f64::consts::TAU / 4096.0).abs() < 0.05
}

#[test]
fn ur_rtde_dashboard_client_drives_the_virtual_dashboard_server() {
    let _turn = one_at_a_time();
    let Some(python) = python() else { return };
    let serve = start(&short_lift(&[]), &ServeConfig::loopback().with_port_base(21870)).unwrap();
    let addr = serve.ur_addrs.dashboard;
    let v = run_script(&python, "ur_rtde_dashboard.py", &[&addr.ip().to_string(), &addr.port().to_string()]);
    let program = serve.state.lock().unwrap().program;
    serve.stop().unwrap();
    assert_eq!(v["connected"], true);
    assert_eq!(v["remote"], true, "ur_rtde asks only on PolyScope 5.6 and later: {v}");
    assert_eq!(v["version"], "5.11.1.108318");
    assert_eq!(v["robotmode"], "Robotmode: RUNNING");
    assert_eq!(v["safetystatus"], "Safetystatus: NORMAL");
    assert_eq!(v["after_power_off"], "Robotmode: POWER_OFF");
    assert_eq!(v["after_power_on"], "Robotmode: IDLE");
    assert_eq!(v["after_brake_release"], "Robotmode: RUNNING");
    assert_eq!(v["running"], true);
    assert_eq!(v["program_state"], "PLAYING /programs/follow.urp");
    assert_eq!(v["paused_state"], "PAUSED /programs/follow.urp");
    assert_eq!(v["running_after_stop"], false);
    assert_eq!(program, tendril_serve::ProgramState::Stopped);
}

fn close(a: &serde_json::Value, b: &serde_json::Value, tol: f64, what: &str) {
    let (a, b): (Vec<f64>, Vec<f64>) =
        (serde_json::from_value(a.clone()).unwrap(), serde_json::from_value(b.clone()).unwrap());
    assert_eq!(a.len(), b.len(), "{what}");
    for (x, y) in a.iter().zip(&b) {
        assert!((x - y).abs() < tol, "{what}: {a:?} vs {b:?} (tolerance {tol})");
    }
}

/// Issue 17: ur_rtde's `RTDEControlInterface` uploads its own control script (threads, a command
/// loop on the RTDE registers) and could not drive the twin: every move timed out. The virtual
/// controller now interprets it.
#[test]
fn ur_rtde_control_interface_moves_the_twin_and_io_interface_sets_outputs() {
    let _turn = one_at_a_time();
    let Some(python) = python() else { return };
    // ur_rtde always uses 30004, 30003 and 29999: a loopback address of its own.
    let mut config = ServeConfig::loopback().with_port_base(21880);
    config.bind = IpAddr::V4(Ipv4Addr::new(127, 0, 0, 75));
    (config.rtde_port, config.script_port, config.realtime_script_port, config.dashboard_port) =
        (30004, 30002, 30003, 29999);
    // The prescribed arm, so that "at rest" is exact: this checks the interpreter's moves, not the
    // servoed arm's settling (0.4 s after speedStop its base joint still turns at 2e-4 rad/s).
    let serve = start(&short_lift(&["physics.arm_mode=\"kinematic\""]), &config).unwrap();
    let v = run_script(&python, "ur_rtde_control.py", &["127.0.0.75"]);
    let (log, running) = {
        let s = serve.state.lock().unwrap();
        (s.program_log.iter().cloned().collect::<Vec<_>>(), serve.running())
    };
    serve.stop().unwrap();
    eprintln!("{v}");
    assert!(running, "serve survived the client");
    assert_eq!(v["program_running"], true, "the uploaded control script plays");
    // moveJ there and back: the arm within 1 mrad of each target.
    for ok in ["movej_ok", "movej_back_ok", "movel_ok", "servo_stop_ok", "speedj_ok", "speed_stop_ok", "movej_async_ok"]
    {
        assert_eq!(v[ok], true, "{ok}: {v}");
    }
    close(&v["after_movej"], &v["q1"], 1e-3, "moveJ");
    close(&v["after_movej_back"], &v["q0"], 1e-3, "moveJ back");
    // 0.2 rad at 1 rad/s, 2 rad/s² is a triangle of 2 sqrt(0.1) = 0.63 s; the call waits for it.
    let movej_s = v["movej_s"].as_f64().unwrap();
    assert!((0.6..2.0).contains(&movej_s), "moveJ took {movej_s} s");
    // moveL 3 cm along x and 5 cm down: the TCP there within 1 mm, the orientation unchanged.
    let (got, want): (Vec<f64>, Vec<f64>) =
        (serde_json::from_value(v["after_movel"].clone()).unwrap(), serde_json::from_value(v["p1"].clone()).unwrap());
    let to_pose = |p: &[f64]| tendril_ur5e::pose::pose_from_vector(&std::array::from_fn(|k| p[k]));
    let (got, want) = (to_pose(&got), to_pose(&want));
    let off = (got.translation.vector - want.translation.vector).norm();
    assert!(off < 1e-3, "moveL ended {off} m from its target");
    assert!(got.rotation.angle_to(&want.rotation) < 2e-3, "moveL kept the orientation");
    assert!(log.iter().any(|l| l == "movel done"), "the script's own log: {log:?}");
    // servoJ: the arm followed the streamed targets (sampled every 0.1 s, within 0.02 rad, the
    // distance covered in a few cycles) and stopped where the last one was.
    let follow: Vec<[f64; 2]> = serde_json::from_value(v["servo_follow"].clone()).unwrap();
    assert_eq!(follow.len(), 10);
    for [target, actual] in &follow {
        assert!((target - actual).abs() < 0.02, "servoJ: target {target}, arm {actual}: {follow:?}");
    }
    let moved = v["servo_last"][0].as_f64().unwrap() - v["servo_start"][0].as_f64().unwrap();
    assert!(moved > 0.15, "the servo arc moved the base {moved} rad");
    close(&v["after_servo_stop"], &v["servo_last"], 2e-3, "servoStop");
    // speedJ: the commanded speed once ramped up; speedStop and stopJ bring it to rest.
    let speed = v["speed_mean"].as_f64().unwrap();
    assert!((speed - 0.3).abs() < 0.03, "speedJ at 0.3 rad/s measured {speed}");
    close(&v["after_speed_stop_qd"], &serde_json::json!([0.0, 0.0, 0.0, 0.0, 0.0, 0.0]), 1e-6, "speedStop");
    assert!(v["drift_after_speed_stop"].as_f64().unwrap().abs() < 1e-6);
    let before = v["moving_before_stopj"][5].as_f64().unwrap();
    assert!((before + 0.3).abs() < 0.03, "the asynchronous moveJ at its 0.3 rad/s: {before}");
    close(&v["after_stopj_qd"], &serde_json::json!([0.0, 0.0, 0.0, 0.0, 0.0, 0.0]), 1e-6, "stopJ");
    let (start, end) = (v["stopj_start"][5].as_f64().unwrap(), v["after_stopj"][5].as_f64().unwrap());
    assert!(end < start - 0.2 && end > start - 0.45, "stopped part way along the 0.6 rad: {start} -> {end}");
    // RTDEIOInterface: the outputs as the receive interface reads them back.
    assert_eq!(v["io_ok"], serde_json::json!([true, true, true, true]));
    assert_eq!(v["digital_bits"], (1 << 3) + (1 << 17), "DO3 and tool output 1 (bit 16 + 1)");
    assert_eq!(v["digital_bits_after_clear"], 1 << 17);
    assert!((v["speed_fraction"].as_f64().unwrap() - 0.4).abs() < 1e-12);
    assert!((v["analog1"].as_f64().unwrap() - 3.0).abs() < 1e-9, "0.3 of 10 V: {v}");
    assert_eq!(v["running_after_stop_script"], false, "stopScript ends the program");
}
