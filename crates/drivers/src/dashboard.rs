//! The UR5e's preconditions, checked on its dashboard server (TCP 29999) before the follow program
//! is uploaded: a program sent to the script port only runs on a robot that is powered with its
//! brakes released (robot mode RUNNING), not in a protective or other safety stop (safety status
//! NORMAL), and, on PolyScope 5.6 and later, in remote control. Each failure says which
//! precondition failed and what to do on the pendant.

use super::tcp;
use std::time::Duration;
use tendril_rtde::dashboard::{Command, GREETING, PolyscopeVersion, RobotMode, SafetyStatus, parse_true};
use tokio::io::{AsyncBufReadExt, AsyncWriteExt, BufReader};
use tokio::net::TcpStream;

/// How long the connection and each reply may take.
const TIMEOUT: Duration = Duration::from_secs(3);

/// The oldest PolyScope the follow program is written for: 5.0, the e-Series software (the UR5e
/// runs nothing older).
pub const MIN_POLYSCOPE: PolyscopeVersion = PolyscopeVersion { major: 5, minor: 0, bugfix: 0, build: 0 };

/// A precondition the UR5e does not meet, or a dashboard that does not answer as one.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PreconditionError {
    /// The dashboard server could not be reached or stopped answering.
    #[error("UR5e dashboard server {addr}: {cause}")]
    Dashboard {
        /// Its address.
        addr: String,
        /// What went wrong.
        cause: String,
    },
    /// A reply that is not what the command gives.
    #[error("UR5e dashboard: unexpected reply to `{command}`: {reply:?}")]
    Unexpected {
        /// The command.
        command: String,
        /// Its reply.
        reply: String,
    },
    /// PolyScope older than [`MIN_POLYSCOPE`].
    #[error("UR5e runs PolyScope {version}; the follow program needs {MIN_POLYSCOPE} or later (e-Series)")]
    PolyscopeTooOld {
        /// The version reported.
        version: PolyscopeVersion,
    },
    /// Local control on PolyScope 5.6 or later.
    #[error(
        "UR5e is not in remote control (PolyScope {version}: programs start only in remote control); switch the pendant to Remote Control"
    )]
    NotInRemoteControl {
        /// The version reported.
        version: PolyscopeVersion,
    },
    /// Robot mode other than RUNNING.
    #[error("UR5e robot mode is {mode}, not RUNNING: power the robot on and release the brakes")]
    NotRunning {
        /// The mode reported.
        mode: &'static str,
    },
    /// Safety status other than NORMAL.
    #[error("UR5e safety status is {status}, not NORMAL: clear the stop on the pendant (after inspecting its cause)")]
    NotSafe {
        /// The status reported.
        status: &'static str,
    },
}

/// What the dashboard reported when every precondition held.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Readiness {
    /// PolyScope version.
    pub version: PolyscopeVersion,
    /// Whether remote control was checked (PolyScope 5.6 and later).
    pub remote_control_checked: bool,
}

struct Dashboard {
    addr: String,
    lines: BufReader<TcpStream>,
}

impl Dashboard {
    fn fail(&self, cause: impl std::fmt::Display) -> PreconditionError {
        PreconditionError::Dashboard { addr: self.addr.clone(), cause: cause.to_string() }
    }

    async fn read_line(&mut self) -> Result<String, PreconditionError> {
        let mut line = String::new();
        match tokio::time::timeout(TIMEOUT, self.lines.read_line(&mut line)).await {
            Err(_) => Err(self.fail("no reply within 3 s")),
            Ok(Err(e)) => Err(self.fail(e)),
            Ok(Ok(0)) => Err(self.fail("closed the connection")),
            Ok(Ok(_)) => Ok(line.trim_end().to_string()),
        }
    }

    async fn ask(&mut self, command: Command) -> Result<String, PreconditionError> {
        let line = command.line();
        if let Err(e) = self.lines.get_mut().write_all(line.as_bytes()).await {
            return Err(self.fail(e));
        }
        self.read_line().await
    }
}

fn unexpected(command: Command, reply: String) -> PreconditionError {
    PreconditionError::Unexpected { command: command.line().trim_end().to_string(), reply }
}

/// Connects to the dashboard server at `addr` and checks, in this order: PolyScope version,
/// remote control (5.6 and later), robot mode RUNNING, safety status NORMAL. The first that fails
/// is the error.
pub async fn check_ready(addr: &str) -> Result<Readiness, PreconditionError> {
    let stream = tcp::connect(addr, TIMEOUT)
        .await
        .map_err(|cause| PreconditionError::Dashboard { addr: addr.to_string(), cause })?;
    let mut d = Dashboard { addr: addr.to_string(), lines: BufReader::new(stream) };
    let greeting = d.read_line().await?;
    if !greeting.starts_with(GREETING) {
        return Err(d.fail(format!("greeted with {greeting:?}, not {GREETING:?}")));
    }
    let reply = d.ask(Command::PolyscopeVersion).await?;
    let version = PolyscopeVersion::parse_reply(&reply).ok_or_else(|| unexpected(Command::PolyscopeVersion, reply))?;
    if version < MIN_POLYSCOPE {
        return Err(PreconditionError::PolyscopeTooOld { version });
    }
    let remote_control_checked = version >= PolyscopeVersion::REMOTE_CONTROL;
    if remote_control_checked && !parse_true(&d.ask(Command::IsInRemoteControl).await?) {
        return Err(PreconditionError::NotInRemoteControl { version });
    }
    let reply = d.ask(Command::RobotMode).await?;
    let mode = RobotMode::parse_reply(&reply).ok_or_else(|| unexpected(Command::RobotMode, reply))?;
    if mode != RobotMode::Running {
        return Err(PreconditionError::NotRunning { mode: mode.name() });
    }
    let reply = d.ask(Command::SafetyStatus).await?;
    let status = SafetyStatus::parse_reply(&reply).ok_or_else(|| unexpected(Command::SafetyStatus, reply))?;
    if status != SafetyStatus::Normal {
        return Err(PreconditionError::NotSafe { status: status.name() });
    }
    // Leave as a client should; the reply does not matter.
    let _ = d.ask(Command::Quit).await;
    Ok(Readiness { version, remote_control_checked })
}
