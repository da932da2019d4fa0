//! The virtual UR5e as UR's own driver uses it, with clients of our own: the primary interface
//! (the version, the robot state, key messages and runtime exceptions), a program that connects
//! back over sockets (the reverse, trajectory and script-command interfaces, written from their
//! published descriptions: `fixtures/reverse_interface.script`) and a driver that streams servoj
//! targets and a trajectory to it and sees the twin's arm follow; and hostile programs (a socket
//! to a host not allowed, an endless loop, a thread flood, a socket flood, a connection churn),
//! each stopped with its reason while RTDE and the dashboard keep answering.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::time::{Duration, Instant};
use tendril_codec::Decoded;
use tendril_rtde::primary::{Package, RobotMessage, SubPackage};
use tendril_serve::{ProgramState, ServeConfig, ServeHandle, start};

use crate::common::{one_at_a_time, short_lift};

const MULT: f64 = 1e6;

/// A primary interface client: everything the controller sends, decoded.
struct Primary {
    socket: TcpStream,
    buf: Vec<u8>,
    /// Robot messages received and not looked at yet.
    unread: std::collections::VecDeque<RobotMessage>,
}

impl Primary {
    fn connect(addr: SocketAddr) -> Primary {
        let socket = TcpStream::connect(addr).unwrap();
        socket.set_read_timeout(Some(Duration::from_millis(100))).unwrap();
        Primary { socket, buf: Vec::new(), unread: std::collections::VecDeque::new() }
    }

    fn send(&mut self, script: &str) {
        self.socket.write_all(script.as_bytes()).unwrap();
    }

    /// The packages received within `wait`.
    fn read_for(&mut self, wait: Duration) -> Vec<Package> {
        let until = Instant::now() + wait;
        let mut packages = Vec::new();
        while Instant::now() < until {
            let mut chunk = [0u8; 8192];
            match self.socket.read(&mut chunk) {
                Ok(0) => break,
                Ok(n) => self.buf.extend_from_slice(&chunk[..n]),
                Err(_) => {}
            }
            loop {
                match Package::decode(&self.buf) {
                    Decoded::Frame { packet, consumed } => {
                        self.buf.drain(..consumed);
                        packages.push(packet);
                    }
                    Decoded::NeedMore => break,
                    Decoded::Invalid { error, .. } => panic!("the primary interface sent {error}"),
                }
            }
        }
        packages
    }

    /// The first robot message matching `want` (those before it are dropped), read for at most
    /// `wait`.
    fn message(&mut self, wait: Duration, want: impl Fn(&RobotMessage) -> bool) -> Option<RobotMessage> {
        let until = Instant::now() + wait;
        loop {
            while let Some(m) = self.unread.pop_front() {
                if want(&m) {
                    return Some(m);
                }
            }
            if Instant::now() >= until {
                return None;
            }
            for p in self.read_for(Duration::from_millis(100)) {
                if let Package::Message(m) = p {
                    self.unread.push_back(m.body);
                }
            }
        }
    }
}

fn key(title: &'static str, text: &'static str) -> impl Fn(&RobotMessage) -> bool {
    move |m| matches!(m, RobotMessage::Key { title: t, text: x, .. } if t == title && x == text)
}

