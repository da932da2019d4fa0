//! The constructs UR's external control program is made of, in programs of our own, against an
//! in-memory network: sockets opened back to a "driver", reads that block while other threads go
//! on, threads with critical sections, the controller settings, and the refusals.

use super::interp::CONTROL_PERIOD_S;
use super::value::Value;
use super::*;
use std::collections::{HashMap, VecDeque};

/// A socket of the in-memory network: what the driver sent and what the program sent.
#[derive(Default)]
struct Link {
    state: Option<SocketState>,
    to_program: VecDeque<u8>,
    from_program: Vec<u8>,
}

/// A controller with an in-memory network: sockets to 127.0.0.1 connect at the next cycle,
/// anything else is refused; the arm is where it was last commanded.
#[derive(Default)]
struct Net {
    links: HashMap<String, Link>,
    opened: Vec<(String, String, u16)>,
    q: [f64; 6],
    force: [f64; 6],
    log: Vec<String>,
}

impl Controller for Net {
    fn input_int(&self, _: usize) -> i32 {
        0
    }
    fn input_float(&self, _: usize) -> f64 {
        0.0
    }
    fn input_bool(&self, _: usize) -> bool {
        false
    }
    fn set_output_int(&mut self, _: usize, _: i32) {}
    fn set_output_float(&mut self, _: usize, _: f64) {}
    fn set_output_bool(&mut self, _: usize, _: bool) {}
    fn set_digital_out(&mut self, _: DigitalOut, _: usize, _: bool) {}
    fn set_analog_out(&mut self, _: usize, _: f64) {}
    fn actual_q(&self) -> [f64; 6] {
        self.q
    }
    fn actual_qd(&self) -> [f64; 6] {
        [0.0; 6]
    }
    fn actual_tcp_force(&self) -> [f64; 6] {
        self.force
    }
    fn input_packages(&self) -> u64 {
        0
    }
    fn set_watchdog(&mut self, _: RtdeWatchdog) {}
    fn message(&mut self, text: &str) {
        self.log.push(text.to_string());
    }
    fn socket_open(&mut self, name: &str, host: &str, port: u16) -> Result<(), String> {
        if host != "127.0.0.1" {
            return Err(format!("{host} is not an allowed host"));
        }
        self.opened.push((name.into(), host.into(), port));
        self.links.insert(name.into(), Link { state: Some(SocketState::Connecting), ..Link::default() });
        Ok(())
    }
    fn socket_state(&self, name: &str) -> SocketState {
        self.links.get(name).and_then(|l| l.state.clone()).unwrap_or(SocketState::Closed)
    }
    fn socket_read(&mut self, name: &str, n: usize) -> Option<Vec<u8>> {
        let link = self.links.get_mut(name)?;
        (link.to_program.len() >= n).then(|| link.to_program.drain(..n).collect())
    }
    fn socket_send(&mut self, name: &str, bytes: &[u8]) -> bool {
        match self.links.get_mut(name) {
            Some(l) if l.state == Some(SocketState::Open) => {
                l.from_program.extend_from_slice(bytes);
                true
            }
            _ => false,
        }
    }
    fn socket_close(&mut self, name: &str) {
        self.links.remove(name);
    }
}

impl Net {
    /// The network's side of a cycle: pending connections are made.
    fn connect_pending(&mut self) {
        for l in self.links.values_mut() {
            if l.state == Some(SocketState::Connecting) {
                l.state = Some(SocketState::Open);
            }
        }
    }

    /// The driver sends big-endian 32-bit integers on socket `name`.
    fn send_ints(&mut self, name: &str, values: &[i32]) {
        let link = self.links.get_mut(name).expect("socket open");
        for v in values {
            link.to_program.extend(v.to_be_bytes());
        }
    }
}

/// Runs cycles `from..from + n`, the network connecting between them; returns the arm commands.
fn run(p: &mut Interpreter, net: &mut Net, from: usize, n: usize) -> Vec<(usize, [f64; 6])> {
    let mut out = Vec::new();
    for k in from..from + n {
        if let Some(q) = p.step(k as f64 * CONTROL_PERIOD_S, net) {
            net.q = q;
            out.push((k, q));
        }
        net.connect_pending();
    }
    out
}

