//! The UR Dashboard Server protocol (TCP 29999): one ASCII command per line, one reply line each.
//!
//! Command names and reply texts as UR documents them ("Dashboard Server e-Series, port 29999") and
//! as SDU's `ur_rtde` `DashboardClient` parses them: `Robotmode: RUNNING`, `Safetystatus: NORMAL`,
//! `Program running: true`, `URSoftware 5.11.1.108318 (Mar 23 2021)`, `Starting program`, ...
//! The server greets each connection with `Connected: Universal Robots Dashboard Server`.
//! Sans-IO: [`Command::parse`] and the reply texts for the server, the reply parsers for the client.

/// The greeting line sent on connect.
pub const GREETING: &str = "Connected: Universal Robots Dashboard Server";

/// A dashboard command (the subset the virtual UR answers; others are [`Command::Unknown`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Command {
    /// `robotmode`.
    RobotMode,
    /// `programState`.
    ProgramState,
    /// `running`.
    Running,
    /// `is in remote control` (PolyScope 5.6 and later).
    IsInRemoteControl,
    /// `power on`.
    PowerOn,
    /// `power off`.
    PowerOff,
    /// `brake release`.
    BrakeRelease,
    /// `play`.
    Play,
    /// `stop`.
    Stop,
    /// `pause`.
    Pause,
    /// `load <program.urp>`.
    Load(String),
    /// `safetystatus`.
    SafetyStatus,
    /// `safetymode` (deprecated by UR in favour of `safetystatus`).
    SafetyMode,
    /// `PolyscopeVersion`.
    PolyscopeVersion,
    /// `close safety popup`.
    CloseSafetyPopup,
    /// `close popup`.
    ClosePopup,
    /// `saveLog`: flush the log to disk.
    SaveLog,
    /// `unlock protective stop`.
    UnlockProtectiveStop,
    /// `get serial number` (PolyScope 5.6 and later; SDU ur_rtde's control interface asks).
    GetSerialNumber,
    /// `get robot model`.
    GetRobotModel,
    /// `quit`: the server replies and closes the connection.
    Quit,
    /// Anything else, as received.
    Unknown(String),
}

impl Command {
    /// Parses one line (without its newline); names are matched without regard to case, as the
    /// controller does.
    pub fn parse(line: &str) -> Command {
        let trimmed = line.trim();
        let lower = trimmed.to_ascii_lowercase();
        match lower.as_str() {
            "robotmode" => Command::RobotMode,
            "programstate" => Command::ProgramState,
            "running" => Command::Running,
            "is in remote control" => Command::IsInRemoteControl,
            "power on" => Command::PowerOn,
            "power off" => Command::PowerOff,
            "brake release" => Command::BrakeRelease,
            "play" => Command::Play,
            "stop" => Command::Stop,
            "pause" => Command::Pause,
            "safetystatus" => Command::SafetyStatus,
            "safetymode" => Command::SafetyMode,
            "polyscopeversion" => Command::PolyscopeVersion,
            "close safety popup" => Command::CloseSafetyPopup,
            "close popup" => Command::ClosePopup,
            "savelog" => Command::SaveLog,
            "get serial number" => Command::GetSerialNumber,
            "get robot model" => Command::GetRobotModel,
            "unlock protective stop" => Command::UnlockProtectiveStop,
            "quit" => Command::Quit,
            _ if lower.starts_with("load ") => Command::Load(trimmed[5..].trim().to_string()),
            _ => Command::Unknown(trimmed.to_string()),
        }
    }

    /// The line a client sends (with its newline).
    pub fn line(&self) -> String {
        let text = match self {
            Command::RobotMode => "robotmode",
            Command::ProgramState => "programState",
            Command::Running => "running",
            Command::IsInRemoteControl => "is in remote control",
            Command::PowerOn => "power on",
            Command::PowerOff => "power off",
            Command::BrakeRelease => "brake release",
            Command::Play => "play",
            Command::Stop => "stop",
            Command::Pause => "pause",
            Command::Load(file) => return format!("load {file}\n"),
            Command::SafetyStatus => "safetystatus",
            Command::SafetyMode => "safetymode",
            Command::PolyscopeVersion => "PolyscopeVersion",
            Command::CloseSafetyPopup => "close safety popup",
            Command::ClosePopup => "close popup",
            Command::SaveLog => "saveLog",
            Command::UnlockProtectiveStop => "unlock protective stop",
            Command::GetSerialNumber => "get serial number",
            Command::GetRobotModel => "get robot model",
            Command::Quit => "quit",
            Command::Unknown(text) => return format!("{text}\n"),
        };
        format!("{text}\n")
    }
}

