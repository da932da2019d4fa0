//! The built-in functions the virtual controller implements (URScript manual names, parameters
//! and defaults). Anything else is a runtime error naming the function, as a controller rejects a
//! program calling an unknown function. The list is in `docs/cell/urscript.md`.

use super::call::{Args, Cx, JOINT_HISTORY_CYCLES, Outcome};
use super::controller::DigitalOut;
use super::motion::{Arm, KILL_DECEL_RAD_S2};
use super::setup;
use super::value::Value;
use crate::watchdog::{RtdeWatchdog, WatchdogAction};
use tendril_rtde::fields::REGISTER_COUNT;
use tendril_ur5e::pose::{pose_from_vector, pose_vector, tcp_pose, tcp_speed};

/// The force the tool must meet against its motion before `tool_contact` reports a contact \[N\],
/// averaged over [`TOOL_CONTACT_WINDOW`] cycles. UR does not publish its detector (it compares
/// expected and measured joint currents); ours compares the wrist sensor's force with the
/// direction the TCP moves. 5 N: a firm touch, below a UR5e's default protective-stop force
/// (150 N); averaged over 25 readings the twin's wrist noise (1.75 N a reading, `[wrist]`) is
/// 0.35 N, so noise alone never reaches it (14 standard deviations).
pub const TOOL_CONTACT_FORCE_N: f64 = 5.0;
/// Cycles the wrist force is averaged over for `tool_contact` (50 ms).
pub const TOOL_CONTACT_WINDOW: usize = 25;

fn float(v: f64) -> Value {
    Value::Float(v)
}

fn positive(name: &str, what: &str, v: f64) -> Result<f64, String> {
    if v.is_finite() && v > 0.0 { Ok(v) } else { Err(format!("{name}: `{what}` must be positive, got {v}")) }
}

fn duration(name: &str, t: f64) -> Result<f64, String> {
    if t.is_finite() && t >= 0.0 { Ok(t) } else { Err(format!("{name}: `t` must be a non-negative time, got {t}")) }
}

fn finite6(name: &str, v: [f64; 6]) -> Result<[f64; 6], String> {
    if v.iter().all(|x| x.is_finite()) { Ok(v) } else { Err(format!("{name}: {v:?} is not finite")) }
}

/// Joint angles for a `movej`/`servoj` target given as joints or as a pose (a pose is solved
/// near the current setpoint, as `get_inverse_kin` does). Joint targets are not checked here:
/// a non-finite or out-of-range one reaches the safety check and ends in a protective stop, as on
/// the controller.
fn joints_of(name: &str, v: &Value, arm: &Arm, near: &[f64; 6]) -> Result<[f64; 6], String> {
    match v {
        Value::Pose(p) => arm
            .joints_for(&pose_from_vector(&finite6(name, *p)?), near)
            .ok_or_else(|| format!("{name}: no joint solution for {v}")),
        other => other.six(&format!("{name}'s target")),
    }
}

/// A TCP pose given as a pose, or as joints whose TCP it is (`movel(q)`, `movec` via joints).
fn pose_of(name: &str, v: &Value, arm: &Arm) -> Result<[f64; 6], String> {
    match v {
        Value::Pose(p) => finite6(name, *p),
        other => Ok(pose_vector(&arm.tcp_at(&finite6(name, other.six(&format!("{name}'s target"))?)?))),
    }
}

/// Builtins that consume time or move the arm: a secondary program may not call them.
const TIMED: [&str; 18] = [
    "sync",
    "sleep",
    "movej",
    "movel",
    "movep",
    "movec",
    "servoj",
    "speedj",
    "speedl",
    "stopj",
    "stopl",
    "socket_open",
    "socket_read_binary_integer",
    "socket_read_byte_list",
    "freedrive_mode",
    "end_freedrive_mode",
    "force_mode",
    "tool_contact",
];

