//! The follow program in the interpreter: stamped targets on a ramp, some late and bunched, and
//! the setpoint it commands every 2 ms cycle: `cargo run -p tendril-urscript --example follow`.

use tendril_urscript::{
    Controller, DigitalOut, ENABLE_REGISTER, FOLLOW_SCRIPT, Interpreter, RtdeWatchdog, STAMP_REGISTER, TARGET_REGISTER,
};

/// The controller around the program: RTDE input registers written by "the client".
struct Host {
    in_int: [i32; 48],
    in_float: [f64; 48],
    packages: u64,
    q: [f64; 6],
}

impl Controller for Host {
    fn input_int(&self, i: usize) -> i32 {
        self.in_int[i]
    }
    fn input_float(&self, i: usize) -> f64 {
        self.in_float[i]
    }
    fn input_bool(&self, _: usize) -> bool {
        false
    }
    fn set_output_int(&mut self, _: usize, _: i32) {}
    fn set_output_float(&mut self, _: usize, _: f64) {}
    fn set_output_bool(&mut self, _: usize, _: bool) {}
    fn set_digital_out(&mut self, _: DigitalOut, _: usize, _: bool) {}
    fn set_analog_out(&mut self, _: usize, _: f64) {}
    fn actual_q(&self) -> [f64; 6] {
        self.q
    }
    fn actual_qd(&self) -> [f64; 6] {
        [0.0; 6]
    }
    fn actual_tcp_force(&self) -> [f64; 6] {
        [0.0; 6]
    }
    fn input_packages(&self) -> u64 {
        self.packages
    }
    fn set_watchdog(&mut self, _: RtdeWatchdog) {}
    fn message(&mut self, text: &str) {
        println!("program: {text}");
    }
}

fn main() {
    let mut p = Interpreter::new(FOLLOW_SCRIPT, [0.0; 6]).unwrap();
    let mut host = Host { in_int: [0; 48], in_float: [0.0; 48], packages: 0, q: [0.0; 6] };
    host.in_int[ENABLE_REGISTER] = 1;
    // A 100 Hz client's targets on a 0.5 rad/s ramp; every third one arrives 7 cycles late.
    let late = |k: usize| if k % 3 == 1 { 7 } else { 0 };
    let mut delivered = 0;
    for cycle in 0..200 {
        while delivered < 30 && delivered * 5 + late(delivered) <= cycle {
            let t = delivered as f64 * 0.01;
            host.in_float[TARGET_REGISTER] = 0.5 * t;
            host.in_float[STAMP_REGISTER] = t;
            host.packages += 1;
            delivered += 1;
        }
        if let Some(q) = p.step(cycle as f64 * 0.002, &mut host) {
            if cycle % 10 == 0 {
                println!("cycle {cycle:3}: setpoint {:.4} rad ({delivered} targets arrived)", q[0]);
            }
            host.q = q;
        }
    }
}
