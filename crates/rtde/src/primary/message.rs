//! Robot messages (message type 20): `u64 timestamp`, `i8 source`, `u8 message type`, then the
//! message's fields, as UR's "Client Interfaces" document gives them for PolyScope 5 and as UR's
//! C++ client library parses them. Strings at the end of a message run to its end; a string inside
//! one has a length byte before it.

use super::error::PrimaryError;
use super::wire::{Reader, Writer};

/// Robot message type bytes.
pub mod kind {
    /// Text message.
    pub const TEXT: u8 = 0;
    /// Program label.
    pub const PROGRAM_LABEL: u8 = 1;
    /// Popup.
    pub const POPUP: u8 = 2;
    /// Version message (the first package on every connection).
    pub const VERSION: u8 = 3;
    /// Safety mode change.
    pub const SAFETY_MODE: u8 = 5;
    /// Error code ("robot comm") message.
    pub const ERROR_CODE: u8 = 6;
    /// Key message (program started, stopped, ...).
    pub const KEY: u8 = 7;
    /// Runtime exception of a program.
    pub const RUNTIME_EXCEPTION: u8 = 10;
}

/// Message sources UR lists (a subset).
pub mod source {
    /// The robot interface (the controller's interpreter side).
    pub const ROBOT_INTERFACE: i8 = -2;
    /// The real-time machine (program runtime).
    pub const RT_MACHINE: i8 = -3;
    /// The controller.
    pub const CONTROLLER: i8 = 7;
}

/// Report levels of error code messages.
pub mod report_level {
    /// Debug.
    pub const DEBUG: i32 = 0;
    /// Info.
    pub const INFO: i32 = 1;
    /// Warning.
    pub const WARNING: i32 = 2;
    /// Violation.
    pub const VIOLATION: i32 = 3;
    /// Fault.
    pub const FAULT: i32 = 4;
}

/// The version message's fields.
#[derive(Debug, Clone, PartialEq)]
pub struct Version {
    /// "URControl".
    pub project_name: String,
    /// Major version (5 on e-Series).
    pub major: u8,
    /// Minor version.
    pub minor: u8,
    /// Bugfix version.
    pub bugfix: i32,
    /// Build number.
    pub build: i32,
    /// Build date text.
    pub build_date: String,
}

/// What a robot message says.
#[derive(Debug, Clone, PartialEq)]
pub enum RobotMessage {
    /// Type 0: text.
    Text(String),
    /// Type 1: a program label reached.
    ProgramLabel {
        /// Label id.
        id: i32,
        /// Label text.
        text: String,
    },
    /// Type 2: a popup.
    Popup {
        /// Request id.
        request_id: u32,
        /// Requested type (8: a plain popup, no value asked).
        requested_type: u32,
        /// Shown as a warning.
        warning: bool,
        /// Shown as an error.
        error: bool,
        /// The program waits for the user.
        blocking: bool,
        /// Title (at most 255 bytes).
        title: String,
        /// Text.
        text: String,
    },
    /// Type 3: the controller's version.
    Version(Version),
    /// Type 5: the safety mode changed.
    SafetyMode {
        /// Code.
        code: i32,
        /// Argument.
        argument: i32,
        /// The new safety mode (1 normal, 3 protective stop, ...).
        mode: u8,
        /// Type of `data`.
        data_type: u32,
        /// Report data.
        data: u32,
    },
    /// Type 6: an error code.
    ErrorCode {
        /// Code (C...).
        code: i32,
        /// Argument (A...).
        argument: i32,
        /// Report level ([`report_level`]).
        level: i32,
        /// Type of `data`.
        data_type: u32,
        /// Data.
        data: u32,
        /// Text.
        text: String,
    },
    /// Type 7: a key message (`PROGRAM_XXX_STARTED` and `PROGRAM_XXX_STOPPED` with the program's
    /// name as text, ...).
    Key {
        /// Code.
        code: i32,
        /// Argument.
        argument: i32,
        /// Title (at most 255 bytes).
        title: String,
        /// Text.
        text: String,
    },
    /// Type 10: a program's runtime exception at a line and column.
    RuntimeException {
        /// Line (1-based).
        line: i32,
        /// Column (1-based; 0 when not known).
        column: i32,
        /// Text.
        text: String,
    },
    /// A message type not modelled: its type byte and body as received.
    Other {
        /// Type byte.
        kind: u8,
        /// Body after the type byte.
        body: Vec<u8>,
    },
}

/// A robot message with its header fields.
#[derive(Debug, Clone, PartialEq)]
pub struct Message {
    /// Controller time (microseconds of twin time in ours).
    pub timestamp: u64,
    /// Source ([`source`]).
    pub source: i8,
    /// What it says.
    pub body: RobotMessage,
}

fn short_text(w: &mut Writer, text: &str) -> Result<(), PrimaryError> {
    let len = u8::try_from(text.len()).map_err(|_| PrimaryError::TooLong(text.len()))?;
    w.u8(len).bytes(text.as_bytes());
    Ok(())
}

fn read_short_text(r: &mut Reader<'_>) -> Result<String, PrimaryError> {
    let n = usize::from(r.u8()?);
    Ok(String::from_utf8_lossy(r.bytes(n)?).into_owned())
}

