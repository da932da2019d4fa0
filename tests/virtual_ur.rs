//! The virtual UR5e as a client that is not ours sees it, over plain RTDE and the script port:
//! TCP pose and joint velocities consistent with the joint angles, the names UR's output list has,
//! a protective stop (never a diverged twin) on hostile targets, and the follow program's RTDE
//! watchdog stopping the arm when the client's input stream stops.

use std::collections::VecDeque;
use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::time::{Duration, Instant};
use tendril_rtde::{ClientEvent, ClientPacket, ClientSession, RtdeValue};
use tendril_serve::{ServeConfig, ServeHandle, start};
use tendril_ur5e::pose::tcp_pose;
use tendril_urscript::{FOLLOW_SCRIPT, input_names};

use crate::common::{one_at_a_time, short_lift};

/// A blocking RTDE client on a plain socket.
struct Rtde {
    socket: TcpStream,
    session: ClientSession,
    buf: Vec<u8>,
    events: VecDeque<ClientEvent>,
    input_recipe: u8,
    /// The client's clock: targets are stamped with their time on it.
    clock: Instant,
}

impl Rtde {
    /// Connects, negotiates version 2, sets up `outputs` at 500 Hz and (if any) `inputs`, starts.
    fn start(addr: SocketAddr, outputs: &[&str], inputs: &[&str]) -> Rtde {
        let socket = TcpStream::connect(addr).unwrap();
        socket.set_nodelay(true).unwrap();
        let mut c = Rtde {
            socket,
            session: ClientSession::new(),
            buf: Vec::new(),
            events: VecDeque::new(),
            input_recipe: 0,
            clock: Instant::now(),
        };
        let p = c.session.request_protocol_version();
        assert_eq!(c.request(p), ClientEvent::ProtocolVersion { accepted: true });
        let p = c.session.setup_outputs(500.0, outputs).unwrap();
        assert!(matches!(c.request(p), ClientEvent::OutputRecipe(_)), "outputs {outputs:?} refused");
        if !inputs.is_empty() {
            let p = c.session.setup_inputs(inputs).unwrap();
            match c.request(p) {
                ClientEvent::InputRecipe(r) => c.input_recipe = r.id,
                other => panic!("inputs refused: {other:?}"),
            }
        }
        let p = c.session.start();
        assert_eq!(c.request(p), ClientEvent::Started { accepted: true });
        c
    }

    fn send(&mut self, p: ClientPacket) {
        self.socket.write_all(&p.encode().unwrap()).unwrap();
    }

    /// Reads until at least one event is queued or `deadline` passes.
    fn fill(&mut self, deadline: Instant) {
        let mut chunk = [0u8; 8192];
        while self.events.is_empty() {
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return;
            }
            self.socket.set_read_timeout(Some(left.max(Duration::from_millis(1)))).unwrap();
            match self.socket.read(&mut chunk) {
                Ok(0) => panic!("the virtual UR closed the connection"),
                Ok(n) => {
                    self.buf.extend_from_slice(&chunk[..n]);
                    self.events.extend(self.session.feed(&mut self.buf).unwrap());
                }
                Err(e) if matches!(e.kind(), std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut) => {}
                Err(e) => panic!("RTDE read: {e}"),
            }
        }
    }

    /// Sends a request and returns the first reply that is not a data package.
    fn request(&mut self, p: ClientPacket) -> ClientEvent {
        self.send(p);
        let deadline = Instant::now() + Duration::from_secs(2);
        loop {
            self.fill(deadline);
            match self.events.pop_front() {
                Some(ClientEvent::Data { .. }) => {}
                Some(e) => return e,
                None => panic!("no reply within 2 s"),
            }
        }
    }

    /// The six targets, their time on the client's clock (now) and the enable flag of the follow
    /// program, in one package.
    fn targets(&mut self, q: [f64; 6], enable: bool) {
        let mut values: Vec<RtdeValue> = q.iter().map(|&v| RtdeValue::Double(v)).collect();
        values.push(RtdeValue::Double(self.clock.elapsed().as_secs_f64()));
        values.push(RtdeValue::Int32(i32::from(enable)));
        let p = self.session.input_data(self.input_recipe, &values).unwrap();
        self.send(p);
    }

    /// Every data package until `deadline`.
    fn samples_until(&mut self, deadline: Instant) -> Vec<Vec<RtdeValue>> {
        let mut out = Vec::new();
        while Instant::now() < deadline {
            self.fill(deadline);
            while let Some(e) = self.events.pop_front() {
                if let ClientEvent::Data { values, .. } = e {
                    out.push(values);
                }
            }
        }
        out
    }

    /// The latest data package after `wait`.
    fn latest_after(&mut self, wait: Duration) -> Vec<RtdeValue> {
        self.samples_until(Instant::now() + wait).pop().expect("data packages stream while started")
    }
}

