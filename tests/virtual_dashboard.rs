//! The virtual UR5e's dashboard server (29999) and real-time script port (30003), and the real
//! path's dashboard check: with each UR precondition failing in turn, configure fails and the
//! error names that precondition.

use std::io::{BufRead, BufReader, Write};
use std::net::{SocketAddr, TcpStream};
use std::time::{Duration, Instant};
use tendril_cell::Cell;
use tendril_drivers::RealCell;
use tendril_rtde::dashboard::RobotMode;
use tendril_serve::{ProgramState, ServeConfig, ServeHandle, start};
use tendril_urscript::FOLLOW_SCRIPT;

use crate::common::{one_at_a_time, short_lift};

/// A line-oriented dashboard client on a plain socket.
struct Dashboard {
    reader: BufReader<TcpStream>,
}

impl Dashboard {
    fn connect(addr: SocketAddr) -> (Dashboard, String) {
        let s = TcpStream::connect(addr).unwrap();
        s.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
        let mut d = Dashboard { reader: BufReader::new(s) };
        let greeting = d.line();
        (d, greeting)
    }

    fn line(&mut self) -> String {
        let mut line = String::new();
        self.reader.read_line(&mut line).unwrap();
        line.trim_end().to_string()
    }

    fn ask(&mut self, command: &str) -> String {
        self.reader.get_mut().write_all(format!("{command}\n").as_bytes()).unwrap();
        self.line()
    }
}

fn program(serve: &ServeHandle) -> ProgramState {
    serve.state.lock().unwrap().program
}

#[test]
fn the_dashboard_answers_as_the_controller_does_and_30003_takes_programs() {
    let _turn = one_at_a_time();
    let serve = start(&short_lift(&[]), &ServeConfig::loopback().with_port_base(21850)).unwrap();
    let (mut d, greeting) = Dashboard::connect(serve.ur_addrs.dashboard);
    assert_eq!(greeting, "Connected: Universal Robots Dashboard Server");
    assert_eq!(d.ask("robotmode"), "Robotmode: RUNNING");
    assert_eq!(d.ask("safetystatus"), "Safetystatus: NORMAL");
    assert_eq!(d.ask("safetymode"), "Safetymode: NORMAL");
    assert_eq!(d.ask("is in remote control"), "true");
    assert_eq!(d.ask("PolyscopeVersion"), "URSoftware 5.11.1.108318 (Mar 23 2021)");
    assert_eq!(d.ask("programState"), "STOPPED <unnamed>");
    assert_eq!(d.ask("running"), "Program running: false");
    assert_eq!(d.ask("play"), "Failed to execute: play", "nothing loaded");
    // A program on the real-time interface port plays, as one on 30002 does.
    let mut s = TcpStream::connect(serve.ur_addrs.realtime_script).unwrap();
    s.write_all(FOLLOW_SCRIPT.as_bytes()).unwrap();
    drop(s);
    let deadline = Instant::now() + Duration::from_secs(5);
    while program(&serve) != ProgramState::Playing && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(10));
    }
    assert_eq!(d.ask("running"), "Program running: true");
    assert_eq!(d.ask("pause"), "Pausing program");
    assert_eq!(d.ask("programState"), "PAUSED <unnamed>");
    assert_eq!(d.ask("stop"), "Stopped");
    assert_eq!(d.ask("stop"), "Failed to execute: stop");
    assert_eq!(d.ask("load /programs/nothing.txt"), "File not found: /programs/nothing.txt");
    assert_eq!(d.ask("load /programs/follow.urp"), "Loading program: /programs/follow.urp");
    assert_eq!(d.ask("play"), "Starting program");
    assert_eq!(d.ask("programState"), "PLAYING /programs/follow.urp");
    // Power off stops the program; power on and brake release bring the robot back to RUNNING.
    assert_eq!(d.ask("power off"), "Powering off");
    assert_eq!(d.ask("robotmode"), "Robotmode: POWER_OFF");
    assert_eq!(program(&serve), ProgramState::Stopped);
    assert_eq!(d.ask("play"), "Failed to execute: play", "powered off");
    assert_eq!(d.ask("power on"), "Powering on");
    assert_eq!(d.ask("robotmode"), "Robotmode: IDLE");
    assert_eq!(d.ask("brake release"), "Brake releasing");
    assert_eq!(d.ask("robotmode"), "Robotmode: RUNNING");
    // RTDE's robot_mode follows at the twin's next tick.
    let deadline = Instant::now() + Duration::from_secs(2);
    while serve.state.lock().unwrap().outputs.robot_mode != 7 && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(5));
    }
    assert_eq!(serve.state.lock().unwrap().outputs.robot_mode, 7, "RTDE robot_mode follows");
    // A protective stop unlocks 5 s after it happened, not before.
    {
        let mut s = serve.state.lock().unwrap();
        s.protective_stop = Some("test".into());
        s.ur.protective_stop_at = Some(s.status.time_s);
    }
    assert_eq!(d.ask("safetystatus"), "Safetystatus: PROTECTIVE_STOP");
    assert!(d.ask("unlock protective stop").starts_with("Cannot unlock protective stop until 5s after occurrence"));
    serve.state.lock().unwrap().ur.protective_stop_at = Some(-10.0);
    assert_eq!(d.ask("unlock protective stop"), "Protective stop releasing");
    assert_eq!(d.ask("safetystatus"), "Safetystatus: NORMAL");
    assert_eq!(d.ask("close safety popup"), "closing safety popup");
    assert_eq!(d.ask("fly to the moon"), "could not understand: 'fly to the moon'");
    assert_eq!(d.ask("quit"), "Disconnected");
    assert_eq!(d.line(), "", "closed after quit");
    // In local control, the robot takes no program from outside.
    serve.state.lock().unwrap().ur.remote_control = false;
    let (mut d, _) = Dashboard::connect(serve.ur_addrs.dashboard);
    assert_eq!(d.ask("is in remote control"), "false");
    assert!(d.ask("play").contains("remote control"), "refused in local control");
    assert_eq!(d.ask("stop"), "Failed to execute: stop", "stop is allowed in local control (nothing runs)");
    let uploads = serve.state.lock().unwrap().program_uploads;
    let mut s = TcpStream::connect(serve.addrs[1]).unwrap();
    s.write_all(FOLLOW_SCRIPT.as_bytes()).unwrap();
    drop(s);
    std::thread::sleep(Duration::from_millis(300));
    assert_eq!(serve.state.lock().unwrap().program_uploads, uploads, "ignored in local control");
    assert_eq!(program(&serve), ProgramState::Stopped);
    assert!(serve.running());
    serve.stop().unwrap();
}

