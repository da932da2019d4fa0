//! The follow program the real path uploads (`follow.script`), the RTDE registers it reads and
//! writes, and what makes a program text complete.

/// The program text (newline-terminated `def ... end`, as the secondary interface expects).
pub const FOLLOW_SCRIPT: &str = include_str!("follow.script");

/// First input double register holding a joint target (six consecutive registers).
pub const TARGET_REGISTER: usize = 24;
/// Input double register holding the target's time on the client's clock \[s\].
pub const STAMP_REGISTER: usize = 30;
/// Input int register holding the enable flag (1 follow, 0 stop).
pub const ENABLE_REGISTER: usize = 24;
/// Output int register the program sets to 1 while following.
pub const FOLLOWING_REGISTER: usize = 24;

/// RTDE input names in recipe order: six targets, their time, then the enable flag.
pub fn input_names() -> Vec<String> {
    let mut names: Vec<String> = (0..6).map(|i| format!("input_double_register_{}", TARGET_REGISTER + i)).collect();
    names.push(format!("input_double_register_{STAMP_REGISTER}"));
    names.push(format!("input_int_register_{ENABLE_REGISTER}"));
    names
}

/// Whether `text` looks like a complete program: a `def name():` line and a final `end`.
pub fn is_complete_program(text: &str) -> bool {
    let lines: Vec<&str> = text.lines().map(str::trim).filter(|l| !l.is_empty() && !l.starts_with('#')).collect();
    lines.first().is_some_and(|l| l.starts_with("def ") && l.ends_with("):")) && lines.last() == Some(&"end")
}
