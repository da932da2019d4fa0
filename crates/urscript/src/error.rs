//! [`ScriptError`]: an error in a program, with its line.

/// An error in a program: where and what. Line 0 means no single line (a motion that fails
/// between calls, such as a `movel` through an unreachable pose).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ScriptError {
    /// Line number, 1-based (0: not tied to a line).
    pub line: u32,
    /// What is wrong.
    pub message: String,
}

impl std::fmt::Display for ScriptError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.line > 0 { write!(f, "line {}: {}", self.line, self.message) } else { write!(f, "{}", self.message) }
    }
}

impl std::error::Error for ScriptError {}
