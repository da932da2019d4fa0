//! What a client sends to the controller's script ports (primary 30001, secondary 30002,
//! real-time 30003), split into what the controller does with it, sans-IO: feed bytes, take
//! [`ScriptEvent`]s.
//!
//! - A program: `def name(): ... end` (replaces the running program) or `sec name(): ... end` (a
//!   secondary program, run beside it), taken as soon as its last `end` arrives: blocks are
//!   counted line by line (`def`, `sec`, `thread`, `if`, `while`, `for` open one, `end` closes
//!   it), so a program split over many TCP segments is whole when taken.
//! - A controller command on a line of its own, as UR's client library sends them: `stop
//!   program`, `power on`, `power off`, `set robotmode run` (brake release), `set unlock protective
//!   stop`.
//! - Any other line: URScript to run on its own, as the controller runs a line sent without a
//!   `def` (`movej([...])` moves the arm); it becomes a one-line program.

/// A controller command sent as a line of text.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ControllerCommand {
    /// `stop program`.
    StopProgram,
    /// `power on`.
    PowerOn,
    /// `power off`.
    PowerOff,
    /// `set robotmode run`: release the brakes.
    BrakeRelease,
    /// `set unlock protective stop`.
    UnlockProtectiveStop,
}

impl ControllerCommand {
    fn parse(line: &str) -> Option<ControllerCommand> {
        Some(match line {
            "stop program" => ControllerCommand::StopProgram,
            "power on" => ControllerCommand::PowerOn,
            "power off" => ControllerCommand::PowerOff,
            "set robotmode run" => ControllerCommand::BrakeRelease,
            "set unlock protective stop" => ControllerCommand::UnlockProtectiveStop,
            _ => return None,
        })
    }
}

/// What the controller received.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ScriptEvent {
    /// A program's text (`def` or `sec`, or a single line wrapped as `def unnamed():`).
    Program(String),
    /// A controller command.
    Command(ControllerCommand),
    /// More than [`MAX_PROGRAM_LEN`] bytes without a complete program: dropped (the stream has
    /// lost its place; the port closes the connection).
    TooLong,
}

/// Largest program taken \[bytes\] (1 MiB; UR's external control script is 50 kB, SDU ur_rtde's
/// 40 kB).
pub const MAX_PROGRAM_LEN: usize = 1 << 20;

/// Name of the program a single line becomes.
pub const ONE_LINE_PROGRAM: &str = "unnamed";

/// Splits a script port's byte stream.
#[derive(Debug, Default)]
pub struct ScriptStream {
    /// Bytes after the last complete line.
    partial: Vec<u8>,
    /// The program being received, and how many blocks are open in it.
    block: Option<(String, usize)>,
}

/// The first word of a line, comments and indentation aside.
fn first_word(line: &str) -> &str {
    let t = line.trim_start();
    let end = t.find(|c: char| !(c.is_alphanumeric() || c == '_')).unwrap_or(t.len());
    &t[..end]
}

impl ScriptStream {
    /// A stream with nothing received.
    pub fn new() -> ScriptStream {
        ScriptStream::default()
    }

    /// Whether a program has started arriving and is not complete.
    pub fn in_program(&self) -> bool {
        self.block.is_some() || !self.partial.is_empty()
    }

    /// Whether what is pending would complete something if no more came: a line without its line
    /// end that is a whole line on its own (outside a program), or the last `end` of a program.
    /// A port flushes such a tail soon; anything else may be a client pausing mid-program.
    pub fn tail_completes(&self) -> bool {
        let tail = String::from_utf8_lossy(&self.partial);
        match &self.block {
            None => !tail.trim().is_empty(),
            Some((_, depth)) => *depth == 1 && first_word(&tail) == "end",
        }
    }

    /// Takes `bytes` and returns what they completed.
    pub fn feed(&mut self, bytes: &[u8]) -> Vec<ScriptEvent> {
        self.partial.extend_from_slice(bytes);
        let mut events = Vec::new();
        while let Some(end) = self.partial.iter().position(|&b| b == b'\n') {
            let line: Vec<u8> = self.partial.drain(..=end).collect();
            let line = String::from_utf8_lossy(&line[..end]).into_owned();
            self.line(line, &mut events);
        }
        let pending = self.partial.len() + self.block.as_ref().map_or(0, |(t, _)| t.len());
        if pending > MAX_PROGRAM_LEN {
            *self = ScriptStream::default();
            events.push(ScriptEvent::TooLong);
        }
        events
    }

