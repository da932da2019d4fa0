//! The virtual UR5e's dashboard server: what each command does to the controller's state.
//!
//! The controller's state besides the program (which lives in [`DeviceState::program`]): robot
//! mode, local or remote control, PolyScope version, the loaded program. [`crate::controller::VirtualUrSetup`] puts
//! it in a given state at start (tests use it to make each precondition of the real path fail);
//! the dashboard commands change it as PolyScope would:
//!
//! - `power on` → IDLE, `brake release` → RUNNING (powering on first when off), `power off` →
//!   POWER_OFF (the program stops);
//! - `play` starts the loaded or uploaded program if the robot is RUNNING, not protective-stopped
//!   and in remote control; `stop`, `pause` as on the pendant;
//! - `load NAME.urp` loads the one program the virtual controller has (it follows the RTDE
//!   registers, as `follow.script` does) under that name; any other name is not found;
//! - in local control (PolyScope 5.6 and later) `power on`, `power off`, `brake release`, `play`
//!   and `load` are refused, and programs sent to the script ports are ignored;
//! - `unlock protective stop` clears a protective stop from 5 s after it on;
//! - `is in remote control` is not understood before PolyScope 5.6, as there.

use super::controller::UNLOCK_DELAY_S;
use super::state::{DeviceState, ProgramState};
use tendril_rtde::dashboard::{Command, RobotMode, SafetyStatus, file_not_found, loading, not_understood, reply};

/// The reply to `command` at twin time `now_s`, and whether the connection closes after it.
pub fn answer(command: &Command, s: &mut DeviceState, now_s: f64) -> (String, bool) {
    let remote_only = matches!(
        command,
        Command::PowerOn | Command::PowerOff | Command::BrakeRelease | Command::Play | Command::Load(_)
    );
    if remote_only && !s.ur.accepts_programs() {
        return (reply::LOCAL_CONTROL.into(), false);
    }
    let text = match command {
        Command::RobotMode => s.ur.robot_mode.reply(),
        Command::ProgramState => {
            let state = match s.program {
                ProgramState::Stopped => "STOPPED",
                ProgramState::Playing => "PLAYING",
                ProgramState::Paused => "PAUSED",
            };
            format!("{state} {}", s.ur.loaded_program.as_deref().unwrap_or("<unnamed>"))
        }
        Command::Running => format!("Program running: {}", s.program == ProgramState::Playing),
        Command::IsInRemoteControl if s.ur.has_remote_control() => s.ur.remote_control.to_string(),
        Command::IsInRemoteControl => not_understood("is in remote control"),
        Command::PowerOn => {
            if s.ur.robot_mode == RobotMode::PowerOff {
                s.ur.robot_mode = RobotMode::Idle;
            }
            reply::POWERING_ON.into()
        }
        Command::PowerOff => {
            s.ur.robot_mode = RobotMode::PowerOff;
            s.program = ProgramState::Stopped;
            reply::POWERING_OFF.into()
        }
        // From power off too: the arm powers on first (UR's client library releases the brakes
        // of a robot its dashboard example left powered off, and its examples then run).
        Command::BrakeRelease => {
            s.ur.robot_mode = RobotMode::Running;
            reply::BRAKE_RELEASING.into()
        }
        Command::Play => {
            let ready = s.ur.robot_mode == RobotMode::Running && s.protective_stop.is_none();
            if ready && (s.ur.loaded_program.is_some() || s.program_uploads > 0) {
                s.program = ProgramState::Playing;
                reply::STARTING_PROGRAM.into()
            } else {
                reply::PLAY_FAILED.into()
            }
        }
        Command::Stop if s.program != ProgramState::Stopped => {
            s.program = ProgramState::Stopped;
            reply::STOPPED.into()
        }
        Command::Stop => reply::STOP_FAILED.into(),
        Command::Pause if s.program == ProgramState::Playing => {
            s.program = ProgramState::Paused;
            reply::PAUSING.into()
        }
        Command::Pause => reply::PAUSE_FAILED.into(),
        Command::Load(file) if file.ends_with(".urp") => {
            s.ur.loaded_program = Some(file.clone());
            // The one program a `.urp` stands for: the follow program.
            s.program_source = None;
            s.program = ProgramState::Stopped;
            loading(file)
        }
        Command::Load(file) => file_not_found(file),
        Command::SafetyStatus => safety(s).reply(),
        Command::SafetyMode => format!("Safetymode: {}", safety(s).name()),
        Command::PolyscopeVersion => s.ur.polyscope_version.clone(),
        Command::CloseSafetyPopup => reply::CLOSING_SAFETY_POPUP.into(),
        // The virtual controller shows no popups (a program's go to its log) and keeps its log in
        // memory (`DeviceState::program_log`): nothing to close or to save.
        Command::ClosePopup => reply::CLOSING_POPUP.into(),
        Command::SaveLog => reply::LOG_SAVED.into(),
        Command::UnlockProtectiveStop => match s.ur.protective_stop_at {
            Some(at) if s.protective_stop.is_some() && now_s - at < UNLOCK_DELAY_S => {
                reply::PROTECTIVE_STOP_TOO_SOON.into()
            }
            _ => {
                s.protective_stop = None;
                s.ur.protective_stop_at = None;
                reply::PROTECTIVE_STOP_RELEASING.into()
            }
        },
        // Ours: a UR serial number is digits (year, model, number); ur_rtde checks only that.
        Command::GetSerialNumber if s.ur.has_remote_control() => "20215500001".into(),
        Command::GetSerialNumber => not_understood("get serial number"),
        Command::GetRobotModel => "UR5".into(),
        Command::Quit => return (reply::DISCONNECTED.into(), true),
        Command::Unknown(text) => not_understood(text),
    };
    (text, false)
}

fn safety(s: &DeviceState) -> SafetyStatus {
    if s.protective_stop.is_some() { SafetyStatus::ProtectiveStop } else { SafetyStatus::Normal }
}
