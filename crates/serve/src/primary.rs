//! The virtual UR5e's script ports: primary (30001), secondary (30002) and real-time (30003).
//!
//! All three take URScript ([`tendril_urscript::stream`]): a `def` program replaces the running
//! one and plays, a `sec` program runs beside it, a line on its own runs as a one-line program,
//! and UR's client library's controller commands (`stop program`, `power on`, `power off`, `set
//! robotmode run`, `set unlock protective stop`) do what the dashboard's equivalents do
//! ([`crate::dashboard::answer`]). The primary and secondary ports also send what a controller
//! sends there ([`crate::robot_state`]): the version message on connect, then the robot state ten
//! times a second of twin time; the primary port also the robot messages
//! ([`crate::robot_messages`]: program started and stopped, runtime exceptions, `textmsg`).
//! The real-time port's 500 Hz state stream is not served.
//!
//! A client that does not read what these ports send loses packages (each connection holds at
//! most [`QUEUED`] unsent), never holds up the others; one that sends more than
//! [`tendril_urscript::stream::MAX_PROGRAM_LEN`] without completing a program is cut off.

use super::dashboard::answer;
use super::robot_state::{robot_state, version};
use super::state::{DeviceState, ProgramState, lock};
use std::sync::{Arc, Mutex};
use std::time::Duration;
use tendril_rtde::dashboard::{Command, RobotMode};
use tendril_rtde::primary::Package;
use tendril_urscript::stream::{ControllerCommand, ScriptEvent, ScriptStream};
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::TcpStream;
use tokio::sync::{mpsc, watch};

/// Which script port a connection came in on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ScriptPort {
    /// 30001: robot state and messages out, script in.
    Primary,
    /// 30002: robot state out, script in.
    Secondary,
    /// 30003: script in (its state stream is not served).
    RealTime,
}

/// Period of the robot state \[s\] (10 Hz, UR's client interface document).
pub const STATE_PERIOD_S: f64 = 0.1;
/// Packages a connection holds for a client that is slow to read.
pub const QUEUED: usize = 64;
/// How long a client may pause before a last line sent without its line end is taken (a
/// program's last `end`, a line on its own; [`ScriptStream::tail_completes`]).
pub const SETTLE: Duration = Duration::from_millis(50);
/// How long a client may pause inside a program before the part received is taken as all it
/// sends (then a program missing its `end` is reported as the syntax error it is): a large program
/// arrives in many segments, 2 s covers the pauses between them on a loaded machine.
pub const PAUSE: Duration = Duration::from_secs(2);

type Shared = Arc<Mutex<DeviceState>>;

/// Serves one connection on a script port.
pub async fn serve(socket: TcpStream, port: ScriptPort, state: Shared, mut ticks: watch::Receiver<u64>) {
    let (mut reader, mut writer) = socket.into_split();
    let (out, mut queue) = mpsc::channel::<Vec<u8>>(QUEUED);
    tokio::spawn(async move {
        while let Some(bytes) = queue.recv().await {
            if writer.write_all(&bytes).await.is_err() {
                return;
            }
        }
    });
    let sends = port != ScriptPort::RealTime;
    let (mut next_state_s, mut messages_sent) = {
        let s = lock(&state);
        if sends && let Ok(bytes) = version(&s).encode() {
            let _ = out.try_send(bytes);
        }
        (s.status.time_s, s.robot_messages.last())
    };
    let mut stream = ScriptStream::new();
    let mut chunk = [0u8; 4096];
    let mut last_byte = tokio::time::Instant::now();
    loop {
        tokio::select! {
            r = reader.read(&mut chunk) => match r {
                Ok(n) if n > 0 => {
                    last_byte = tokio::time::Instant::now();
                    if !apply(stream.feed(&chunk[..n]), &state) {
                        return;
                    }
                }
                _ => {
                    apply(stream.flush(), &state);
                    return;
                }
            },
            () = tokio::time::sleep_until(last_byte + if stream.tail_completes() { SETTLE } else { PAUSE }),
                if stream.in_program() => {
                apply(stream.flush(), &state);
            }
            changed = ticks.changed(), if sends => {
                if changed.is_err() {
                    return;
                }
                let mut packages = Vec::new();
                {
                    let s = lock(&state);
                    if port == ScriptPort::Primary {
                        for (n, m) in s.robot_messages.since(messages_sent) {
                            messages_sent = n;
                            packages.push(Package::Message(m));
                        }
                    }
                    if s.status.time_s >= next_state_s {
                        next_state_s = s.status.time_s + STATE_PERIOD_S;
                        packages.push(robot_state(&s));
                    }
                }
                for p in packages {
                    let Ok(bytes) = p.encode() else { continue };
                    if let Err(mpsc::error::TrySendError::Closed(_)) = out.try_send(bytes) {
                        return;
                    }
                }
            }
        }
    }
}

/// Does what the client sent; false when the connection is to be closed.
fn apply(events: Vec<ScriptEvent>, state: &Shared) -> bool {
    if events.is_empty() {
        return true;
    }
    let mut s = lock(state);
    for event in events {
        match event {
            ScriptEvent::Program(text) => take_program(&mut s, text),
            ScriptEvent::Command(command) => {
                let command = match command {
                    ControllerCommand::StopProgram => Command::Stop,
                    ControllerCommand::PowerOn => Command::PowerOn,
                    ControllerCommand::PowerOff => Command::PowerOff,
                    ControllerCommand::BrakeRelease => Command::BrakeRelease,
                    ControllerCommand::UnlockProtectiveStop => Command::UnlockProtectiveStop,
                };
                let now = s.status.time_s;
                answer(&command, &mut s, now);
            }
            ScriptEvent::TooLong => return false,
        }
    }
    true
}

/// A program arrived: a `sec` program is queued to run beside the main one, a `def` program
/// replaces it and plays (its parse, and a syntax error, come when the twin starts it).
fn take_program(s: &mut DeviceState, text: String) {
    // In local control (PolyScope 5.6 and later) the script ports take no programs; with the
    // robot powered off or its brakes engaged a program cannot start.
    if !s.ur.accepts_programs() {
        return;
    }
    if text.trim_start().starts_with("sec") {
        s.secondary_programs.push_back(text);
        return;
    }
    if s.ur.robot_mode != RobotMode::Running {
        return;
    }
    s.program_source = Some(text);
    s.program_uploads += 1;
    s.program = ProgramState::Playing;
    // A fresh upload also clears a protective stop (see `safety`; a real controller wants
    // `unlock protective stop` on the dashboard, which the virtual one takes as well).
    s.protective_stop = None;
    s.ur.protective_stop_at = None;
}
