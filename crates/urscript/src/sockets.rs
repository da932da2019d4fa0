//! The socket builtins (URScript manual names and defaults): `socket_open`, `socket_close`,
//! `socket_read_binary_integer`, `socket_read_byte_list`, `socket_send_int`, `socket_send_byte`,
//! `socket_send_string`, `socket_send_line`. The controller does the I/O
//! ([`crate::Controller::socket_open`] and the rest); here are the calls' semantics:
//!
//! - `socket_open(address, port, socket_name="socket_0")` waits until the connection is made
//!   (True) or fails (False), at most [`OPEN_TIMEOUT_S`]; a host the controller refuses stops the
//!   program with the reason.
//! - A read waits until its bytes have arrived or `timeout` \[s\] has passed (default 2; 0 or less
//!   waits for ever), the thread parked meanwhile so the others run. It returns the count read
//!   first, then the values: on a timeout, or on a socket that is not open, the count is 0 and the
//!   values are -1, as the manual gives `[0, -1, -1, ...]`.
//! - Integers are 32-bit, big-endian (network byte order), as the manual and UR's client library
//!   (its reverse, trajectory and script-command interfaces) have them.

use super::call::{Args, Cx, Outcome};
use super::controller::SocketState;
use super::value::Value;

/// How long `socket_open` waits for a connection \[s\] (the manual: "times out after 2 seconds").
pub const OPEN_TIMEOUT_S: f64 = 2.0;
/// `socket_read_*`'s default timeout \[s\].
pub const READ_TIMEOUT_S: f64 = 2.0;
/// Most values one read may ask for: the manual caps `socket_read_binary_integer` at 30
/// integers; bytes are capped at 1000 (UR gives no figure; a larger read is an error, not an
/// allocation a program chooses).
pub const MAX_READ_INTEGERS: usize = 30;
/// See [`MAX_READ_INTEGERS`].
pub const MAX_READ_BYTES: usize = 1000;

const DEFAULT_NAME: &str = "socket_0";

fn name_arg(a: &Args<'_>, i: usize) -> Result<String, String> {
    match a.get(i, "socket_name") {
        None => Ok(DEFAULT_NAME.into()),
        Some(Value::Str(s)) => Ok(s.clone()),
        Some(other) => Err(format!("{}: socket_name must be a string, got {}", a.name, other.describe())),
    }
}

/// Whether the call has waited out `timeout` \[s\] (0 or less: never).
fn timed_out(cx: &Cx<'_>, timeout: f64) -> bool {
    timeout > 0.0 && cx.now - cx.call_started >= timeout - 1e-9
}

/// A read's result: the count, then the values, or the failure value `[0, -1, ...]`.
fn read_result(values: Option<Vec<i64>>, n: usize) -> Value {
    match values {
        Some(v) => {
            let mut out = vec![Value::Int(v.len() as i64)];
            out.extend(v.into_iter().map(Value::Int));
            Value::List(out)
        }
        None => {
            let mut out = vec![Value::Int(0)];
            out.extend(std::iter::repeat_n(Value::Int(-1), n));
            Value::List(out)
        }
    }
}

/// Reads `n` items of `size` bytes each, decoded by `decode`; blocks until they arrived or the
/// timeout passed.
fn read(cx: &mut Cx<'_>, name: &str, n: usize, size: usize, timeout: f64, decode: fn(&[u8]) -> i64) -> Outcome {
    if cx.host.socket_state(name) != SocketState::Open {
        return Outcome::Value(read_result(None, n));
    }
    match cx.host.socket_read(name, n * size) {
        Some(bytes) => Outcome::Value(read_result(Some(bytes.chunks_exact(size).map(decode).collect()), n)),
        None if timed_out(cx, timeout) => Outcome::Value(read_result(None, n)),
        None => Outcome::Block,
    }
}

fn count(a: &Args<'_>, key: &str, max: usize) -> Result<usize, String> {
    let v = a.num(0, key)?;
    if v.fract() != 0.0 || v < 1.0 || v > max as f64 {
        return Err(format!("{}: {key} must be an integer in 1..={max}, got {v}", a.name));
    }
    Ok(v as usize)
}