/// Robot modes, as `robotmode` names them (RTDE `robot_mode` numbers).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RobotMode {
    /// 0.
    Disconnected,
    /// 1.
    ConfirmSafety,
    /// 2.
    Booting,
    /// 3.
    PowerOff,
    /// 4.
    PowerOn,
    /// 5: powered, brakes engaged.
    Idle,
    /// 6.
    Backdrive,
    /// 7: brakes released, ready to run programs.
    Running,
}

impl RobotMode {
    const ALL: [(RobotMode, &'static str); 8] = [
        (RobotMode::Disconnected, "DISCONNECTED"),
        (RobotMode::ConfirmSafety, "CONFIRM_SAFETY"),
        (RobotMode::Booting, "BOOTING"),
        (RobotMode::PowerOff, "POWER_OFF"),
        (RobotMode::PowerOn, "POWER_ON"),
        (RobotMode::Idle, "IDLE"),
        (RobotMode::Backdrive, "BACKDRIVE"),
        (RobotMode::Running, "RUNNING"),
    ];

    /// The name `robotmode` reports.
    pub fn name(self) -> &'static str {
        Self::ALL[self as usize].1
    }

    /// The RTDE `robot_mode` number.
    pub fn rtde(self) -> i32 {
        self as i32
    }

    /// The `robotmode` reply.
    pub fn reply(self) -> String {
        format!("Robotmode: {}", self.name())
    }

    /// Parses a `robotmode` reply (`Robotmode: RUNNING`).
    pub fn parse_reply(reply: &str) -> Option<RobotMode> {
        let name = reply.trim().strip_prefix("Robotmode:")?.trim();
        Self::ALL.iter().find(|(_, n)| *n == name).map(|(m, _)| *m)
    }
}

/// The safety statuses `safetystatus` reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SafetyStatus {
    /// Normal operation.
    Normal,
    /// Reduced mode.
    Reduced,
    /// Protective stop.
    ProtectiveStop,
    /// Recovery mode.
    Recovery,
    /// Safeguard stop.
    SafeguardStop,
    /// System emergency stop.
    SystemEmergencyStop,
    /// Robot emergency stop.
    RobotEmergencyStop,
    /// Violation.
    Violation,
    /// Fault.
    Fault,
}

impl SafetyStatus {
    const ALL: [(SafetyStatus, &'static str); 9] = [
        (SafetyStatus::Normal, "NORMAL"),
        (SafetyStatus::Reduced, "REDUCED"),
        (SafetyStatus::ProtectiveStop, "PROTECTIVE_STOP"),
        (SafetyStatus::Recovery, "RECOVERY"),
        (SafetyStatus::SafeguardStop, "SAFEGUARD_STOP"),
        (SafetyStatus::SystemEmergencyStop, "SYSTEM_EMERGENCY_STOP"),
        (SafetyStatus::RobotEmergencyStop, "ROBOT_EMERGENCY_STOP"),
        (SafetyStatus::Violation, "VIOLATION"),
        (SafetyStatus::Fault, "FAULT"),
    ];

    /// The name `safetystatus` reports.
    pub fn name(self) -> &'static str {
        Self::ALL[self as usize].1
    }

    /// The `safetystatus` reply.
    pub fn reply(self) -> String {
        format!("Safetystatus: {}", self.name())
    }

    /// Parses a `safetystatus` (or `safetymode`) reply.
    pub fn parse_reply(reply: &str) -> Option<SafetyStatus> {
        let r = reply.trim();
        let name = r.strip_prefix("Safetystatus:").or_else(|| r.strip_prefix("Safetymode:"))?.trim();
        Self::ALL.iter().find(|(_, n)| *n == name).map(|(s, _)| *s)
    }
}

/// A PolyScope version, `major.minor.bugfix.build`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub struct PolyscopeVersion {
    /// Major (5 on e-Series).
    pub major: u32,
    /// Minor.
    pub minor: u32,
    /// Bug-fix.
    pub bugfix: u32,
    /// Build.
    pub build: u32,
}

impl PolyscopeVersion {
    /// The first version with remote control (`is in remote control`; programs start only in
    /// remote control): 5.6.0.
    pub const REMOTE_CONTROL: PolyscopeVersion = PolyscopeVersion { major: 5, minor: 6, bugfix: 0, build: 0 };

    /// Parses the first `a.b.c.d` in a `PolyscopeVersion` reply (`URSoftware 5.11.1.108318 (Mar 23
    /// 2021)`), as `ur_rtde` does.
    pub fn parse_reply(reply: &str) -> Option<PolyscopeVersion> {
        reply.split_whitespace().find_map(|word| {
            let parts: Vec<u32> = word.split('.').map(str::parse).collect::<Result<_, _>>().ok()?;
            match parts[..] {
                [major, minor, bugfix, build] => Some(PolyscopeVersion { major, minor, bugfix, build }),
                _ => None,
            }
        })
    }
}