#[test]
fn the_primary_interface_sends_version_state_and_what_becomes_of_a_program() {
    let _turn = one_at_a_time();
    let serve = start(&short_lift(&[]), &ServeConfig::ephemeral()).unwrap();
    let mut primary = Primary::connect(serve.ur_addrs.primary);
    let first = primary.read_for(Duration::from_millis(400));
    // The version first, then robot states at 10 Hz.
    let Package::Message(m) = &first[0] else { panic!("{:?}", first[0]) };
    let RobotMessage::Version(v) = &m.body else { panic!("{m:?}") };
    assert_eq!((v.project_name.as_str(), v.major, v.minor, v.bugfix), ("URControl", 5, 11, 1));
    let states: Vec<&Vec<SubPackage>> =
        first.iter().filter_map(|p| if let Package::State(s) = p { Some(s) } else { None }).collect();
    assert!((3..=6).contains(&states.len()), "{} states in 0.4 s", states.len());
    let kinematics = states[0].iter().find_map(|s| if let SubPackage::Kinematics(k) = s { Some(k) } else { None });
    assert_eq!(kinematics.unwrap().client_library_checksum(), "calib_12788084448423163542");
    let joints = states[0].iter().find_map(|s| if let SubPackage::Joints(j) = s { Some(j) } else { None }).unwrap();
    let served = serve.state.lock().unwrap().outputs.actual_q;
    assert!((joints[1].q_actual - served[1]).abs() < 1e-3, "the twin's joints");

    // A program: started, its textmsg, stopped; a bad one: its runtime exception and line.
    primary.send("def greeting():\n  textmsg(\"hello\")\nend\n");
    assert!(primary.message(Duration::from_secs(2), key("PROGRAM_XXX_STARTED", "greeting")).is_some());
    let text = primary.message(Duration::from_secs(2), |m| matches!(m, RobotMessage::Text(t) if t == "hello"));
    assert!(text.is_some());
    assert!(primary.message(Duration::from_secs(2), key("PROGRAM_XXX_STOPPED", "greeting")).is_some());
    primary.send("def bad():\n  x = 1\n  movel(current_pos)\nend\n");
    let exception = primary.message(Duration::from_secs(2), |m| matches!(m, RobotMessage::RuntimeException { .. }));
    let Some(RobotMessage::RuntimeException { line, text, .. }) = exception else { panic!("no runtime exception") };
    assert_eq!(line, 3);
    assert!(text.contains("current_pos"), "{text}");

    // UR's client library's controller commands: stop, power off, brake release (which powers on).
    primary.send("power off\n");
    std::thread::sleep(Duration::from_millis(200));
    assert_eq!(serve.state.lock().unwrap().ur.robot_mode, tendril_rtde::dashboard::RobotMode::PowerOff);
    primary.send("set robotmode run\n");
    std::thread::sleep(Duration::from_millis(200));
    assert_eq!(serve.state.lock().unwrap().ur.robot_mode, tendril_rtde::dashboard::RobotMode::Running);
    serve.stop().unwrap();
}

/// The driver's three servers and the program connected to them.
struct Driver {
    reverse: TcpStream,
    trajectory: TcpStream,
    command: TcpStream,
}

/// Opens the driver's servers, uploads the reverse-interface program through the primary
/// interface (as UR's client library does in headless mode) and waits for its connections.
fn connect_driver(serve: &ServeHandle, primary: &mut Primary) -> Driver {
    let listeners: Vec<TcpListener> = (0..3).map(|_| TcpListener::bind("127.0.0.1:0").unwrap()).collect();
    let port = |l: &TcpListener| l.local_addr().unwrap().port().to_string();
    let program = include_str!("fixtures/reverse_interface.script")
        .replace("{HOST}", "127.0.0.1")
        .replace("{REVERSE}", &port(&listeners[0]))
        .replace("{TRAJECTORY}", &port(&listeners[1]))
        .replace("{COMMAND}", &port(&listeners[2]));
    primary.send(&format!("stop program\n{program}\n"));
    let accept = |l: &TcpListener| {
        l.set_nonblocking(true).unwrap();
        let until = Instant::now() + Duration::from_secs(5);
        loop {
            match l.accept() {
                Ok((s, _)) => {
                    s.set_nonblocking(false).unwrap();
                    s.set_nodelay(true).unwrap();
                    return s;
                }
                Err(_) if Instant::now() < until => std::thread::sleep(Duration::from_millis(5)),
                Err(e) => {
                    panic!("the program did not connect back ({e}): {:?}", serve.state.lock().unwrap().program_log)
                }
            }
        }
    };
    let trajectory = accept(&listeners[1]);
    let command = accept(&listeners[2]);
    let reverse = accept(&listeners[0]);
    Driver { reverse, trajectory, command }
}

fn ints(values: &[i32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_be_bytes()).collect()
}

impl Driver {
    /// A reverse-interface message: read timeout, six values, mode.
    fn reverse(&mut self, timeout_ms: i32, values: [i32; 6], mode: i32) {
        let mut m = vec![timeout_ms];
        m.extend(values);
        m.push(mode);
        self.reverse.write_all(&ints(&m)).unwrap();
    }

    fn servo(&mut self, q: [f64; 6]) {
        self.reverse(100, q.map(|v| (v * MULT).round() as i32), 1);
    }
}