fn send(cx: &mut Cx<'_>, name: &str, bytes: &[u8]) -> Outcome {
    Outcome::Value(Value::Bool(cx.host.socket_send(name, bytes)))
}

/// Calls socket builtin `name`, if it is one.
pub(crate) fn call(a: &Args<'_>, cx: &mut Cx<'_>) -> Option<Result<Outcome, String>> {
    if a.name.starts_with("socket_") {
        // I/O, not an endless computation (a thread reading a socket the peer closed gets its
        // failure value at once, and may loop on it until another thread ends the program).
        cx.socket_io = true;
    }
    Some(match a.name {
        "socket_open" => open(a, cx),
        "socket_close" => a.check(&["socket_name"]).and_then(|()| {
            let name = name_arg(a, 0)?;
            cx.host.socket_close(&name);
            Ok(Outcome::Value(Value::Void))
        }),
        "socket_read_binary_integer" => a.check(&["number", "socket_name", "timeout"]).and_then(|()| {
            let n = count(a, "number", MAX_READ_INTEGERS)?;
            let name = name_arg(a, 1)?;
            let timeout = a.num_or(2, "timeout", READ_TIMEOUT_S)?;
            Ok(read(cx, &name, n, 4, timeout, |b| i64::from(i32::from_be_bytes([b[0], b[1], b[2], b[3]]))))
        }),
        "socket_read_byte_list" => a.check(&["number", "socket_name", "timeout"]).and_then(|()| {
            let n = count(a, "number", MAX_READ_BYTES)?;
            let name = name_arg(a, 1)?;
            let timeout = a.num_or(2, "timeout", READ_TIMEOUT_S)?;
            Ok(read(cx, &name, n, 1, timeout, |b| i64::from(b[0])))
        }),
        "socket_send_int" => a.check(&["value", "socket_name"]).and_then(|()| {
            let v = a.num(0, "value")?;
            if v.fract() != 0.0 || v < f64::from(i32::MIN) || v > f64::from(i32::MAX) {
                return Err(format!("socket_send_int: {v} is not a 32-bit integer"));
            }
            Ok(send(cx, &name_arg(a, 1)?, &(v as i32).to_be_bytes()))
        }),
        "socket_send_byte" => a.check(&["value", "socket_name"]).and_then(|()| {
            let v = a.num(0, "value")?;
            if v.fract() != 0.0 || !(0.0..=255.0).contains(&v) {
                return Err(format!("socket_send_byte: {v} is not a byte"));
            }
            Ok(send(cx, &name_arg(a, 1)?, &[v as u8]))
        }),
        "socket_send_string" | "socket_send_line" => a.check(&["str", "socket_name"]).and_then(|()| {
            let mut text = a.value(0, "str")?.to_string();
            if a.name == "socket_send_line" {
                text.push('\n');
            }
            Ok(send(cx, &name_arg(a, 1)?, text.as_bytes()))
        }),
        _ => return None,
    })
}

fn open(a: &Args<'_>, cx: &mut Cx<'_>) -> Result<Outcome, String> {
    a.check(&["address", "port", "socket_name"])?;
    let host = match a.value(0, "address")? {
        Value::Str(s) => s.clone(),
        other => return Err(format!("socket_open: address must be a string, got {}", other.describe())),
    };
    let port = a.num(1, "port")?;
    if port.fract() != 0.0 || !(1.0..=65535.0).contains(&port) {
        return Err(format!("socket_open: port {port} is not in 1..=65535"));
    }
    let name = name_arg(a, 2)?;
    // First call: start connecting. Later calls (the thread parked here) look how it went.
    if cx.call_started == cx.now {
        cx.host.socket_open(&name, &host, port as u16)?;
    }
    match cx.host.socket_state(&name) {
        SocketState::Open => Ok(Outcome::Value(Value::Bool(true))),
        SocketState::Connecting if !timed_out(cx, OPEN_TIMEOUT_S) => Ok(Outcome::Block),
        SocketState::Failed(why) => {
            cx.host.message(&format!("socket_open: {host}:{port} ({name}) failed: {why}"));
            Ok(Outcome::Value(Value::Bool(false)))
        }
        _ => {
            cx.host.socket_close(&name);
            Ok(Outcome::Value(Value::Bool(false)))
        }
    }
}
