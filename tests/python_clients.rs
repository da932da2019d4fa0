//! Independent clients from PyPI against the virtual devices: SDU `ur_rtde` reads `actual_q`
//! from the virtual UR5e and drives its dashboard server, ROBOTIS `dynamixel-sdk` pings the virtual
//! MX-106, writes/reads Goal and Present Position over the pseudo-terminal, gets the e-manual's
//! status errors and sync/bulk reads the pair.
//!
//! `cargo xtask test` installs both (pinned) in `vendor/venv` and sets `TENDRIL_PYTHON`; under a
//! plain `cargo test` these tests say loudly that they are skipped.

use std::net::{IpAddr, Ipv4Addr};
use std::process::Command;
use tendril::cell::real::serve::{ServeConfig, start};

mod common;
use common::{one_at_a_time, short_lift};

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
    let expected = tendril::cell::real::serve::pose::tcp_pose(&q6, &[0.0; 6]);
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

fn twine_rad_matches(twin: &tendril::cell::real::serve::TwinStatus, ticks: i64) -> bool {
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
    assert_eq!(program, tendril::cell::real::serve::ProgramState::Stopped);
}