/// A movej trajectory point to `q` taking `t` seconds.
fn movej_point(q: [f64; 6], t: f64) -> Vec<u8> {
    let mut p: Vec<i32> = q.iter().map(|v| (v * MULT).round() as i32).collect();
    p.extend([0; 6]);
    p.extend([(1.0 * MULT) as i32, (1.4 * MULT) as i32, 0, 0, 0, 0]);
    p.extend([(t * MULT) as i32, 0, 0]);
    ints(&p)
}

fn actual_q(serve: &ServeHandle) -> [f64; 6] {
    serve.state.lock().unwrap().outputs.actual_q
}

#[test]
fn a_driver_of_our_own_streams_servoj_targets_and_a_trajectory_and_the_twins_arm_follows() {
    let _turn = one_at_a_time();
    let serve = start(&short_lift(&[]), &ServeConfig::ephemeral()).unwrap();
    let mut primary = Primary::connect(serve.ur_addrs.primary);
    let mut driver = connect_driver(&serve, &mut primary);
    assert!(primary.message(Duration::from_secs(2), key("PROGRAM_XXX_STARTED", "driver_side")).is_some());

    // servoj: wrist 3 ramped 0.3 rad over 1.5 s, one target every 2 ms, as a driver streams them.
    let start_q = actual_q(&serve);
    let clock = Instant::now();
    let (mut worst_lag, mut target) = (0.0f64, start_q);
    while clock.elapsed() < Duration::from_millis(1800) {
        let t = clock.elapsed().as_secs_f64().min(1.5);
        target[5] = start_q[5] + 0.2 * t;
        driver.servo(target);
        // The measured arm against the setpoint the program gave it (a twin behind real time on a
        // loaded machine plays the stream late; it still follows what it plays).
        let served = serve.state.lock().unwrap().outputs.clone();
        worst_lag = worst_lag.max((served.target_q[5] - served.actual_q[5]).abs());
        std::thread::sleep(Duration::from_millis(2));
    }
    let clock = Instant::now();
    while actual_q(&serve)[5] - start_q[5] < 0.3 - 5e-3 && clock.elapsed() < Duration::from_secs(3) {
        driver.servo(target);
        std::thread::sleep(Duration::from_millis(2));
    }
    let reached = actual_q(&serve)[5] - start_q[5];
    assert!((reached - 0.3).abs() < 5e-3, "wrist 3 moved {reached} rad of 0.3");
    // A 0.2 rad/s ramp followed within a few cycles' way (the servo path's delay and the physics
    // step's half behind the clock: about 7 ms, 1.4 mrad).
    assert!(worst_lag < 0.01, "wrist 3 lagged its setpoint by up to {worst_lag} rad");
    let now_q = actual_q(&serve);
    for (j, (now, start)) in now_q.iter().zip(start_q).take(5).enumerate() {
        assert!((now - start).abs() < 1e-3, "joint {j} stayed");
    }

    // A trajectory of two movej points: wrist 2 out by 0.1 rad in 0.8 s and back in 0.8 s.
    let here = actual_q(&serve);
    let mut out = here;
    out[4] += 0.1;
    driver.reverse(1000, [1, 2, 0, 0, 0, 0], 3);
    driver.trajectory.write_all(&[movej_point(out, 0.8), movej_point(here, 0.8)].concat()).unwrap();
    driver.trajectory.set_read_timeout(Some(Duration::from_millis(100))).unwrap();
    let (clock, mut farthest, mut result) = (Instant::now(), 0.0f64, None);
    while result.is_none() && clock.elapsed() < Duration::from_secs(5) {
        driver.reverse(1000, [0; 6], 3);
        farthest = farthest.max(actual_q(&serve)[4] - here[4]);
        let mut r = [0u8; 4];
        if driver.trajectory.read_exact(&mut r).is_ok() {
            result = Some(i32::from_be_bytes(r));
        }
    }
    assert_eq!(result, Some(0), "trajectory result (0: success)");
    assert!((farthest - 0.1).abs() < 0.01, "wrist 2 went out {farthest} rad of 0.1");
    assert!((actual_q(&serve)[4] - here[4]).abs() < 5e-3, "and came back");

    // A script command: set_payload(1.5 kg, cog 5 cm along z).
    let mut c = vec![1, (1.5 * MULT) as i32, 0, 0, (0.05 * MULT) as i32];
    c.resize(28, 0);
    driver.command.write_all(&ints(&c)).unwrap();
    let clock = Instant::now();
    while serve.state.lock().unwrap().outputs.payload_kg != 1.5 && clock.elapsed() < Duration::from_secs(2) {
        std::thread::sleep(Duration::from_millis(10));
    }
    assert_eq!(serve.state.lock().unwrap().outputs.payload_cog, [0.0, 0.0, 0.05]);

    // Stopped by the driver: the program ends and says so.
    driver.reverse(0, [0; 6], -2);
    assert!(primary.message(Duration::from_secs(3), key("PROGRAM_XXX_STOPPED", "driver_side")).is_some());
    assert_eq!(serve.state.lock().unwrap().program, ProgramState::Stopped);
    serve.stop().unwrap();
}