    /// The client went quiet (or left) with a line or a program unfinished: takes it as it is
    /// (a program missing its `end` then fails to parse, with the controller's syntax error).
    pub fn flush(&mut self) -> Vec<ScriptEvent> {
        let mut events = Vec::new();
        if !self.partial.is_empty() {
            let line = String::from_utf8_lossy(&std::mem::take(&mut self.partial)).into_owned();
            self.line(line, &mut events);
        }
        if let Some((text, _)) = self.block.take() {
            events.push(ScriptEvent::Program(text));
        }
        events
    }

    fn line(&mut self, line: String, events: &mut Vec<ScriptEvent>) {
        let line = line.trim_end_matches('\r');
        let word = first_word(line);
        match &mut self.block {
            Some((text, depth)) => {
                text.push_str(line);
                text.push('\n');
                match word {
                    "def" | "sec" | "thread" | "if" | "while" | "for" => *depth += 1,
                    "end" => *depth -= 1,
                    _ => {}
                }
                if *depth == 0 {
                    let (text, _) = self.block.take().expect("matched Some");
                    events.push(ScriptEvent::Program(text));
                }
            }
            None => {
                let trimmed = line.trim();
                if trimmed.is_empty() || trimmed.starts_with('#') {
                } else if word == "def" || word == "sec" {
                    self.block = Some((format!("{line}\n"), 1));
                } else if let Some(command) = ControllerCommand::parse(trimmed) {
                    events.push(ScriptEvent::Command(command));
                } else {
                    events.push(ScriptEvent::Program(format!("def {ONE_LINE_PROGRAM}():\n  {trimmed}\nend\n")));
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_program_split_anywhere_is_taken_whole_when_its_last_end_arrives() {
        let program = "def p():\n  thread t():\n    while True:\n      sync()\n    end\n  end\n  if x:\n    y = 1\n  elif z:\n    y = 2\n  end\nend\n";
        for cut in 0..program.len() {
            let mut s = ScriptStream::new();
            let mut events = s.feed(&program.as_bytes()[..cut]);
            assert!(events.is_empty(), "cut at {cut}: {events:?}");
            events = s.feed(&program.as_bytes()[cut..]);
            assert_eq!(events, [ScriptEvent::Program(program.into())], "cut at {cut}");
            assert!(!s.in_program());
        }
    }

    #[test]
    fn the_client_librarys_commands_and_headless_program_are_told_apart() {
        // What UR's client library sends in headless mode: `stop program`, then the program.
        let mut s = ScriptStream::new();
        let events = s.feed(b"stop program\ndef externalControl():\n\ttextmsg(\"x\")\nend\n\n");
        assert_eq!(
            events,
            [
                ScriptEvent::Command(ControllerCommand::StopProgram),
                ScriptEvent::Program("def externalControl():\n\ttextmsg(\"x\")\nend\n".into())
            ]
        );
        for (line, command) in [
            ("power on", ControllerCommand::PowerOn),
            ("power off", ControllerCommand::PowerOff),
            ("set robotmode run", ControllerCommand::BrakeRelease),
            ("set unlock protective stop", ControllerCommand::UnlockProtectiveStop),
        ] {
            assert_eq!(s.feed(format!("{line}\n").as_bytes()), [ScriptEvent::Command(command)]);
        }
        // A secondary program, and a line of URScript on its own.
        assert_eq!(
            s.feed(b"sec s():\n  textmsg(1)\nend\n"),
            [ScriptEvent::Program("sec s():\n  textmsg(1)\nend\n".into())]
        );
        assert_eq!(
            s.feed(b"movej([0,0,0,0,0,0])\n"),
            [ScriptEvent::Program("def unnamed():\n  movej([0,0,0,0,0,0])\nend\n".into())]
        );
        // Comments and blank lines are nothing.
        assert!(s.feed(b"# a comment\n\n   \n").is_empty());
    }

    #[test]
    fn an_unfinished_program_is_flushed_and_an_endless_one_dropped() {
        let mut s = ScriptStream::new();
        assert!(s.feed(b"def p():\n  x = 1\n").is_empty());
        assert!(s.in_program() && !s.tail_completes());
        assert!(s.feed(b"en").is_empty() && !s.tail_completes(), "`en` is not `end`");
        assert!(s.feed(b"d").is_empty() && s.tail_completes(), "a last `end` without its line end");
        assert_eq!(s.flush(), [ScriptEvent::Program("def p():\n  x = 1\nend\n".into())]);
        assert!(!s.in_program());
        let mut s = ScriptStream::new();
        s.feed(b"def p():\n");
        let line = format!("  x = \"{}\"\n", "a".repeat(1000));
        let mut events = Vec::new();
        for _ in 0..1100 {
            events = s.feed(line.as_bytes());
            if !events.is_empty() {
                break;
            }
        }
        // The client is then cut off (the stream has lost its place in the program).
        assert_eq!(events, [ScriptEvent::TooLong]);
        assert!(!s.in_program());
    }
}