/// The reverse-interface pattern: the program connects back, a servo thread commands the arm
/// every cycle, the main loop reads 8-integer messages in a critical section with the timeout
/// each message sets (the first read blocking), and a command thread blocks on another socket
/// for good; results go back as big-endian integers.
const REVERSE: &str = "def reverse():
  MULT = 1000000
  global cmd_q = get_joint_positions()
  global mode = -1
  global commands = 0
  thread servo():
    while mode == 1:
      enter_critical
      q = cmd_q
      servoj(q, t=0.002, lookahead_time=0.03, gain=2000)
      exit_critical
    end
    stopj(4)
  end
  thread listen():
    while mode > -2:
      c = socket_read_binary_integer(2, \"command_socket\", 0)
      if c[0] > 0:
        commands = commands + 1
        socket_send_int(c[1] + c[2], \"command_socket\")
      end
    end
  end
  ok = socket_open(\"127.0.0.1\", 50004, \"command_socket\") and socket_open(\"127.0.0.1\", 50001, \"reverse_socket\")
  if not ok:
    halt
  end
  listener = run listen()
  mover = 0
  join mover
  timeout = 0
  while mode > -2:
    enter_critical
    m = socket_read_binary_integer(8, \"reverse_socket\", timeout)
    if m[0] > 0:
      timeout = m[1] / 1000.0
      if mode != m[8]:
        mode = m[8]
        if mode == 1:
          mover = run servo()
        end
      end
      if mode == 1:
        cmd_q = [m[2] / MULT, m[3] / MULT, m[4] / MULT, m[5] / MULT, m[6] / MULT, m[7] / MULT]
      end
    else:
      textmsg(\"reverse socket timed out\")
      mode = -2
      kill mover
      kill listener
      stopj(4)
    end
    exit_critical
  end
  socket_close(\"reverse_socket\")
  socket_close(\"command_socket\")
end
";

/// A reverse-interface message: read timeout \[ms\], six values, the mode.
fn message(timeout_ms: i32, q: [f64; 6], mode: i32) -> Vec<i32> {
    let mut m = vec![timeout_ms];
    m.extend(q.map(|v| (v * 1e6).round() as i32));
    m.push(mode);
    m
}

#[test]
fn a_thread_blocked_on_a_socket_leaves_the_servo_thread_commanding_every_cycle() {
    let mut net = Net::default();
    let mut p = Interpreter::new(REVERSE, [0.0; 6]).unwrap();
    // Two sockets, connected one after the other (socket_open waits for each).
    run(&mut p, &mut net, 0, 6);
    assert_eq!(net.opened.len(), 2, "{:?}", net.opened);
    assert_eq!(net.opened[1], ("reverse_socket".into(), "127.0.0.1".into(), 50001));
    // Nothing sent yet: the first read blocks (timeout 0), and nothing moves, for as long as it
    // takes.
    assert!(run(&mut p, &mut net, 6, 500).is_empty());
    assert_eq!(p.status(), &Status::Running);
    // Servo targets on a ramp, one per cycle, each allowing 20 ms until the next.
    let mut commanded = Vec::new();
    for k in 0..200usize {
        let q = [0.0, 0.0, 0.0, 0.0, 0.0, 0.001 * k as f64];
        net.send_ints("reverse_socket", &message(20, q, 1));
        commanded.extend(run(&mut p, &mut net, 506 + k, 1));
    }
    // Every cycle a new setpoint, while `listen` sat blocked on its socket the whole time.
    assert!(commanded.len() >= 198, "{} setpoints in 200 cycles", commanded.len());
    let last = commanded.last().unwrap().1[5];
    assert!((last - 0.199).abs() < 2e-3, "{last}");
    // The command thread answers as soon as its message arrives, without the reverse loop's help.
    net.send_ints("command_socket", &[20, 22]);
    run(&mut p, &mut net, 706, 2);
    assert_eq!(net.links["command_socket"].from_program, 42i32.to_be_bytes());
    assert_eq!(p.global("commands"), Some(&Value::Int(1)));
    // The driver goes quiet: 20 ms later the read times out, the program stops its threads and
    // ends (its sockets closed).
    let quiet = run(&mut p, &mut net, 708, 30);
    assert!(net.log.iter().any(|l| l == "reverse socket timed out"), "{:?}", net.log);
    assert_eq!(p.status(), &Status::Finished);
    assert!(net.links.is_empty(), "sockets closed");
    assert!(quiet.len() < 30, "the arm came to rest");
}

#[test]
fn reads_time_out_with_the_manuals_failure_value_and_sends_are_big_endian() {
    let src = "def p():
  socket_open(\"127.0.0.1\", 3000)
  socket_send_int(-2)
  socket_send_byte(255)
  socket_send_line(\"hi\")
  global a = socket_read_binary_integer(3, \"socket_0\", 0.01)
  global b = socket_read_byte_list(2)
  global c = socket_read_binary_integer(1, \"no_such_socket\")
end
";
    let mut net = Net::default();
    let mut p = Interpreter::new(src, [0.0; 6]).unwrap();
    run(&mut p, &mut net, 0, 3);
    assert_eq!(net.links["socket_0"].from_program, [0xff, 0xff, 0xff, 0xfe, 0xff, b'h', b'i', b'\n']);
    // 10 ms with nothing: [0, -1, -1, -1].
    run(&mut p, &mut net, 3, 6);
    let failed = Value::List(vec![Value::Int(0), Value::Int(-1), Value::Int(-1), Value::Int(-1)]);
    assert_eq!(p.global("a"), Some(&failed));
    net.links.get_mut("socket_0").unwrap().to_program.extend([7, 9]);
    run(&mut p, &mut net, 9, 2);
    assert_eq!(p.global("b"), Some(&Value::List(vec![Value::Int(2), Value::Int(7), Value::Int(9)])));
    assert_eq!(p.global("c"), Some(&Value::List(vec![Value::Int(0), Value::Int(-1)])), "not open: at once");
    assert_eq!(p.status(), &Status::Finished);
}

#[test]
fn a_socket_to_a_host_not_allowed_stops_the_program_with_its_line_and_reason() {
    let src = "def p():\n  textmsg(\"start\")\n  socket_open(\"10.0.0.5\", 50001, \"reverse_socket\")\n  textmsg(\"never\")\nend\n";
    let mut net = Net::default();
    let mut p = Interpreter::new(src, [0.0; 6]).unwrap();
    run(&mut p, &mut net, 0, 3);
    match p.status() {
        Status::Failed(e) => assert!(e.line == 3 && e.message.contains("10.0.0.5 is not an allowed host"), "{e}"),
        other => panic!("{other:?}"),
    }
    // A controller without a network refuses every socket.
    let mut p = Interpreter::new(src, [0.0; 6]).unwrap();
    struct NoNet(Net);
    impl Controller for NoNet {
        fn input_int(&self, _: usize) -> i32 {
            0
        }
        fn input_float(&self, _: usize) -> f64 {
            0.0
        }
        fn input_bool(&self, _: usize) -> bool {
            false
        }
        fn set_output_int(&mut self, _: usize, _: i32) {}
        fn set_output_float(&mut self, _: usize, _: f64) {}
        fn set_output_bool(&mut self, _: usize, _: bool) {}
        fn set_digital_out(&mut self, _: DigitalOut, _: usize, _: bool) {}
        fn set_analog_out(&mut self, _: usize, _: f64) {}
        fn actual_q(&self) -> [f64; 6] {
            self.0.q
        }
        fn actual_qd(&self) -> [f64; 6] {
            [0.0; 6]
        }
        fn actual_tcp_force(&self) -> [f64; 6] {
            [0.0; 6]
        }
        fn input_packages(&self) -> u64 {
            0
        }
        fn set_watchdog(&mut self, _: RtdeWatchdog) {}
        fn message(&mut self, text: &str) {
            self.0.log.push(text.into());
        }
    }
    p.step(0.0, &mut NoNet(Net::default()));
    assert!(matches!(p.status(), Status::Failed(e) if e.message.contains("no network")));
}

#[test]
fn a_refused_connection_returns_false_and_the_program_goes_on() {
    let src = "def p():\n  global ok = socket_open(\"127.0.0.1\", 1, \"s\")\nend\n";
    let mut net = Net::default();
    let mut p = Interpreter::new(src, [0.0; 6]).unwrap();
    p.step(0.0, &mut net);
    net.links.get_mut("s").unwrap().state = Some(SocketState::Failed("connection refused".into()));
    p.step(0.002, &mut net);
    assert_eq!(p.global("ok"), Some(&Value::Bool(false)));
    assert_eq!(p.status(), &Status::Finished);
    assert!(net.log[0].contains("connection refused"), "{:?}", net.log);
}

#[test]
fn controller_settings_are_kept_and_checked() {
    let src = "def p():
  set_tcp(p[0, 0, 0.1, 0, 0, 0])
  set_payload(1.5, [0, 0, 0.05])
  set_target_payload(2.0, [0, 0, 0.1], [0.003, 0.003, 0.003, 0, 0, 0], 0.5)
  set_gravity([0, 0, 9.81])
  set_tool_voltage(24)
  zero_ftsensor()
  global f = get_tcp_force()
  global pose = get_actual_tcp_pose()
  global flange = get_forward_kin(get_actual_joint_positions(), p[0, 0, 0, 0, 0, 0])
end
";
    let mut net = Net { q: tendril_ur5e::kinematics::HOME, force: [1.0, 2.0, -3.0, 0.0, 0.0, 0.0], ..Net::default() };
    let mut p = Interpreter::new(src, net.q).unwrap();
    run(&mut p, &mut net, 0, 1);
    assert_eq!(p.status(), &Status::Finished);
    let s = p.setup();
    assert_eq!(s.tcp, [0.0, 0.0, 0.1, 0.0, 0.0, 0.0]);
    assert_eq!((s.payload_kg, s.payload_cog, s.payload_inertia[0]), (2.0, [0.0, 0.0, 0.1], 0.003));
    assert_eq!((s.gravity, s.tool_voltage), ([0.0, 0.0, 9.81], 24));
    assert_eq!(p.global("f"), Some(&Value::Pose([0.0; 6])), "zeroed");
    // The TCP pose is 0.1 m along the flange's z, which points down at home.
    let (Some(Value::Pose(tcp)), Some(Value::Pose(flange))) = (p.global("pose"), p.global("flange")) else { panic!() };
    assert!((tcp[2] - (flange[2] - 0.1)).abs() < 1e-9, "{tcp:?} {flange:?}");
    for (bad, what) in [
        ("set_tool_voltage(5)", "0, 12 or 24"),
        ("set_payload(50, [0, 0, 0])", "mass"),
        ("set_gravity([0, 9.81])", "3 numbers"),
    ] {
        let mut p = Interpreter::new(&format!("def p():\n  {bad}\nend\n"), [0.0; 6]).unwrap();
        run(&mut p, &mut Net::default(), 0, 1);
        assert!(matches!(p.status(), Status::Failed(e) if e.message.contains(what)), "{bad}: {:?}", p.status());
    }
}

#[test]
fn force_mode_is_refused_freedrive_holds_the_arm_and_tool_contact_reads_the_wrist() {
    let refused =
        "def p():\n  force_mode(p[0,0,0,0,0,0], [0,0,1,0,0,0], [0,0,-2,0,0,0], 2, [0.1,0.1,1.5,3.14,3.14,0.5])\nend\n";
    let mut p = Interpreter::new(refused, [0.0; 6]).unwrap();
    run(&mut p, &mut Net::default(), 0, 1);
    assert!(matches!(p.status(), Status::Failed(e) if e.line == 2 && e.message.contains("no force control")));

    let src = "def p():
  freedrive_mode()
  global in_freedrive = True
  sleep(0.1)
  end_freedrive_mode()
  global early = tool_contact(direction=[0, 0, -0.02, 0, 0, 0])
  sleep(0.1)
  global steps = tool_contact(direction=[0, 0, -0.02, 0, 0, 0])
end
";
    let mut net = Net { q: tendril_ur5e::kinematics::HOME, ..Net::default() };
    let mut p = Interpreter::new(src, net.q).unwrap();
    assert!(run(&mut p, &mut net, 0, 10).is_empty(), "nobody pushes the arm: it stays");
    assert!(p.setup().freedrive);
    // The tool meets something while moving down: the wrist feels 8 N upwards from cycle 45 on,
    // its noise (±1.75 N here) on top.
    for k in 10..110 {
        let noise = if k % 2 == 0 { 1.75 } else { -1.75 };
        net.force = [0.0, 0.0, noise + if k >= 45 { 8.0 } else { 0.0 }, 0.0, 0.0, 0.0];
        run(&mut p, &mut net, k, 1);
    }
    assert!(!p.setup().freedrive);
    assert_eq!(p.global("early"), Some(&Value::Int(0)), "6 cycles of contact do not make the 50 ms mean");
    // Called at cycle 101, 57 cycles into the contact: the pose it names is before cycle 45.
    let Some(Value::Int(steps)) = p.global("steps") else { panic!() };
    assert!((57..=57 + 25 + 3).contains(steps), "{steps}");
}

#[test]
fn a_secondary_program_runs_at_once_and_may_not_move_the_arm() {
    let mut p = Interpreter::new("sec s():\n  textmsg(\"from sec\")\nend\n", [0.0; 6]).unwrap();
    assert!(p.is_secondary() && p.name() == "s");
    let mut net = Net::default();
    run(&mut p, &mut net, 0, 1);
    assert_eq!((p.status(), net.log[0].as_str()), (&Status::Finished, "from sec"));
    let mut p = Interpreter::new("sec s():\n  movej([0,0,0,0,0,0])\nend\n", [0.0; 6]).unwrap();
    run(&mut p, &mut net, 0, 1);
    assert!(matches!(p.status(), Status::Failed(e) if e.message.contains("secondary program")));
}

#[test]
fn movep_movec_and_speedl_move_the_tcp_along_their_paths() {
    let home = tendril_ur5e::kinematics::HOME;
    let start = tendril_ur5e::pose::tcp_pose(&home, &[0.0; 6]);
    let tcp = |q: &[f64; 6]| tendril_ur5e::pose::tcp_pose(q, &[0.0; 6]);
    // movec through a point 5 cm across and 5 cm down-across: a quarter... of a circle in xz.
    let (x, z) = (start[0], start[2]);
    let src = format!(
        "def p():
  movec(p[{}, {}, {}, {}, {}, {}], p[{}, {}, {}, {}, {}, {}], a=1.2, v=0.1)
  speedl([0, 0, -0.05, 0, 0, 0], 0.5, 0.2)
end
",
        x + 0.05,
        start[1],
        z - 0.05,
        start[3],
        start[4],
        start[5],
        x + 0.1,
        start[1],
        z,
        start[3],
        start[4],
        start[5]
    );
    let mut net = Net { q: home, ..Net::default() };
    let mut p = Interpreter::new(&src, home).unwrap();
    let path = run(&mut p, &mut net, 0, 2000);
    assert_eq!(p.status(), &Status::Finished);
    // Along the arc the TCP stays 5 cm from the circle's centre (x + 0.05, z).
    let arc: Vec<_> = path.iter().map(|(_, q)| tcp(q)).filter(|p| (p[2] - z).abs() > 1e-4 || p[0] > x + 0.09).collect();
    for p in arc.iter().take_while(|p| p[0] < x + 0.1 - 1e-6) {
        let r = ((p[0] - x - 0.05).powi(2) + (p[2] - z).powi(2)).sqrt();
        assert!((r - 0.05).abs() < 2e-4 && (p[1] - start[1]).abs() < 2e-4, "{p:?}: r {r}");
    }
    // Then speedl: 0.2 s at up to 5 cm/s down (ramped at 0.5 m/s², then stopping at it).
    let end = tcp(&net.q);
    assert!((end[0] - (x + 0.1)).abs() < 1e-3, "{end:?}");
    let fell = z - end[2];
    assert!(fell > 0.005 && fell < 0.012, "{fell}");
}