/// The dashboard answers `robotmode` and RTDE still streams: the controller serves on.
fn still_serving(serve: &ServeHandle) {
    let mut d = TcpStream::connect(serve.ur_addrs.dashboard).unwrap();
    d.set_read_timeout(Some(Duration::from_secs(2))).unwrap();
    let mut r = BufReader::new(d.try_clone().unwrap());
    let mut line = String::new();
    r.read_line(&mut line).unwrap();
    d.write_all(b"robotmode\n").unwrap();
    line.clear();
    r.read_line(&mut line).unwrap();
    assert_eq!(line.trim(), "Robotmode: RUNNING");
    let before = serve.state.lock().unwrap().status.ticks;
    let mut rtde = TcpStream::connect(serve.addrs[0]).unwrap();
    rtde.set_read_timeout(Some(Duration::from_secs(2))).unwrap();
    rtde.write_all(&[0, 5, b'V', 0, 2]).unwrap();
    let mut reply = [0u8; 4];
    rtde.read_exact(&mut reply).unwrap();
    assert_eq!(reply, [0, 4, b'V', 1], "RTDE accepts protocol version 2");
    std::thread::sleep(Duration::from_millis(200));
    assert!(serve.state.lock().unwrap().status.ticks > before, "the twin ticks on");
}

/// Uploads `program` on the secondary port and waits until it has stopped; its last log line.
fn stopped_with(serve: &ServeHandle, program: &str, within: Duration) -> String {
    let uploads = serve.state.lock().unwrap().program_uploads;
    TcpStream::connect(serve.addrs[1]).unwrap().write_all(program.as_bytes()).unwrap();
    let clock = Instant::now();
    loop {
        {
            let s = serve.state.lock().unwrap();
            if s.program_uploads > uploads && s.program == ProgramState::Stopped {
                return s.program_log.back().cloned().unwrap_or_default();
            }
        }
        assert!(clock.elapsed() < within, "still running after {within:?}: {program}");
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn hostile_programs_are_stopped_with_their_reason_while_rtde_and_the_dashboard_answer() {
    let _turn = one_at_a_time();
    let serve = start(&short_lift(&[]), &ServeConfig::ephemeral()).unwrap();
    let target = TcpListener::bind("127.0.0.1:0").unwrap();
    let port = target.local_addr().unwrap().port();
    for (program, within, reason) in [
        (
            "def far():\n  socket_open(\"192.0.2.7\", 50001, \"reverse_socket\")\nend\n".to_string(),
            Duration::from_secs(2),
            "line 2: socket_open: 192.0.2.7 is not an allowed host",
        ),
        (
            "def spin():\n  x = 0\n  while True:\n    x = x + 1\n  end\nend\n".to_string(),
            Duration::from_secs(4),
            "a thread used its whole 2 ms time slice for 1 s",
        ),
        (
            "def threads():\n  thread t():\n    sleep(10)\n  end\n  while True:\n    run t()\n  end\nend\n".to_string(),
            Duration::from_secs(2),
            "line 6: more than 32 threads",
        ),
        (
            format!(
                "def sockets():\n  n = 0\n  while True:\n    socket_open(\"127.0.0.1\", {port}, str_cat(\"s\", n))\n    n = n + 1\n  end\nend\n"
            ),
            Duration::from_secs(3),
            "line 4: socket_open: more than 16 sockets open at once",
        ),
        (
            format!(
                "def churn():\n  while True:\n    socket_open(\"127.0.0.1\", {port})\n    socket_close()\n  end\nend\n"
            ),
            Duration::from_secs(3),
            "line 3: socket_open: more than 50 sockets opened within a second",
        ),
    ] {
        let line = stopped_with(&serve, &program, within);
        assert!(line.contains(reason), "{program}\nstopped with {line:?}, not {reason:?}");
        still_serving(&serve);
    }
    serve.stop().unwrap();
}