impl std::fmt::Display for PolyscopeVersion {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}.{}.{}.{}", self.major, self.minor, self.bugfix, self.build)
    }
}

/// Parses a yes/no reply (`true`, `Program running: true`), as `ur_rtde` does: "true" anywhere,
/// regardless of case.
pub fn parse_true(reply: &str) -> bool {
    reply.to_ascii_lowercase().contains("true")
}

/// Reply texts of the commands that act.
pub mod reply {
    /// `power on`.
    pub const POWERING_ON: &str = "Powering on";
    /// `power off`.
    pub const POWERING_OFF: &str = "Powering off";
    /// `brake release`.
    pub const BRAKE_RELEASING: &str = "Brake releasing";
    /// `play`, success.
    pub const STARTING_PROGRAM: &str = "Starting program";
    /// `play`, failure.
    pub const PLAY_FAILED: &str = "Failed to execute: play";
    /// `stop`, success.
    pub const STOPPED: &str = "Stopped";
    /// `stop`, failure.
    pub const STOP_FAILED: &str = "Failed to execute: stop";
    /// `pause`, success.
    pub const PAUSING: &str = "Pausing program";
    /// `pause`, failure.
    pub const PAUSE_FAILED: &str = "Failed to execute: pause";
    /// `close safety popup`.
    pub const CLOSING_SAFETY_POPUP: &str = "closing safety popup";
    /// `close popup`.
    pub const CLOSING_POPUP: &str = "closing popup";
    /// `saveLog`.
    pub const LOG_SAVED: &str = "Log saved to disk";
    /// `unlock protective stop`, success.
    pub const PROTECTIVE_STOP_RELEASING: &str = "Protective stop releasing";
    /// `unlock protective stop` within 5 s of the stop.
    pub const PROTECTIVE_STOP_TOO_SOON: &str = "Cannot unlock protective stop until 5s after occurrence. Always inspect cause of protective stop before unlocking";
    /// `quit`.
    pub const DISCONNECTED: &str = "Disconnected";
    /// A command that moves the robot or changes its program, refused in local control (the
    /// text is ours: UR does not document the one PolyScope sends).
    pub const LOCAL_CONTROL: &str = "Command is not allowed due to safety reasons. Switch your robot to remote control";
}

/// `load` success.
pub fn loading(file: &str) -> String {
    format!("Loading program: {file}")
}

/// `load` of a file the controller does not have.
pub fn file_not_found(file: &str) -> String {
    format!("File not found: {file}")
}

/// The reply to an unknown command.
pub fn not_understood(command: &str) -> String {
    format!("could not understand: '{command}'")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn commands_parse_regardless_of_case_and_round_trip() {
        assert_eq!(Command::parse("PolyscopeVersion"), Command::PolyscopeVersion);
        assert_eq!(Command::parse("polyscopeversion\r"), Command::PolyscopeVersion);
        assert_eq!(Command::parse("Is In Remote Control"), Command::IsInRemoteControl);
        assert_eq!(Command::parse("load /programs/follow.urp"), Command::Load("/programs/follow.urp".into()));
        assert_eq!(Command::parse("fly"), Command::Unknown("fly".into()));
        for c in [Command::ProgramState, Command::UnlockProtectiveStop, Command::Load("a.urp".into())] {
            assert_eq!(Command::parse(c.line().trim_end()), c);
        }
    }

    #[test]
    fn replies_parse_as_ur_rtde_reads_them() {
        assert_eq!(RobotMode::Running.reply(), "Robotmode: RUNNING");
        assert_eq!(RobotMode::parse_reply("Robotmode: POWER_OFF"), Some(RobotMode::PowerOff));
        assert_eq!(RobotMode::Idle.rtde(), 5);
        assert_eq!(SafetyStatus::parse_reply("Safetystatus: PROTECTIVE_STOP"), Some(SafetyStatus::ProtectiveStop));
        assert_eq!(SafetyStatus::parse_reply("Safetymode: NORMAL"), Some(SafetyStatus::Normal));
        let v = PolyscopeVersion::parse_reply("URSoftware 5.11.1.108318 (Mar 23 2021)").unwrap();
        assert_eq!(v, PolyscopeVersion { major: 5, minor: 11, bugfix: 1, build: 108318 });
        assert!(v >= PolyscopeVersion::REMOTE_CONTROL);
        assert!(PolyscopeVersion::parse_reply("URSoftware 5.5.1.1 (x)").unwrap() < PolyscopeVersion::REMOTE_CONTROL);
        assert_eq!(PolyscopeVersion::parse_reply("garbage"), None);
        assert!(parse_true("Program running: true") && parse_true("TRUE") && !parse_true("false"));
    }
}
