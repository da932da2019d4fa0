//! The URScript program the real path sends to the controller's secondary interface (TCP 30002).
//!
//! The program (`urscript/follow.script`, written by this project) loops forever:
//! - `input_int_register_24` = 1: read the six joint targets from `input_double_register_24..29`
//!   \[rad\] and `servoj` to them over 2 ms (one RTDE period at 500 Hz), `output_int_register_24` = 1;
//! - anything else: `stopj(2.0)` (2 rad/s² deceleration), `output_int_register_24` = 0.
//!
//! Registers 24..29 leave 0..23 free for SDU's `ur_rtde`, whose control script uses the lower half.
//! The client writes the targets and the enable flag in one RTDE input recipe, so a target and its
//! enable always arrive together; speed and acceleration limits are applied before (see
//! [`crate::cell::real::limits`]). The controller's own safety limits still apply on top.

/// The program text (newline-terminated `def ... end`, as the secondary interface expects).
pub const FOLLOW_SCRIPT: &str = include_str!("urscript/follow.script");

/// First input double register holding a joint target (six consecutive registers).
pub const TARGET_REGISTER: usize = 24;
/// Input int register holding the enable flag (1 follow, 0 stop).
pub const ENABLE_REGISTER: usize = 24;
/// Output int register the program sets to 1 while following.
pub const FOLLOWING_REGISTER: usize = 24;

/// RTDE input names in recipe order: six targets, then the enable flag.
pub fn input_names() -> Vec<String> {
    let mut names: Vec<String> = (0..6).map(|i| format!("input_double_register_{}", TARGET_REGISTER + i)).collect();
    names.push(format!("input_int_register_{ENABLE_REGISTER}"));
    names
}

/// Whether `text` looks like a complete program: a `def name():` line and a final `end`.
pub fn is_complete_program(text: &str) -> bool {
    let lines: Vec<&str> = text.lines().map(str::trim).filter(|l| !l.is_empty() && !l.starts_with('#')).collect();
    lines.first().is_some_and(|l| l.starts_with("def ") && l.ends_with("):")) && lines.last() == Some(&"end")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_script_is_a_complete_program_using_the_documented_registers() {
        assert!(is_complete_program(FOLLOW_SCRIPT));
        assert!(FOLLOW_SCRIPT.contains("read_input_integer_register(24)"));
        for i in 24..30 {
            assert!(FOLLOW_SCRIPT.contains(&format!("read_input_float_register({i})")));
        }
        assert!(!is_complete_program("def f():\n  stopj(1)\n"));
        assert_eq!(input_names().len(), 7);
    }
}
