//! The robot messages the virtual controller sends on its primary interface (30001): a program
//! started or stopped (key messages `PROGRAM_XXX_STARTED` / `PROGRAM_XXX_STOPPED` with the
//! program's name), a runtime exception with its line, the program's `textmsg` lines. Each
//! primary connection sends every message after the last it sent; the newest [`KEPT`] are kept.

use std::collections::VecDeque;
use tendril_rtde::primary::message::source;
use tendril_rtde::primary::{Message, RobotMessage};

/// Messages kept for connections that have not sent them yet.
pub const KEPT: usize = 1000;

/// Title of the key message when a program starts.
pub const PROGRAM_STARTED: &str = "PROGRAM_XXX_STARTED";
/// Title of the key message when a program stops.
pub const PROGRAM_STOPPED: &str = "PROGRAM_XXX_STOPPED";

/// The messages, numbered from 1.
#[derive(Debug, Default)]
pub struct RobotMessages {
    log: VecDeque<(u64, Message)>,
    last: u64,
}

impl RobotMessages {
    /// Adds a message at twin time `now_s` \[s\].
    pub fn push(&mut self, now_s: f64, source: i8, body: RobotMessage) {
        if self.log.len() >= KEPT {
            self.log.pop_front();
        }
        self.last += 1;
        let timestamp = (now_s.max(0.0) * 1e6) as u64;
        self.log.push_back((self.last, Message { timestamp, source, body }));
    }

    /// A key message (`PROGRAM_XXX_STARTED`, ...) with `text`.
    pub fn key(&mut self, now_s: f64, title: &str, text: &str) {
        let body = RobotMessage::Key { code: 0, argument: 0, title: title.into(), text: text.into() };
        self.push(now_s, source::ROBOT_INTERFACE, body);
    }

    /// The number of the newest message (0: none yet).
    pub fn last(&self) -> u64 {
        self.last
    }

    /// The messages after number `after`, with their numbers.
    pub fn since(&self, after: u64) -> Vec<(u64, Message)> {
        self.log.iter().filter(|(n, _)| *n > after).cloned().collect()
    }
}