fn upload(serve: &ServeHandle, program: &str) {
    let mut s = TcpStream::connect(serve.addrs[1]).unwrap();
    s.write_all(program.as_bytes()).unwrap();
    drop(s);
    std::thread::sleep(Duration::from_millis(50));
}

fn v6(v: &RtdeValue) -> [f64; 6] {
    match v {
        RtdeValue::Vector6d(x) => *x,
        other => panic!("not a VECTOR6D: {other:?}"),
    }
}

fn f(v: &RtdeValue) -> f64 {
    match v {
        RtdeValue::Double(x) => *x,
        other => panic!("not a DOUBLE: {other:?}"),
    }
}

fn int(v: &RtdeValue) -> i64 {
    match *v {
        RtdeValue::Int32(x) => x.into(),
        RtdeValue::Uint32(x) => x.into(),
        RtdeValue::Uint64(x) => x as i64,
        ref other => panic!("not an integer: {other:?}"),
    }
}

/// Issue: `actual_TCP_pose` was always zero and `actual_qd` five times the true speed; five names
/// of UR's output list answered NOT_FOUND.
#[test]
fn tcp_pose_follows_actual_q_and_actual_qd_is_the_derivative_of_actual_q() {
    let _turn = one_at_a_time();
    // A 5 ms physics step, so that two or three 2 ms RTDE samples fall inside each step, where
    // actual_qd is constant and the derivative check below applies (at the default 2.5 ms step
    // a step holds one sample or two).
    let serve =
        start(&short_lift(&["physics.timestep_s=0.005"]), &ServeConfig::loopback().with_port_base(21800)).unwrap();
    upload(&serve, FOLLOW_SCRIPT);
    let outputs = [
        "timestamp",
        "actual_q",
        "actual_qd",
        "actual_TCP_pose",
        "target_TCP_pose",
        "target_q",
        "tcp_offset",
        "actual_configurable_digital_input_bits",
        "actual_configurable_digital_output_bits",
        "encoder0_raw",
        "encoder1_raw",
    ];
    let names = input_names();
    let inputs: Vec<&str> = names.iter().map(String::as_str).collect();
    let mut c = Rtde::start(serve.addrs[0], &outputs, &inputs);
    let first = c.latest_after(Duration::from_millis(50));
    let q0 = v6(&first[1]);
    assert_eq!(v6(&first[6]), [0.0; 6], "no TCP offset configured");
    for (k, name) in outputs.iter().enumerate().skip(7) {
        assert_eq!(int(&first[k]), 0, "{name}");
    }
    // Joint 0 at 0.4 rad/s and joint 4 at -0.3 rad/s for 0.6 s, targets at 100 Hz.
    let speed = [0.4, 0.0, 0.0, 0.0, -0.3, 0.0];
    let started = Instant::now();
    let mut samples = Vec::new();
    for k in 0..=60 {
        let t = k as f64 * 0.01;
        c.targets(std::array::from_fn(|j| q0[j] + speed[j] * t), true);
        samples.extend(c.samples_until(started + Duration::from_secs_f64(t + 0.01)));
    }
    c.targets(std::array::from_fn(|j| q0[j] + speed[j] * 0.6), false);
    assert!(serve.running());
    serve.stop().unwrap();

    /// timestamp, actual_q, actual_qd, actual_TCP_pose, target_TCP_pose, target_q.
    type Sample = (f64, [f64; 6], [f64; 6], [f64; 6], [f64; 6], [f64; 6]);
    let parsed: Vec<Sample> =
        samples.iter().map(|s| (f(&s[0]), v6(&s[1]), v6(&s[2]), v6(&s[3]), v6(&s[4]), v6(&s[5]))).collect();
    // The pose is the forward kinematics of the joint angles of the same sample, target likewise.
    for (_, q, _, pose, target_pose, target_q) in &parsed {
        let reach = (pose[0] * pose[0] + pose[1] * pose[1]).sqrt();
        assert!(reach > 0.1 && pose[2] > 0.1, "a zero-like pose: {pose:?}");
        let expected = tcp_pose(q, &[0.0; 6]);
        let expected_target = tcp_pose(target_q, &[0.0; 6]);
        for k in 0..6 {
            assert!((pose[k] - expected[k]).abs() < 1e-9, "{pose:?} vs fk({q:?}) = {expected:?}");
            assert!((target_pose[k] - expected_target[k]).abs() < 1e-9, "{target_pose:?} vs {expected_target:?}");
        }
    }
    // Distinct samples only (a package may repeat the sample before it).
    let mut steps: Vec<(f64, [f64; 6], [f64; 6])> = Vec::new();
    for &(t, q, qd, ..) in &parsed {
        if steps.last().is_none_or(|s| t > s.0 + 1e-9) {
            steps.push((t, q, qd));
        }
    }
    let moved = steps.last().unwrap().1[0] - steps[0].1[0];
    assert!(moved > 0.15, "the arm followed: joint 0 moved {moved} rad");
    let t_start = steps[0].0;
    let inside: Vec<_> = steps.iter().filter(|s| s.0 > t_start + 0.1 && s.0 < t_start + 0.55).collect();
    // A new sample in (nearly) every 2 ms package of the 500 Hz recipe, not one per 5 ms physics step.
    assert!(inside.len() > 150, "{} distinct samples in 0.45 s", inside.len());
    // actual_qd is the derivative of actual_q: between two samples with the same actual_qd (the
    // arm moves at a constant rate within a physics step, and RTDE reports it interpolated between
    // steps) the joints moved by exactly that speed times the time between them. It was five
    // times the true speed in one sample of five, zero in the others.
    let mut pairs = 0;
    for p in inside.windows(2) {
        let (a, b) = (p[0], p[1]);
        for j in [0, 4] {
            if a.2[j] == b.2[j] && a.2[j].abs() > 0.01 {
                let derivative = (b.1[j] - a.1[j]) / (b.0 - a.0);
                assert!(
                    (derivative - b.2[j]).abs() < 1e-6,
                    "joint {j} over {:.4}..{:.4} s: dq/dt {derivative:.6} rad/s, actual_qd {:.6} rad/s",
                    a.0,
                    b.0,
                    b.2[j]
                );
                pairs += 1;
            }
        }
    }
    assert!(pairs > 100, "{pairs} pairs within a step");
    // Over the motion the time-weighted mean of actual_qd equals the mean speed.
    let (a, b) = (inside[0], inside[inside.len() - 1]);
    for j in [0, 4] {
        let integral: f64 = inside.windows(2).map(|p| p[1].2[j] * (p[1].0 - p[0].0)).sum::<f64>() / (b.0 - a.0);
        let derivative = (b.1[j] - a.1[j]) / (b.0 - a.0);
        assert!((integral - derivative).abs() < 0.05 * speed[j].abs(), "joint {j}: {integral} vs {derivative}");
    }
    // The speed is the commanded one over the whole span (over one 50 ms window a target the
    // client sent a tick late on a loaded machine moves it by a quarter).
    for j in [0, 4] {
        let derivative = (b.1[j] - a.1[j]) / (b.0 - a.0);
        assert!((derivative - speed[j]).abs() < 0.1 * speed[j].abs(), "joint {j}: {derivative} vs {}", speed[j]);
    }
}

