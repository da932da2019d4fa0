//! What the interpreter needs of the controller it runs in ([`Controller`]).

use crate::watchdog::RtdeWatchdog;

/// What the interpreter needs from the controller around it: RTDE registers and IO, the measured
/// arm, a log, and the program's sockets. Register indices are checked before these are called
/// (0..47 for ints and floats, 0..127 for booleans).
///
/// Sockets: the interpreter does no I/O. A controller that has a network opens and serves the
/// program's sockets ([`Controller::socket_open`] starts a connection and returns at once; the
/// interpreter parks the calling thread and asks [`Controller::socket_state`] each cycle), so a
/// thread waiting on a socket never holds up the others. A controller without one keeps the
/// default methods, which refuse.
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
    /// Measured joint speeds \[rad/s\].
    fn actual_qd(&self) -> [f64; 6];
    /// The wrench the wrist's force/torque sensor measures on the tool, in the base frame, before
    /// the program's `zero_ftsensor` offset \[N, N·m\].
    fn actual_tcp_force(&self) -> [f64; 6];
    /// RTDE input packages received so far (see [`super::motion`] on `servoj`).
    fn input_packages(&self) -> u64;
    /// `rtde_set_watchdog` was called.
    fn set_watchdog(&mut self, watchdog: RtdeWatchdog);
    /// A `textmsg`, `popup` or runtime error line for the log.
    fn message(&mut self, text: &str);

    /// `socket_open(host, port, name)`: starts connecting socket `name` (closing one of that name
    /// first). An `Err` refuses the call (a host the controller may not reach, too many sockets):
    /// the program stops with the reason.
    fn socket_open(&mut self, name: &str, host: &str, port: u16) -> Result<(), String> {
        let _ = (name, port);
        Err(format!("socket_open: this controller has no network to reach {host}"))
    }
    /// Where socket `name` stands.
    fn socket_state(&self, name: &str) -> SocketState {
        let _ = name;
        SocketState::Closed
    }
    /// Exactly `n` bytes from socket `name`, oldest first, if that many have arrived (else none
    /// are taken).
    fn socket_read(&mut self, name: &str, n: usize) -> Option<Vec<u8>> {
        let _ = (name, n);
        None
    }
    /// Queues `bytes` on socket `name`; false if it is not open.
    fn socket_send(&mut self, name: &str, bytes: &[u8]) -> bool {
        let _ = (name, bytes);
        false
    }
    /// Closes socket `name` (nothing if it is not open).
    fn socket_close(&mut self, name: &str) {
        let _ = name;
    }
}

/// Where a program's socket stands.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum SocketState {
    /// Being connected.
    Connecting,
    /// Connected.
    Open,
    /// The connection failed (refused, timed out): why.
    Failed(String),
    /// Not open: never opened, closed by the program or by the peer.
    Closed,
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
