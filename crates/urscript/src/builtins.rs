//! The built-in functions the virtual controller implements (URScript manual names, parameters
//! and defaults). Anything else is a runtime error naming the function, as a controller rejects a
//! program calling an unknown function. The list is in `docs/cell/urscript.md`.

use super::controller::{Controller, DigitalOut};
use super::motion::Arm;
use super::value::Value;
use crate::watchdog::{RtdeWatchdog, WatchdogAction};
use tendril_rtde::fields::REGISTER_COUNT;
use tendril_ur5e::kinematics as ur5e;
use tendril_ur5e::pose::{pose_from_vector, pose_vector, tcp_pose};

/// What a built-in gives back.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome {
    /// A value, at once.
    Value(Value),
    /// A value, after waiting this long \[s\] (`sync`, `sleep`, `servoj`, `speedj`).
    Sleep(Value, f64),
    /// A value, once this motion is over (`movej`, `movel`, `stopj`).
    Move(Value, u64),
}

/// What a built-in may touch.
pub struct Cx<'a> {
    /// The controller around the interpreter.
    pub host: &'a mut dyn Controller,
    /// The motion generator.
    pub arm: &'a mut Arm,
    /// Twin time \[s\].
    pub now: f64,
    /// The calling thread.
    pub thread: u64,
    /// The controller cycle \[s\].
    pub period: f64,
}

/// Positional and keyword arguments of one call.
struct Args<'a> {
    name: &'a str,
    pos: &'a [Value],
    kw: &'a [(String, Value)],
}

impl Args<'_> {
    /// Checks the call against the parameter list (in order).
    fn check(&self, params: &[&str]) -> Result<(), String> {
        if self.pos.len() > params.len() {
            return Err(format!("{} takes at most {} arguments, {} given", self.name, params.len(), self.pos.len()));
        }
        for (k, _) in self.kw {
            if !params.contains(&k.as_str()) {
                return Err(format!("{} has no parameter `{k}`", self.name));
            }
        }
        Ok(())
    }

    fn get(&self, i: usize, key: &str) -> Option<&Value> {
        self.pos.get(i).or_else(|| self.kw.iter().find(|(k, _)| k == key).map(|(_, v)| v))
    }

    fn value(&self, i: usize, key: &str) -> Result<&Value, String> {
        self.get(i, key).ok_or_else(|| format!("{}: missing argument `{key}`", self.name))
    }

    fn num(&self, i: usize, key: &str) -> Result<f64, String> {
        self.value(i, key)?.num(&format!("{}'s `{key}`", self.name))
    }

    fn num_or(&self, i: usize, key: &str, default: f64) -> Result<f64, String> {
        match self.get(i, key) {
            Some(v) => v.num(&format!("{}'s `{key}`", self.name)),
            None => Ok(default),
        }
    }

    fn six(&self, i: usize, key: &str) -> Result<[f64; 6], String> {
        self.value(i, key)?.six(&format!("{}'s `{key}`", self.name))
    }

    fn index(&self, i: usize, key: &str, count: usize) -> Result<usize, String> {
        let v = self.num(i, key)?;
        if v < 0.0 || v.fract() != 0.0 || v >= count as f64 {
            return Err(format!("{}: index {v} is not in 0..{}", self.name, count - 1));
        }
        Ok(v as usize)
    }

    fn boolean(&self, i: usize, key: &str) -> Result<bool, String> {
        self.value(i, key)?.truthy()
    }
}

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
fn joints_of(name: &str, v: &Value, near: &[f64; 6]) -> Result<[f64; 6], String> {
    match v {
        Value::Pose(p) => ur5e::inverse_near(&pose_from_vector(&finite6(name, *p)?), near)
            .ok_or_else(|| format!("{name}: no joint solution for {v}")),
        other => other.six(&format!("{name}'s target")),
    }
}

/// Calls built-in `name`.
pub fn call(name: &str, pos: &[Value], kw: &[(String, Value)], cx: &mut Cx<'_>) -> Result<Outcome, String> {
    let a = Args { name, pos, kw };
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
            let target = joints_of(name, a.value(0, "q")?, &cx.arm.target_q())?;
            let acc = positive(name, "a", a.num_or(1, "a", 1.4)?)?;
            let vel = positive(name, "v", a.num_or(2, "v", 1.05)?)?;
            let t = duration(name, a.num_or(3, "t", 0.0)?)?;
            Ok(Outcome::Move(Value::Void, cx.arm.movej(target, acc, vel, t, cx.thread)))
        }
        "movel" => {
            a.check(&["pose", "a", "v", "t", "r"])?;
            let target = match a.value(0, "pose")? {
                Value::Pose(p) => *p,
                other => tcp_pose(&finite6(name, other.six("movel's target")?)?, &[0.0; 6]),
            };
            let acc = positive(name, "a", a.num_or(1, "a", 1.2)?)?;
            let vel = positive(name, "v", a.num_or(2, "v", 0.25)?)?;
            let t = duration(name, a.num_or(3, "t", 0.0)?)?;
            Ok(Outcome::Move(Value::Void, cx.arm.movel(target, acc, vel, t, cx.thread)?))
        }
        "servoj" => {
            a.check(&["q", "a", "v", "t", "lookahead_time", "gain"])?;
            let q = joints_of(name, a.value(0, "q")?, &cx.arm.target_q())?;
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
        "get_actual_joint_positions" => {
            a.check(&[])?;
            Ok(V(Value::list6(cx.host.actual_q())))
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
            Ok(V(Value::Pose(tcp_pose(&cx.host.actual_q(), &[0.0; 6]))))
        }
        "get_target_tcp_pose" => {
            a.check(&[])?;
            Ok(V(Value::Pose(tcp_pose(&cx.arm.target_q(), &[0.0; 6]))))
        }
        "get_forward_kin" => {
            a.check(&["q", "tcp"])?;
            let q = match a.get(0, "q") {
                Some(v) => finite6(name, v.six("get_forward_kin's q")?)?,
                None => cx.host.actual_q(),
            };
            let tcp = match a.get(1, "tcp") {
                Some(v) => v.six("get_forward_kin's tcp")?,
                None => [0.0; 6],
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
            ur5e::inverse_near(&pose_from_vector(&x), &near)
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
            Ok(V(Value::Bool(ur5e::inverse_near(&pose_from_vector(&x), &near).is_some())))
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
        // --- Messages ---
        "textmsg" => {
            a.check(&["s1", "s2"])?;
            let s2 = a.get(1, "s2").map(ToString::to_string).unwrap_or_default();
            cx.host.message(&format!("{}{s2}", a.value(0, "s1")?));
            Ok(V(Value::Void))
        }
        "popup" => {
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