/// Issue: a program plus 100 rad (or 1e308, or NaN) targets with enable = 1 made the twin
/// diverge and `serve` exit. Now: a protective stop, the arm where it was, the devices serving.
#[test]
fn hostile_targets_end_in_a_protective_stop_and_serve_keeps_serving() {
    let _turn = one_at_a_time();
    let serve = start(&short_lift(&[]), &ServeConfig::loopback().with_port_base(21810)).unwrap();
    let watch =
        ["timestamp", "actual_q", "safety_mode", "safety_status", "runtime_state", "robot_mode", "safety_status_bits"];
    let mut observer = Rtde::start(serve.addrs[0], &watch, &[]);
    let names = input_names();
    let inputs: Vec<&str> = names.iter().map(String::as_str).collect();
    let mut hostile = Rtde::start(serve.addrs[0], &["timestamp"], &inputs);
    let q0 = v6(&observer.latest_after(Duration::from_millis(50))[1]);
    for bad in [100.0, 1e308, f64::NAN, -f64::INFINITY] {
        upload(&serve, FOLLOW_SCRIPT);
        let s = observer.latest_after(Duration::from_millis(20));
        assert_eq!((int(&s[2]), int(&s[4])), (1, 2), "{bad}: a fresh upload plays, safety normal");
        for _ in 0..50 {
            hostile.targets([bad; 6], true);
            std::thread::sleep(Duration::from_millis(2));
        }
        // A valid target after the stop is ignored too.
        hostile.targets(std::array::from_fn(|j| q0[j] + 0.01), true);
        let s = observer.latest_after(Duration::from_millis(200));
        assert!(serve.running(), "{bad}: serve must keep running");
        assert_eq!(int(&s[2]), 3, "{bad}: safety_mode PROTECTIVE_STOP");
        assert_eq!(int(&s[3]), 3, "{bad}: safety_status PROTECTIVE_STOP");
        assert_eq!(int(&s[4]), 1, "{bad}: runtime_state STOPPED");
        assert_eq!(int(&s[5]), 7, "{bad}: robot_mode stays RUNNING");
        assert_eq!(int(&s[6]), 1 << 2, "{bad}: safety_status_bits: protective stopped");
        let q = v6(&s[1]);
        for j in 0..6 {
            assert!((q[j] - q0[j]).abs() < 0.02, "{bad}: the arm moved: {q:?} from {q0:?}");
        }
        let why = serve.state.lock().unwrap().protective_stop.clone();
        assert!(why.is_some_and(|w| w.contains("joint 0")), "{bad}");
    }
    // A fresh upload and sane targets: back to normal, following.
    upload(&serve, FOLLOW_SCRIPT);
    for k in 0..30 {
        hostile.targets(std::array::from_fn(|j| q0[j] + 0.001 * k as f64), true);
        std::thread::sleep(Duration::from_millis(10));
    }
    let s = observer.latest_after(Duration::from_millis(20));
    assert_eq!((int(&s[2]), int(&s[4])), (1, 2));
    assert!((v6(&s[1])[0] - (q0[0] + 0.029)).abs() < 0.005, "following again: {:?}", v6(&s[1]));
    assert!(serve.running());
    serve.stop().unwrap();
}