/// Calls built-in `name`.
pub fn call(name: &str, pos: &[Value], kw: &[(String, Value)], cx: &mut Cx<'_>) -> Result<Outcome, String> {
    let a = Args::new(name, pos, kw);
    if cx.secondary && TIMED.contains(&name) {
        return Err(format!("`{name}` consumes time or moves the arm: a secondary program may not call it"));
    }
    if let Some(outcome) = super::sockets::call(&a, cx) {
        return outcome;
    }
    use Outcome::Value as V;
    let math1 = |f: fn(f64) -> f64| -> Result<Outcome, String> {
        a.check(&["f"])?;
        let x = a.num(0, "f")?;
        let y = f(x);
        if y.is_nan() && !x.is_nan() {
            return Err(format!("{name}({x}) is undefined"));
        }
        Ok(V(float(y)))
    };
    match name {
        // --- Time ---
        "sync" => {
            a.check(&[])?;
            Ok(Outcome::Sleep(Value::Void, cx.period))
        }
        "sleep" => {
            a.check(&["t"])?;
            let t = a.num(0, "t")?;
            if !(t.is_finite() && t >= 0.0) {
                return Err(format!("sleep: t must be non-negative, got {t}"));
            }
            Ok(Outcome::Sleep(Value::Void, t))
        }
        "get_steptime" => {
            a.check(&[])?;
            Ok(V(float(cx.period)))
        }
        // --- Motion ---
        "movej" => {
            a.check(&["q", "a", "v", "t", "r"])?;
            let target = joints_of(name, a.value(0, "q")?, cx.arm, &cx.arm.target_q())?;
            let acc = positive(name, "a", a.num_or(1, "a", 1.4)?)?;
            let vel = positive(name, "v", a.num_or(2, "v", 1.05)?)?;
            let t = duration(name, a.num_or(3, "t", 0.0)?)?;
            Ok(Outcome::Move(Value::Void, cx.arm.movej(target, acc, vel, t, cx.thread)))
        }
        "movel" | "movep" => {
            // Blends (`r`) are not modelled: each move ends at rest on its target.
            let params: &[&str] =
                if name == "movel" { &["pose", "a", "v", "t", "r"] } else { &["pose", "a", "v", "r"] };
            a.check(params)?;
            let target = pose_of(name, a.value(0, "pose")?, cx.arm)?;
            let acc = positive(name, "a", a.num_or(1, "a", 1.2)?)?;
            let vel = positive(name, "v", a.num_or(2, "v", 0.25)?)?;
            let t = if name == "movel" { duration(name, a.num_or(3, "t", 0.0)?)? } else { 0.0 };
            Ok(Outcome::Move(Value::Void, cx.arm.movel(target, acc, vel, t, cx.thread)?))
        }
        "movec" => {
            a.check(&["pose_via", "pose_to", "a", "v", "r", "mode"])?;
            let via = pose_of(name, a.value(0, "pose_via")?, cx.arm)?;
            let to = pose_of(name, a.value(1, "pose_to")?, cx.arm)?;
            let acc = positive(name, "a", a.num_or(2, "a", 1.2)?)?;
            let vel = positive(name, "v", a.num_or(3, "v", 0.25)?)?;
            let fixed = match a.num_or(5, "mode", 0.0)? {
                0.0 => false,
                1.0 => true,
                m => return Err(format!("movec: mode must be 0 (unconstrained) or 1 (fixed), got {m}")),
            };
            Ok(Outcome::Move(Value::Void, cx.arm.movec(via, to, acc, vel, fixed, cx.thread)?))
        }
        "speedl" => {
            a.check(&["xd", "a", "t", "aRot"])?;
            let xd = finite6(name, a.six(0, "xd")?)?;
            let acc = positive(name, "a", a.num(1, "a")?)?;
            let t = a.num_or(2, "t", cx.period)?.max(cx.period);
            let a_rot = positive(name, "aRot", a.num_or(3, "aRot", acc)?)?;
            cx.arm.speedl(xd, acc, a_rot, cx.now + t, cx.thread);
            Ok(Outcome::Sleep(Value::Void, t))
        }
        "servoj" => {
            a.check(&["q", "a", "v", "t", "lookahead_time", "gain"])?;
            let q = joints_of(name, a.value(0, "q")?, cx.arm, &cx.arm.target_q())?;
            let t = a.num_or(3, "t", 0.002)?;
            if !(t.is_finite() && t >= 0.0) {
                return Err(format!("servoj: t must be non-negative, got {t}"));
            }
            cx.arm.servoj(q, cx.host.input_packages(), cx.thread);
            Ok(Outcome::Sleep(Value::Void, t))
        }
        "speedj" => {
            a.check(&["qd", "a", "t"])?;
            let qd = finite6(name, a.six(0, "qd")?)?;
            let acc = positive(name, "a", a.num(1, "a")?)?;
            // Without t the call returns after one cycle (the speed is kept while renewed).
            let t = a.num_or(2, "t", cx.period)?.max(cx.period);
            cx.arm.speedj(qd, acc, cx.now + t, cx.thread);
            Ok(Outcome::Sleep(Value::Void, t))
        }
        "stopj" => {
            a.check(&["a"])?;
            let decel = positive(name, "a", a.num(0, "a")?)?;
            Ok(Outcome::Move(Value::Void, cx.arm.stopj(decel, cx.thread)))
        }
        "stopl" => {
            a.check(&["a", "aRot"])?;
            let decel = positive(name, "a", a.num(0, "a")?)? / super::motion::STOPL_LEVER_M;
            Ok(Outcome::Move(Value::Void, cx.arm.stopj(decel, cx.thread)))
        }
        // --- Robot state ---
        // `get_joint_positions` is the manual's older name of the measured joints.
        "get_actual_joint_positions" | "get_joint_positions" => {
            a.check(&[])?;
            Ok(V(Value::list6(cx.host.actual_q())))
        }
        "get_actual_joint_speeds" => {
            a.check(&[])?;
            Ok(V(Value::list6(cx.host.actual_qd())))
        }
        "get_actual_joint_positions_history" => {
            a.check(&["steps"])?;
            let steps = a.num_or(0, "steps", 0.0)?;
            let k = steps as usize;
            if steps.fract() != 0.0 || steps < 0.0 || k >= JOINT_HISTORY_CYCLES {
                return Err(format!("{name}: steps must be an integer in 0..{}, got {steps}", JOINT_HISTORY_CYCLES));
            }
            let q = cx.history.get(k).or(cx.history.back()).map_or_else(|| cx.host.actual_q(), |m| m.q);
            Ok(V(Value::list6(q)))
        }
        "get_actual_tcp_speed" => {
            a.check(&[])?;
            Ok(V(Value::Pose(tcp_speed(&cx.host.actual_q(), &cx.host.actual_qd(), &cx.setup.tcp))))
        }
        "get_target_tcp_speed" => {
            a.check(&[])?;
            Ok(V(Value::Pose(tcp_speed(&cx.arm.target_q(), &cx.arm.target_qd(), &cx.setup.tcp))))
        }
        "get_tcp_force" => {
            a.check(&[])?;
            let f = cx.host.actual_tcp_force();
            Ok(V(Value::Pose(std::array::from_fn(|k| f[k] - cx.setup.ft_zero[k]))))
        }
        "get_tcp_offset" => {
            a.check(&[])?;
            Ok(V(Value::Pose(cx.setup.tcp)))
        }
        "get_target_joint_positions" => {
            a.check(&[])?;
            Ok(V(Value::list6(cx.arm.target_q())))
        }
        "get_target_joint_speeds" => {
            a.check(&[])?;
            Ok(V(Value::list6(cx.arm.target_qd())))
        }
        "get_actual_tcp_pose" => {
            a.check(&[])?;
            Ok(V(Value::Pose(tcp_pose(&cx.host.actual_q(), &cx.setup.tcp))))
        }
        "get_target_tcp_pose" => {
            a.check(&[])?;
            Ok(V(Value::Pose(tcp_pose(&cx.arm.target_q(), &cx.setup.tcp))))
        }
        "get_forward_kin" => {
            a.check(&["q", "tcp"])?;
            let q = match a.get(0, "q") {
                Some(v) => finite6(name, v.six("get_forward_kin's q")?)?,
                None => cx.host.actual_q(),
            };
            let tcp = match a.get(1, "tcp") {
                Some(v) => v.six("get_forward_kin's tcp")?,
                None => cx.setup.tcp,
            };
            Ok(V(Value::Pose(tcp_pose(&q, &tcp))))
        }
        "get_inverse_kin" => {
            a.check(&["x", "qnear", "maxPositionError", "maxOrientationError", "tcp"])?;
            let x = finite6(name, a.six(0, "x")?)?;
            let near = match a.get(1, "qnear") {
                Some(v) => finite6(name, v.six("get_inverse_kin's qnear")?)?,
                None => cx.host.actual_q(),
            };
            cx.arm
                .joints_for(&pose_from_vector(&x), &near)
                .map(|q| V(Value::list6(q)))
                .ok_or_else(|| format!("get_inverse_kin: no solution for p{x:?}"))
        }
        "get_inverse_kin_has_solution" => {
            a.check(&["pose", "qnear", "maxPositionError", "maxOrientationError", "tcp"])?;
            let x = finite6(name, a.six(0, "pose")?)?;
            let near = match a.get(1, "qnear") {
                Some(v) => v.six("qnear")?,
                None => cx.host.actual_q(),
            };
            Ok(V(Value::Bool(cx.arm.joints_for(&pose_from_vector(&x), &near).is_some())))
        }
        // --- RTDE registers ---
        "read_input_integer_register" => {
            a.check(&["address"])?;
            Ok(V(Value::Int(cx.host.input_int(a.index(0, "address", REGISTER_COUNT)?).into())))
        }
        "read_input_float_register" => {
            a.check(&["address"])?;
            Ok(V(float(cx.host.input_float(a.index(0, "address", REGISTER_COUNT)?))))
        }
        "read_input_boolean_register" => {
            a.check(&["address"])?;
            Ok(V(Value::Bool(cx.host.input_bool(a.index(0, "address", 128)?))))
        }
        "write_output_integer_register" => {
            a.check(&["address", "value"])?;
            let i = a.index(0, "address", REGISTER_COUNT)?;
            let v = a.num(1, "value")?;
            if v.fract() != 0.0 || v < f64::from(i32::MIN) || v > f64::from(i32::MAX) {
                return Err(format!("{name}: {v} is not a 32-bit integer"));
            }
            cx.host.set_output_int(i, v as i32);
            Ok(V(Value::Void))
        }
        "write_output_float_register" => {
            a.check(&["address", "value"])?;
            let i = a.index(0, "address", REGISTER_COUNT)?;
            cx.host.set_output_float(i, a.num(1, "value")?);
            Ok(V(Value::Void))
        }
        "write_output_boolean_register" => {
            a.check(&["address", "value"])?;
            let i = a.index(0, "address", 128)?;
            cx.host.set_output_bool(i, a.boolean(1, "value")?);
            Ok(V(Value::Void))
        }
        "rtde_set_watchdog" => {
            a.check(&["variable_name", "min_frequency", "action"])?;
            let variable = match a.value(0, "variable_name")? {
                Value::Str(s) => s.clone(),
                other => return Err(format!("{name}: variable_name must be a string, got {}", other.describe())),
            };
            let min_frequency_hz = positive(name, "min_frequency", a.num(1, "min_frequency")?)?;
            let action = match a.get(2, "action") {
                None => WatchdogAction::Pause,
                Some(Value::Str(s)) => match s.to_ascii_lowercase().as_str() {
                    "ignore" => WatchdogAction::Ignore,
                    "pause" => WatchdogAction::Pause,
                    "stop" => WatchdogAction::Stop,
                    _ => return Err(format!("{name}: action must be \"ignore\", \"pause\" or \"stop\", got {s:?}")),
                },
                Some(other) => return Err(format!("{name}: action must be a string, got {}", other.describe())),
            };
            cx.host.set_watchdog(RtdeWatchdog { variable, min_frequency_hz, action });
            Ok(V(Value::Void))
        }
        // --- IO ---
        "set_standard_digital_out" | "set_configurable_digital_out" | "set_tool_digital_out" => {
            a.check(&["n", "b"])?;
            let (kind, count) = match name {
                "set_standard_digital_out" => (DigitalOut::Standard, 8),
                "set_configurable_digital_out" => (DigitalOut::Configurable, 8),
                _ => (DigitalOut::Tool, 2),
            };
            let n = a.index(0, "n", count)?;
            cx.host.set_digital_out(kind, n, a.boolean(1, "b")?);
            Ok(V(Value::Void))
        }
        "set_standard_analog_out" => {
            a.check(&["n", "f"])?;
            let n = a.index(0, "n", 2)?;
            let f = a.num(1, "f")?;
            if !(0.0..=1.0).contains(&f) {
                return Err(format!("{name}: f must be in [0, 1], got {f}"));
            }
            cx.host.set_analog_out(n, f);
            Ok(V(Value::Void))
        }
        // --- Force mode parameters: accepted (SDU ur_rtde's control script sets them at start);
        // force mode itself is not supported. ---
        "force_mode_set_gain_scaling" | "force_mode_set_damping" => {
            a.check(&["v"])?;
            let v = a.num(0, "v")?;
            let max = if name == "force_mode_set_damping" { 1.0 } else { 2.0 };
            if !(0.0..=max).contains(&v) {
                return Err(format!("{name}: {v} is not in [0, {max}]"));
            }
            Ok(V(Value::Void))
        }
        // --- Controller settings (`Setup`) ---
        "set_tcp" => {
            a.check(&["pose"])?;
            let tcp = finite6(name, a.six(0, "pose")?)?;
            cx.setup.tcp = tcp;
            cx.arm.set_tcp(&tcp);
            Ok(V(Value::Void))
        }
        "set_payload" => {
            a.check(&["m", "cog"])?;
            cx.setup.payload_kg = setup::payload_mass(name, a.num(0, "m")?)?;
            if let Some(cog) = a.get(1, "cog") {
                cx.setup.payload_cog = setup::three(name, "cog", cog)?;
            }
            Ok(V(Value::Void))
        }
        "set_payload_mass" => {
            a.check(&["m"])?;
            cx.setup.payload_kg = setup::payload_mass(name, a.num(0, "m")?)?;
            Ok(V(Value::Void))
        }
        "set_payload_cog" => {
            a.check(&["CoG"])?;
            cx.setup.payload_cog = setup::three(name, "CoG", a.value(0, "CoG")?)?;
            Ok(V(Value::Void))
        }
        "set_target_payload" => {
            a.check(&["mass", "cog", "inertia", "transition_time"])?;
            cx.setup.payload_kg = setup::payload_mass(name, a.num(0, "mass")?)?;
            cx.setup.payload_cog = setup::three(name, "cog", a.value(1, "cog")?)?;
            if let Some(i) = a.get(2, "inertia") {
                cx.setup.payload_inertia = finite6(name, i.six("set_target_payload's inertia")?)?;
            }
            // The transition time smooths the change on the controller; the twin's physics does
            // not read the payload, so it has nothing to smooth.
            duration(name, a.num_or(3, "transition_time", 0.0)?)?;
            Ok(V(Value::Void))
        }
        "set_gravity" => {
            a.check(&["d"])?;
            cx.setup.gravity = setup::three(name, "d", a.value(0, "d")?)?;
            Ok(V(Value::Void))
        }
        "set_tool_voltage" => {
            a.check(&["voltage"])?;
            let v = a.num(0, "voltage")?;
            if ![0.0, 12.0, 24.0].contains(&v) {
                return Err(format!("{name}: voltage must be 0, 12 or 24, got {v}"));
            }
            cx.setup.tool_voltage = v as i32;
            Ok(V(Value::Void))
        }
        "zero_ftsensor" => {
            a.check(&[])?;
            cx.setup.ft_zero = cx.host.actual_tcp_force();
            Ok(V(Value::Void))
        }
        "freedrive_mode" => {
            // Nobody pushes the twin's arm, so in freedrive it stays where it is, as a real arm in
            // freedrive does when nobody touches it; the program goes on (the mode is reported).
            a.check(&["freeAxes", "feature"])?;
            cx.setup.freedrive = true;
            Ok(Outcome::Move(Value::Void, cx.arm.stopj(KILL_DECEL_RAD_S2, cx.thread)))
        }
        "end_freedrive_mode" => {
            a.check(&[])?;
            cx.setup.freedrive = false;
            Ok(V(Value::Void))
        }
        "force_mode" => Err("force_mode is not supported by the virtual controller: the twin's arm follows position \
             setpoints and has no force control loop to comply with a wrench"
            .into()),
        // Nothing to end: force mode never starts here (the controller accepts the call then too).
        "end_force_mode" => {
            a.check(&[])?;
            Ok(V(Value::Void))
        }
        "tool_contact" => {
            a.check(&["direction"])?;
            let d = finite6(name, a.six(0, "direction")?)?;
            Ok(V(Value::Int(tool_contact_steps(cx, &d))))
        }
        // --- Messages ---
        "textmsg" => {
            a.check(&["s1", "s2"])?;
            let s2 = a.get(1, "s2").map(ToString::to_string).unwrap_or_default();
            cx.host.message(&format!("{}{s2}", a.value(0, "s1")?));
            Ok(V(Value::Void))
        }
        "popup" => {
            // Logged; a blocking popup does not wait for a user the virtual controller has not.
            a.check(&["s", "title", "warning", "error", "blocking"])?;
            cx.host.message(&format!("popup: {}", a.value(0, "s")?));
            Ok(V(Value::Void))
        }
        // --- Math and conversions ---
        "sqrt" => math1(f64::sqrt),
        "sin" => math1(f64::sin),
        "cos" => math1(f64::cos),
        "tan" => math1(f64::tan),
        "asin" => math1(f64::asin),
        "acos" => math1(f64::acos),
        "atan" => math1(f64::atan),
        "fabs" => math1(f64::abs),
        "log" => math1(f64::ln),
        "d2r" => math1(f64::to_radians),
        "r2d" => math1(f64::to_degrees),
        "floor" | "ceil" | "round" => {
            a.check(&["f"])?;
            let x = a.num(0, "f")?;
            let y = match name {
                "floor" => x.floor(),
                "ceil" => x.ceil(),
                _ => x.round(),
            };
            if !y.is_finite() || y.abs() > 9.0e15 {
                return Err(format!("{name}({x}) is not an integer"));
            }
            Ok(V(Value::Int(y as i64)))
        }
        "atan2" | "pow" => {
            a.check(&["x", "y"])?;
            let (x, y) = (a.num(0, "x")?, a.num(1, "y")?);
            Ok(V(float(if name == "atan2" { x.atan2(y) } else { x.powf(y) })))
        }
        "norm" => {
            a.check(&["a"])?;
            Ok(V(float(match a.value(0, "a")? {
                Value::Int(i) => (*i as f64).abs(),
                Value::Float(f) => f.abs(),
                Value::Pose(p) => (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt(),
                Value::List(l) => {
                    l.iter().map(|v| v.num("a list element").map(|x| x * x)).sum::<Result<f64, _>>()?.sqrt()
                }
                other => return Err(format!("norm of {}", other.describe())),
            })))
        }
        "to_num" => {
            a.check(&["str"])?;
            match a.value(0, "str")? {
                Value::Str(s) => {
                    let s = s.trim();
                    s.parse::<i64>()
                        .map(Value::Int)
                        .or_else(|_| s.parse::<f64>().map(Value::Float))
                        .map(V)
                        .map_err(|_| format!("to_num: {s:?} is not a number"))
                }
                other => Err(format!("to_num needs a string, got {}", other.describe())),
            }
        }
        "to_str" => {
            a.check(&["val"])?;
            Ok(V(Value::Str(a.value(0, "val")?.to_string())))
        }
        "str_cat" => {
            a.check(&["op1", "op2"])?;
            Ok(V(Value::Str(format!("{}{}", a.value(0, "op1")?, a.value(1, "op2")?))))
        }
        "str_len" => {
            a.check(&["str"])?;
            match a.value(0, "str")? {
                Value::Str(s) => Ok(V(Value::Int(s.chars().count() as i64))),
                other => Err(format!("str_len needs a string, got {}", other.describe())),
            }
        }
        "get_list_length" | "length" => {
            a.check(&["v"])?;
            match a.value(0, "v")? {
                Value::List(l) => Ok(V(Value::Int(l.len() as i64))),
                Value::Pose(_) => Ok(V(Value::Int(6))),
                Value::Str(s) => Ok(V(Value::Int(s.chars().count() as i64))),
                other => Err(format!("{name} of {}", other.describe())),
            }
        }
        // --- Poses ---
        "pose_trans" | "pose_add" | "pose_sub" => {
            a.check(&["p_from", "p_from_to"])?;
            let (p, q) = (a.six(0, "p_from")?, a.six(1, "p_from_to")?);
            let (pp, qq) = (pose_from_vector(&p), pose_from_vector(&q));
            let out = match name {
                "pose_trans" => pose_vector(&(pp * qq)),
                // pose_add: positions add, rotations compose (manual: "p1 ⊕ p2").
                "pose_add" => {
                    let r = qq.rotation * pp.rotation;
                    let v = r.scaled_axis();
                    [p[0] + q[0], p[1] + q[1], p[2] + q[2], v.x, v.y, v.z]
                }
                _ => {
                    let r = pp.rotation * qq.rotation.inverse();
                    let v = r.scaled_axis();
                    [p[0] - q[0], p[1] - q[1], p[2] - q[2], v.x, v.y, v.z]
                }
            };
            Ok(V(Value::Pose(out)))
        }
        "pose_inv" => {
            a.check(&["p_from"])?;
            Ok(V(Value::Pose(pose_vector(&pose_from_vector(&a.six(0, "p_from")?).inverse()))))
        }
        "pose_dist" | "point_dist" => {
            a.check(&["p_from", "p_to"])?;
            let (p, q) = (a.six(0, "p_from")?, a.six(1, "p_to")?);
            let d = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt();
            Ok(V(float(d)))
        }
        "interpolate_pose" => {
            a.check(&["p_from", "p_to", "alpha"])?;
            let (p, q) = (pose_from_vector(&a.six(0, "p_from")?), pose_from_vector(&a.six(1, "p_to")?));
            let f = a.num(2, "alpha")?;
            let t = p.translation.vector.lerp(&q.translation.vector, f);
            let r = p.rotation.slerp(&q.rotation, f);
            Ok(V(Value::Pose(pose_vector(&nalgebra::Isometry3::from_parts(t.into(), r)))))
        }
        _ => Err(format!("`{name}` is not supported by the virtual controller")),
    }
}

/// `tool_contact(direction)`: the cycles back to before the contact began, 0 without one. A
/// contact is the wrist sensor's force (less its `zero_ftsensor` offset), averaged over the last
/// [`TOOL_CONTACT_WINDOW`] cycles, pushing back against the TCP's direction of motion by more than
/// [`TOOL_CONTACT_FORCE_N`]. The cycles back reach past the newest window whose average was below a
/// quarter of that by one window more, so the pose they name is before the contact (by at most
/// 50 ms of motion).
fn tool_contact_steps(cx: &Cx<'_>, direction: &[f64; 6]) -> i64 {
    let v = nalgebra::Vector3::new(direction[0], direction[1], direction[2]);
    let Some(unit) = v.try_normalize(1e-9) else { return 0 };
    let zero = cx.setup.ft_zero;
    let push: Vec<f64> = cx
        .history
        .iter()
        .map(|m| -nalgebra::Vector3::new(m.force[0] - zero[0], m.force[1] - zero[1], m.force[2] - zero[2]).dot(&unit))
        .collect();
    let mean_from = |k: usize| {
        let window = &push[k..(k + TOOL_CONTACT_WINDOW).min(push.len())];
        window.iter().sum::<f64>() / window.len() as f64
    };
    if push.len() < TOOL_CONTACT_WINDOW || mean_from(0) <= TOOL_CONTACT_FORCE_N {
        return 0;
    }
    let before = (0..push.len()).find(|&k| mean_from(k) < 0.25 * TOOL_CONTACT_FORCE_N).unwrap_or(push.len());
    (before + TOOL_CONTACT_WINDOW).min(push.len() - 1) as i64
}