impl Message {
    /// The message type byte.
    pub fn kind(&self) -> u8 {
        match &self.body {
            RobotMessage::Text(_) => kind::TEXT,
            RobotMessage::ProgramLabel { .. } => kind::PROGRAM_LABEL,
            RobotMessage::Popup { .. } => kind::POPUP,
            RobotMessage::Version(_) => kind::VERSION,
            RobotMessage::SafetyMode { .. } => kind::SAFETY_MODE,
            RobotMessage::ErrorCode { .. } => kind::ERROR_CODE,
            RobotMessage::Key { .. } => kind::KEY,
            RobotMessage::RuntimeException { .. } => kind::RUNTIME_EXCEPTION,
            RobotMessage::Other { kind, .. } => *kind,
        }
    }

    /// The message body after the package header (timestamp onwards); an error if a title or
    /// project name does not fit its length byte.
    pub(crate) fn encode_body(&self) -> Result<Vec<u8>, PrimaryError> {
        let mut w = Writer::default();
        w.u64(self.timestamp).i8(self.source).u8(self.kind());
        match &self.body {
            RobotMessage::Text(text) => {
                w.bytes(text.as_bytes());
            }
            RobotMessage::ProgramLabel { id, text } => {
                w.i32(*id).bytes(text.as_bytes());
            }
            RobotMessage::Popup { request_id, requested_type, warning, error, blocking, title, text } => {
                w.u32(*request_id).u32(*requested_type).bool(*warning).bool(*error).bool(*blocking);
                short_text(&mut w, title)?;
                w.bytes(text.as_bytes());
            }
            RobotMessage::Version(v) => {
                let len =
                    i8::try_from(v.project_name.len()).map_err(|_| PrimaryError::TooLong(v.project_name.len()))?;
                w.i8(len)
                    .bytes(v.project_name.as_bytes())
                    .u8(v.major)
                    .u8(v.minor)
                    .i32(v.bugfix)
                    .i32(v.build)
                    .bytes(v.build_date.as_bytes());
            }
            RobotMessage::SafetyMode { code, argument, mode, data_type, data } => {
                w.i32(*code).i32(*argument).u8(*mode).u32(*data_type).u32(*data);
            }
            RobotMessage::ErrorCode { code, argument, level, data_type, data, text } => {
                w.i32(*code).i32(*argument).i32(*level).u32(*data_type).u32(*data).bytes(text.as_bytes());
            }
            RobotMessage::Key { code, argument, title, text } => {
                w.i32(*code).i32(*argument);
                short_text(&mut w, title)?;
                w.bytes(text.as_bytes());
            }
            RobotMessage::RuntimeException { line, column, text } => {
                w.i32(*line).i32(*column).bytes(text.as_bytes());
            }
            RobotMessage::Other { body, .. } => {
                w.bytes(body);
            }
        }
        Ok(w.0)
    }

    /// Decodes a message body (timestamp onwards).
    pub(crate) fn decode_body(body: &[u8]) -> Result<Message, PrimaryError> {
        let mut r = Reader(body);
        let r = &mut r;
        let timestamp = r.u64()?;
        let source = r.i8()?;
        let kind = r.u8()?;
        let body = match kind {
            kind::TEXT => RobotMessage::Text(r.rest_text()),
            kind::PROGRAM_LABEL => RobotMessage::ProgramLabel { id: r.i32()?, text: r.rest_text() },
            kind::POPUP => RobotMessage::Popup {
                request_id: r.u32()?,
                requested_type: r.u32()?,
                warning: r.bool()?,
                error: r.bool()?,
                blocking: r.bool()?,
                title: read_short_text(r)?,
                text: r.rest_text(),
            },
            kind::VERSION => {
                let n = usize::try_from(r.i8()?).map_err(|_| PrimaryError::BadLength)?;
                let project_name = String::from_utf8_lossy(r.bytes(n)?).into_owned();
                RobotMessage::Version(Version {
                    project_name,
                    major: r.u8()?,
                    minor: r.u8()?,
                    bugfix: r.i32()?,
                    build: r.i32()?,
                    build_date: r.rest_text(),
                })
            }
            kind::SAFETY_MODE => RobotMessage::SafetyMode {
                code: r.i32()?,
                argument: r.i32()?,
                mode: r.u8()?,
                data_type: r.u32()?,
                data: r.u32()?,
            },
            kind::ERROR_CODE => RobotMessage::ErrorCode {
                code: r.i32()?,
                argument: r.i32()?,
                level: r.i32()?,
                data_type: r.u32()?,
                data: r.u32()?,
                text: r.rest_text(),
            },
            kind::KEY => RobotMessage::Key {
                code: r.i32()?,
                argument: r.i32()?,
                title: read_short_text(r)?,
                text: r.rest_text(),
            },
            kind::RUNTIME_EXCEPTION => {
                RobotMessage::RuntimeException { line: r.i32()?, column: r.i32()?, text: r.rest_text() }
            }
            other => RobotMessage::Other { kind: other, body: r.bytes(r.0.len())?.to_vec() },
        };
        Ok(Message { timestamp, source, body })
    }
}