/// The follow program's `rtde_set_watchdog`: a client that stops writing stops the program and
/// the arm; new targets are then not followed.
#[test]
fn a_client_that_stops_sending_stops_the_follow_program() {
    let _turn = one_at_a_time();
    let serve = start(&short_lift(&[]), &ServeConfig::loopback().with_port_base(21820)).unwrap();
    upload(&serve, FOLLOW_SCRIPT);
    let names = input_names();
    let inputs: Vec<&str> = names.iter().map(String::as_str).collect();
    let outputs = ["timestamp", "actual_q", "runtime_state", "output_int_register_24", "robot_status_bits"];
    let mut c = Rtde::start(serve.addrs[0], &outputs, &inputs);
    let q0 = v6(&c.latest_after(Duration::from_millis(50))[1]);
    // Before the first enabled target the watchdog is not armed: a quiet client keeps it playing.
    let s = c.latest_after(Duration::from_millis(700));
    assert_eq!(int(&s[2]), 2, "not armed before enable");
    for k in 0..30 {
        c.targets(std::array::from_fn(|j| q0[j] + 0.001 * k as f64), true);
        std::thread::sleep(Duration::from_millis(10));
    }
    let s = c.latest_after(Duration::from_millis(5));
    assert_eq!((int(&s[2]), int(&s[3]), int(&s[4]) & 2), (2, 1, 2), "playing and following");
    // The client goes quiet with enable = 1 (as if it died): past 1 / min_frequency the program stops.
    let silent = Instant::now();
    let samples = c.samples_until(silent + Duration::from_millis(900));
    let stopped_at = samples.iter().position(|s| int(&s[2]) == 1).expect("the program stops");
    let playing_for = f(&samples[stopped_at][0]) - f(&samples[0][0]);
    assert!((0.4..0.7).contains(&playing_for), "stopped {playing_for:.3} s after the last package");
    let s = samples.last().unwrap();
    assert_eq!((int(&s[2]), int(&s[3]), int(&s[4]) & 2), (1, 0, 0), "stopped, not following");
    let held = v6(&s[1]);
    // Targets that come later are not followed (the program is not running).
    for _ in 0..20 {
        c.targets(std::array::from_fn(|j| held[j] + 0.05), true);
        std::thread::sleep(Duration::from_millis(10));
    }
    let s = c.latest_after(Duration::from_millis(50));
    assert!((v6(&s[1])[0] - held[0]).abs() < 1e-3, "the arm stays stopped");
    assert_eq!(int(&s[2]), 1);
    serve.stop().unwrap();
}

