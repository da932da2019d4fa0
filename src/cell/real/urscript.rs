//! The URScript program the real path sends to the controller's secondary interface (TCP 30002).
//!
//! The program (`urscript/follow.script`, written by this project) loops forever:
//! - `input_int_register_24` = 1: read the six joint targets from `input_double_register_24..29`
//!   \[rad\] and `servoj` to them over 2 ms (one RTDE period at 500 Hz), `output_int_register_24` = 1;
//! - anything else: `stopj(2.0)` (2 rad/s² deceleration), `output_int_register_24` = 0.
//!
//! From the first enabled target on, `rtde_set_watchdog("input_int_register_24", 2, "stop")`
//! (URScript manual: `rtde_set_watchdog(variable_name, min_frequency, action="pause")`, actions
//! "ignore", "pause", "stop") makes the controller stop the program, and so the arm, when the
//! client writes no package with the enable register for more than 0.5 s (it writes one every
//! control tick, about 100 Hz). Armed only once enabled, because our client uploads the program
//! at configure and streams targets only from the first tick on. Why 2 Hz and not faster: the
//! client's own watchdogs stop a run on a 10 ms stall already (`RealCell`), so this one is only the
//! backstop for a client that died, whose last target is at most one tick's step ahead of the arm;
//! and the real-time tests tolerate 250 ms stalls of a shared machine (`LOOSE_WATCHDOG_S`), which a
//! 10 Hz watchdog would turn into stopped runs.
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

/// What the controller does when a watched RTDE input is not updated in time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WatchdogAction {
    /// Nothing.
    Ignore,
    /// Pause the program (the arm stops; the program can be resumed).
    Pause,
    /// Stop the program (the arm stops).
    Stop,
}

/// An `rtde_set_watchdog(variable_name, min_frequency, action)` call found in a program.
#[derive(Debug, Clone, PartialEq)]
pub struct RtdeWatchdog {
    /// The RTDE input watched, e.g. `input_int_register_24`.
    pub variable: String,
    /// Lowest update rate accepted \[Hz\]: the timeout is its inverse.
    pub min_frequency_hz: f64,
    /// What happens on a timeout.
    pub action: WatchdogAction,
}

/// The program's `rtde_set_watchdog` call, if any (comments skipped); an error names what is
/// wrong with a malformed call (a real controller would fail the program at that line).
pub fn find_watchdog(text: &str) -> Result<Option<RtdeWatchdog>, String> {
    const CALL: &str = "rtde_set_watchdog(";
    for line in text.lines() {
        let code = line.split('#').next().unwrap_or("").trim();
        let Some(start) = code.find(CALL) else { continue };
        let rest = &code[start + CALL.len()..];
        let args = rest.rsplit_once(')').map(|(a, _)| a).ok_or_else(|| format!("unclosed call: {code}"))?;
        let parts: Vec<&str> = args.split(',').map(str::trim).collect();
        let unquote = |s: &str| -> Option<String> {
            let s = s.strip_prefix('"').and_then(|s| s.strip_suffix('"'))?;
            Some(s.to_string())
        };
        let (variable, frequency, action) = match parts.as_slice() {
            [v, f] => (*v, *f, "\"pause\""),
            [v, f, a] => (*v, *f, a.strip_prefix("action=").unwrap_or(a).trim()),
            _ => return Err(format!("rtde_set_watchdog takes 2 or 3 arguments: {code}")),
        };
        let variable = unquote(variable).ok_or_else(|| format!("variable name must be a string: {code}"))?;
        let min_frequency_hz: f64 = frequency.parse().map_err(|_| format!("min_frequency must be a number: {code}"))?;
        if !(min_frequency_hz.is_finite() && min_frequency_hz > 0.0) {
            return Err(format!("min_frequency must be positive: {code}"));
        }
        let action = match unquote(action).map(|a| a.to_ascii_lowercase()).as_deref() {
            Some("ignore") => WatchdogAction::Ignore,
            Some("pause") => WatchdogAction::Pause,
            Some("stop") => WatchdogAction::Stop,
            _ => return Err(format!("action must be \"ignore\", \"pause\" or \"stop\": {code}")),
        };
        return Ok(Some(RtdeWatchdog { variable, min_frequency_hz, action }));
    }
    Ok(None)
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

    #[test]
    fn the_follow_program_sets_a_2_hz_stop_watchdog_on_the_enable_register() {
        let w = find_watchdog(FOLLOW_SCRIPT).unwrap().unwrap();
        assert_eq!(w.variable, format!("input_int_register_{ENABLE_REGISTER}"));
        assert_eq!(w.min_frequency_hz, 2.0);
        assert_eq!(w.action, WatchdogAction::Stop);
    }

    #[test]
    fn watchdog_calls_are_parsed_as_the_manual_defines_them() {
        let w = |s: &str| find_watchdog(&format!("def f():\n  {s}\nend\n"));
        assert_eq!(w("sync()").unwrap(), None);
        assert_eq!(w("# rtde_set_watchdog(\"x\", 1)").unwrap(), None);
        let p = w("rtde_set_watchdog(\"speed_slider_mask\", 2.5)").unwrap().unwrap();
        assert_eq!((p.min_frequency_hz, p.action), (2.5, WatchdogAction::Pause), "pause is the default");
        assert_eq!(
            w("rtde_set_watchdog(\"a\", 1, action=\"IGNORE\")").unwrap().unwrap().action,
            WatchdogAction::Ignore
        );
        for bad in [
            "rtde_set_watchdog(a, 1)",
            "rtde_set_watchdog(\"a\", 0)",
            "rtde_set_watchdog(\"a\", x)",
            "rtde_set_watchdog(\"a\", 1, \"halt\")",
            "rtde_set_watchdog(\"a\")",
            "rtde_set_watchdog(\"a\", 1",
        ] {
            assert!(w(bad).is_err(), "{bad}");
        }
    }
}