/// The real path's configure against the virtual UR in `set`'s state: the error, if any.
fn configure_error(serve: &ServeHandle, set: impl FnOnce(&mut tendril_serve::DeviceState)) -> String {
    set(&mut serve.state.lock().unwrap());
    let mut cell = RealCell::new(serve.real_cell_config());
    let result = cell.configure();
    let _ = cell.deactivate();
    drop(cell);
    result.err().map(|e| e.to_string()).unwrap_or_default()
}

#[test]
fn each_ur_precondition_failing_in_turn_is_named_by_the_real_path() {
    let _turn = one_at_a_time();
    let serve = start(&short_lift(&[]), &ServeConfig::loopback().with_port_base(21860)).unwrap();
    let error = configure_error(&serve, |s| s.ur.remote_control = false);
    assert!(error.contains("not in remote control"), "{error}");
    let error = configure_error(&serve, |s| {
        s.ur.remote_control = true;
        s.ur.robot_mode = RobotMode::PowerOff;
    });
    assert!(error.contains("robot mode is POWER_OFF, not RUNNING"), "{error}");
    let error = configure_error(&serve, |s| s.ur.robot_mode = RobotMode::Idle);
    assert!(error.contains("robot mode is IDLE"), "{error}");
    let error = configure_error(&serve, |s| {
        s.ur.robot_mode = RobotMode::Running;
        s.protective_stop = Some("test".into());
    });
    assert!(error.contains("safety status is PROTECTIVE_STOP, not NORMAL"), "{error}");
    let error = configure_error(&serve, |s| {
        s.protective_stop = None;
        s.ur.polyscope_version = "URSoftware 3.15.7.106331 (Dec 14 2021)".into();
    });
    assert!(error.contains("PolyScope 3.15.7.106331; the follow program needs 5.0.0.0"), "{error}");
    // PolyScope 5.5 has no remote control: local control is no failure there, and with every
    // precondition met the program is uploaded and plays.
    let error = configure_error(&serve, |s| {
        s.ur.polyscope_version = "URSoftware 5.5.1.1 (Jan 1 2020)".into();
        s.ur.remote_control = false;
    });
    assert_eq!(error, "", "all preconditions met");
    assert_eq!(program(&serve), ProgramState::Playing);
    serve.stop().unwrap();
}