/// Issue 17: programs are interpreted; one that the virtual controller cannot run stops with a
/// logged error naming its line, the arm held, and `serve` goes on serving the next program.
#[test]
fn bad_programs_stop_with_their_line_in_the_log_and_serve_runs_the_next_one() {
    let _turn = one_at_a_time();
    let serve = start(&short_lift(&[]), &ServeConfig::loopback().with_port_base(21890)).unwrap();
    let mut c = Rtde::start(serve.addrs[0], &["timestamp", "actual_q", "runtime_state", "output_int_register_3"], &[]);
    let q0 = v6(&c.latest_after(Duration::from_millis(50))[1]);
    let log_after = |serve: &ServeHandle, from: usize| -> Vec<String> {
        serve.state.lock().unwrap().program_log.iter().skip(from).cloned().collect()
    };
    for (program, line, what, within_ms) in [
        // An unsupported builtin after a statement that ran.
        (
            "def bad():\n  textmsg(\"started\")\n  sync()\n  force_mode(p[0,0,0,0,0,0], [0,0,1,0,0,0], [0,0,5,0,0,0], 2, [0.1,0.1,0.1,0.1,0.1,0.1])\nend\n",
            "line 4",
            "force_mode",
            100,
        ),
        // An endless loop without sync(): preempted each frame, then (after 1 s of it) a runtime
        // error, never a hung twin.
        ("def spin():\n  x = 0\n  while True:\n    x = x + 1\n  end\nend\n", "line 4", "endless loop", 1500),
        // A syntax error: the program does not start.
        ("def broken():\n  x = (1 +\n  y = 2\nend\n", "line 3", "syntax error", 100),
    ] {
        let seen = serve.state.lock().unwrap().program_log.len();
        upload(&serve, program);
        let s = c.latest_after(Duration::from_millis(within_ms));
        assert_eq!(int(&s[2]), 1, "{program}: stopped");
        let log = log_after(&serve, seen);
        assert!(log.iter().any(|l| l.contains(line) && l.contains(what)), "{program}: {log:?}");
        assert!(serve.running());
        let q = v6(&s[1]);
        assert!((0..6).all(|j| (q[j] - q0[j]).abs() < 1e-6), "the arm did not move: {q:?}");
    }
    // The next program runs: it writes a register and moves the base joint 0.05 rad.
    let target: Vec<String> = (0..6).map(|j| format!("{}", q0[j] + if j == 0 { 0.05 } else { 0.0 })).collect();
    let good = format!(
        "def good():\n  write_output_integer_register(3, 42)\n  movej([{}], a=1, v=0.5)\n  textmsg(\"there\")\n  while True:\n    sync()\n  end\nend\n",
        target.join(", ")
    );
    upload(&serve, &good);
    let s = c.latest_after(Duration::from_millis(600));
    assert_eq!((int(&s[2]), int(&s[3])), (2, 42), "playing, the register written");
    assert!((v6(&s[1])[0] - (q0[0] + 0.05)).abs() < 1e-3, "moved: {:?}", v6(&s[1]));
    assert!(serve.state.lock().unwrap().program_log.iter().any(|l| l == "there"));
    serve.stop().unwrap();
}
