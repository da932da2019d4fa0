//! What the interpreter needs of the controller it runs in ([`Controller`]).

use crate::watchdog::RtdeWatchdog;

/// What the interpreter needs from the controller around it: RTDE registers and IO, the measured
/// arm, and a log. Register indices are checked before these are called (0..47 for ints and
/// floats, 0..127 for booleans).
pub trait Controller {
    /// `input_int_register_<i>`.
    fn input_int(&self, i: usize) -> i32;
    /// `input_double_register_<i>`.
    fn input_float(&self, i: usize) -> f64;
    /// `input_bit_register_<i>`.
    fn input_bool(&self, i: usize) -> bool;
    /// Sets `output_int_register_<i>`.
    fn set_output_int(&mut self, i: usize, v: i32);
    /// Sets `output_double_register_<i>`.
    fn set_output_float(&mut self, i: usize, v: f64);
    /// Sets `output_bit_register_<i>`.
    fn set_output_bool(&mut self, i: usize, v: bool);
    /// Sets a digital output: standard (0..7), configurable (0..7) or tool (0..1).
    fn set_digital_out(&mut self, kind: DigitalOut, i: usize, v: bool);
    /// Sets standard analog output `i` (0..1) as a fraction of its range.
    fn set_analog_out(&mut self, i: usize, v: f64);
    /// Measured joint angles \[rad\].
    fn actual_q(&self) -> [f64; 6];
    /// RTDE input packages received so far (see [`super::motion`] on `servoj`).
    fn input_packages(&self) -> u64;
    /// `rtde_set_watchdog` was called.
    fn set_watchdog(&mut self, watchdog: RtdeWatchdog);
    /// A `textmsg`, `popup` or runtime error line for the log.
    fn message(&mut self, text: &str);
}

/// Which bank a digital output is in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DigitalOut {
    /// Control box DO0..DO7.
    Standard,
    /// Configurable CO0..CO7.
    Configurable,
    /// Tool TO0..TO1.
    Tool,
}
