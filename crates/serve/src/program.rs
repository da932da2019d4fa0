//! The virtual controller's program: the URScript interpreter run in the twin's time, its RTDE
//! watchdog, and the hand-over of its arm setpoints to the safety check.
//!
//! Life cycle ([`DeviceState::program`]): a complete program on 30002/30003 is parsed and plays
//! from its first line (a syntax error is logged and the program does not start); dashboard
//! `play` after `stop`, or after `load X.urp`, starts the current program afresh (a `.urp` is the
//! follow program, [`FOLLOW_SCRIPT`]); `pause` holds the interpreter, `play` resumes it. The program
//! ends when its body ends, on a runtime error (logged with its line), a protective stop, its
//! RTDE watchdog ("stop"), the dashboard's `stop` or the robot leaving RUNNING. When it ends the
//! output registers it wrote are cleared (our choice: a client polling `output_int_register_24`
//! then sees the program is not following).
//!
//! The interpreter runs one 2 ms controller cycle whenever the twin's clock has reached the next
//! cycle (the twin ticks every 1 ms by default), in twin time, so a twin held up by a busy
//! machine never makes a program see time pass that the arm did not.
//!
//! A secondary program (`sec`, from the script ports) runs at the next tick, beside whatever
//! plays, to its end in that tick (it may not consume time). The controller settings a program
//! makes (`set_tcp`, `set_payload`, ...) are the controller's ([`DeviceState::program_setup`]):
//! a main program starts from the defaults, a secondary one changes what the main one has. The
//! primary interface hears of each program's start and end (key messages), of a runtime or
//! syntax error (a runtime exception with its line), and of `textmsg` lines
//! ([`crate::robot_messages`]). When a program ends, its sockets are closed.

use super::robot_messages::{PROGRAM_STARTED, PROGRAM_STOPPED};
use super::state::{DeviceState, ProgramState};
use std::collections::VecDeque;
use tendril_rtde::dashboard::RobotMode;
use tendril_rtde::primary::RobotMessage;
use tendril_rtde::primary::message::source;
use tendril_urscript::interp::CONTROL_PERIOD_S;
use tendril_urscript::{
    Controller, DigitalOut, FOLLOW_SCRIPT, Interpreter, RtdeWatchdog, ScriptError, Setup, SocketState, Status,
    WatchdogAction,
};

/// Lines kept in [`DeviceState::program_log`].
pub const LOG_LINES: usize = 500;

/// What the arm should do this twin tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ArmCommand {
    /// Keep the last command.
    Keep,
    /// A `servoj` target: joint angles \[rad\] given by the program's cycle at twin time `at_s`
    /// \[s\]. The twin's arm passes through each target at a fixed delay after its cycle, moving
    /// linearly from one target to the next (see the twin's `ServoPath`), whatever its physics step.
    Servo {
        /// Target \[rad\].
        q: [f64; 6],
        /// The program cycle that gave it \[s\].
        at_s: f64,
    },
    /// Follow a generated trajectory: the setpoint `q` \[rad\] at twin time `at_s` \[s\] moving at
    /// `qd` \[rad/s\]. The twin commands the setpoint extrapolated to the end of each physics step:
    /// commanding every 2 ms cycle against 5 ms physics steps would move the arm by two cycles'
    /// way in some steps and three in others (`actual_qd` alternating between 0.8 and 1.2 times
    /// the speed).
    Track {
        /// Setpoint \[rad\].
        q: [f64; 6],
        /// Its speed \[rad/s\].
        qd: [f64; 6],
        /// Its time \[s\].
        at_s: f64,
    },
    /// Stop where the arm is (the program stopped or a protective stop).
    Hold,
}

/// The program runner the twin thread owns.
#[derive(Debug, Default)]
pub struct ProgramRunner {
    interpreter: Option<Interpreter>,
    uploads_seen: u64,
    /// The armed watchdog: variable, its write count and when that last changed (twin time).
    armed: Option<(String, u64, f64)>,
    next_cycle_s: f64,
}

/// The interpreter's view of the devices' state.
struct Host<'a> {
    s: &'a mut DeviceState,
    measured_q: [f64; 6],
    watchdog_set: bool,
    /// The program's cycle \[s\] (socket bytes are readable from the twin time they arrived).
    now_s: f64,
}

impl Controller for Host<'_> {
    fn input_int(&self, i: usize) -> i32 {
        self.s.program_inputs.values.int_registers[i]
    }
    fn input_float(&self, i: usize) -> f64 {
        self.s.program_inputs.values.double_registers[i]
    }
    fn input_bool(&self, i: usize) -> bool {
        self.s.program_inputs.values.bit_registers >> i & 1 == 1
    }
    fn set_output_int(&mut self, i: usize, v: i32) {
        self.s.outputs.int_registers[i] = v;
    }
    fn set_output_float(&mut self, i: usize, v: f64) {
        self.s.outputs.double_registers[i] = v;
    }
    fn set_output_bool(&mut self, i: usize, v: bool) {
        let bit = 1u128 << i;
        let bits = &mut self.s.outputs.bit_registers;
        *bits = if v { *bits | bit } else { *bits & !bit };
    }
    fn set_digital_out(&mut self, kind: DigitalOut, i: usize, v: bool) {
        super::io::set_digital_out(&mut self.s.outputs, kind, i, v);
    }
    fn set_analog_out(&mut self, i: usize, v: f64) {
        super::io::set_analog_out(&mut self.s.outputs, i, v);
    }
    fn actual_q(&self) -> [f64; 6] {
        self.measured_q
    }
    fn actual_qd(&self) -> [f64; 6] {
        self.s.outputs.actual_qd
    }
    fn actual_tcp_force(&self) -> [f64; 6] {
        self.s.tcp_force_raw
    }
    fn input_packages(&self) -> u64 {
        self.s.program_inputs.packages
    }
    fn set_watchdog(&mut self, watchdog: RtdeWatchdog) {
        self.s.watchdog = Some(watchdog);
        self.watchdog_set = true;
    }
    fn message(&mut self, text: &str) {
        log(&mut self.s.program_log, text);
        self.s.robot_messages.push(self.now_s, source::RT_MACHINE, RobotMessage::Text(text.to_string()));
    }
    fn socket_open(&mut self, name: &str, host: &str, port: u16) -> Result<(), String> {
        self.s.sockets.open(name, host, port, self.now_s)
    }
    fn socket_state(&self, name: &str) -> SocketState {
        self.s.sockets.state(name)
    }
    fn socket_read(&mut self, name: &str, n: usize) -> Option<Vec<u8>> {
        self.s.sockets.read(name, n, self.now_s)
    }
    fn socket_send(&mut self, name: &str, bytes: &[u8]) -> bool {
        self.s.sockets.send(name, bytes)
    }
    fn socket_close(&mut self, name: &str) {
        self.s.sockets.close(name);
    }
}

/// Reports the controller settings a program made: RTDE's `tcp_offset`, `payload*`,
/// `target_gravity`, `tool_output_voltage`, and (through [`DeviceState::program_setup`]) the
/// force sensor's zero and freedrive.
fn publish(s: &mut DeviceState, setup: &Setup) {
    let o = &mut s.outputs;
    o.tcp_offset = setup.tcp;
    o.payload_kg = setup.payload_kg;
    o.payload_cog = setup.payload_cog;
    o.payload_inertia = setup.payload_inertia;
    o.gravity = setup.gravity;
    o.tool_output_voltage = setup.tool_voltage;
    s.program_setup = setup.clone();
}

/// A program's error for the primary interface: a runtime exception at its line.
fn runtime_exception(s: &mut DeviceState, now_s: f64, e: &ScriptError) {
    let body = RobotMessage::RuntimeException { line: e.line as i32, column: 0, text: e.message.clone() };
    s.robot_messages.push(now_s, source::RT_MACHINE, body);
}

fn log(lines: &mut VecDeque<String>, text: &str) {
    if lines.len() >= LOG_LINES {
        lines.pop_front();
    }
    lines.push_back(text.to_string());
}

impl ProgramRunner {
    /// One twin tick at `now_s` \[s\] with the arm measured at `measured_q`: starts, steps, pauses
    /// or ends the program and returns what the arm should do.
    pub fn tick(&mut self, s: &mut DeviceState, now_s: f64, measured_q: [f64; 6]) -> ArmCommand {
        self.run_secondary(s, now_s, measured_q);
        let mut hold = false;
        // The program reads the RTDE packages that had arrived by now (see `arrival`).
        s.program_inputs.advance_to(now_s);
        // A new upload replaces the running program. The script port set it playing when it
        // arrived; a dashboard `pause`, `stop` or `power off` since then stands (setting it
        // playing here again, a tick late, restarted programs the dashboard had stopped).
        if s.program_uploads != self.uploads_seen {
            self.uploads_seen = s.program_uploads;
            self.end(s);
        }
        // Powered off or brakes engaged (dashboard): no program runs, the arm holds.
        if s.ur.robot_mode != RobotMode::Running && s.program != ProgramState::Stopped {
            s.program = ProgramState::Stopped;
            hold = true;
        }
        if s.program == ProgramState::Playing && self.interpreter.is_none() {
            self.start(s, now_s, measured_q);
        }
        hold |= self.check_watchdog(s, now_s);
        if s.program == ProgramState::Stopped {
            if self.interpreter.is_some() {
                self.end(s);
                hold = true;
            }
            return if hold { ArmCommand::Hold } else { ArmCommand::Keep };
        }
        if s.program == ProgramState::Paused || now_s + 1e-9 < self.next_cycle_s {
            return if hold { ArmCommand::Hold } else { ArmCommand::Keep };
        }
        let cycle_s = self.next_cycle_s;
        // A twin that fell behind by more than a cycle resumes the schedule from now.
        self.next_cycle_s = if cycle_s + CONTROL_PERIOD_S < now_s { now_s } else { cycle_s } + CONTROL_PERIOD_S;
        let Some(interpreter) = self.interpreter.as_mut() else { return ArmCommand::Keep };
        let mut host = Host { s, measured_q, watchdog_set: false, now_s: cycle_s };
        let command = interpreter.step(cycle_s, &mut host);
        let (servoing, qd) = (interpreter.servoing(), interpreter.target_qd());
        let watchdog_set = host.watchdog_set;
        let status = interpreter.status().clone();
        if interpreter.setup() != &s.program_setup {
            let setup = interpreter.setup().clone();
            publish(s, &setup);
        }
        if watchdog_set {
            self.arm_watchdog(s, now_s);
        }
        match status {
            Status::Running => {}
            Status::Finished => {
                log(&mut s.program_log, "program finished");
                s.program = ProgramState::Stopped;
                self.end(s);
                return ArmCommand::Keep;
            }
            Status::Failed(e) => {
                eprintln!("virtual UR5e: program stopped: {e}");
                runtime_exception(s, cycle_s, &e);
                s.program = ProgramState::Stopped;
                self.end(s);
                return ArmCommand::Hold;
            }
        }
        let Some(q) = command else { return ArmCommand::Keep };
        match tendril_ur5e::safety::violation(&q, &measured_q) {
            None if servoing => ArmCommand::Servo { q, at_s: cycle_s },
            None => ArmCommand::Track { q, qd, at_s: cycle_s },
            Some(why) => {
                // Protective stop: the arm stops where it is, the program stops.
                log(&mut s.program_log, &format!("protective stop: {why}"));
                s.protective_stop = Some(why);
                s.ur.protective_stop_at = Some(now_s);
                s.program = ProgramState::Stopped;
                self.end(s);
                ArmCommand::Hold
            }
        }
    }

    fn start(&mut self, s: &mut DeviceState, now_s: f64, measured_q: [f64; 6]) {
        let source = s.program_source.clone().unwrap_or_else(|| FOLLOW_SCRIPT.to_string());
        match Interpreter::new(&source, measured_q) {
            Ok(i) => {
                s.robot_messages.key(now_s, PROGRAM_STARTED, i.name());
                publish(s, &Setup::default());
                self.interpreter = Some(i);
                self.next_cycle_s = now_s;
            }
            Err(e) => {
                let line = format!("syntax error, program not started: {e}");
                eprintln!("virtual UR5e: {line}");
                log(&mut s.program_log, &line);
                runtime_exception(s, now_s, &e);
                s.program = ProgramState::Stopped;
            }
        }
    }

    /// Drops the interpreter and what it set: watchdog, output registers, sockets.
    fn end(&mut self, s: &mut DeviceState) {
        if let Some(i) = self.interpreter.take() {
            let o = &mut s.outputs;
            o.int_registers.fill(0);
            o.double_registers.fill(0.0);
            o.bit_registers = 0;
            s.sockets.close_all();
            let now = s.status.time_s;
            s.robot_messages.key(now, PROGRAM_STOPPED, i.name());
        }
        self.armed = None;
        s.watchdog = None;
    }

    /// Runs the secondary programs that arrived, each to its end, with the controller's settings.
    fn run_secondary(&mut self, s: &mut DeviceState, now_s: f64, measured_q: [f64; 6]) {
        while let Some(text) = s.secondary_programs.pop_front() {
            let mut program = match Interpreter::new(&text, measured_q) {
                Ok(p) => p,
                Err(e) => {
                    log(&mut s.program_log, &format!("secondary program not started: {e}"));
                    runtime_exception(s, now_s, &e);
                    continue;
                }
            };
            program.set_setup(s.program_setup.clone());
            let mut host = Host { s, measured_q, watchdog_set: false, now_s };
            program.step(now_s, &mut host);
            if let Status::Failed(e) = program.status() {
                runtime_exception(s, now_s, e);
            }
            let setup = program.setup().clone();
            if setup != s.program_setup {
                publish(s, &setup);
                if let Some(main) = self.interpreter.as_mut() {
                    main.set_setup(setup);
                }
            }
        }
    }

    fn arm_watchdog(&mut self, s: &DeviceState, now_s: f64) {
        let Some(w) = &s.watchdog else { return };
        if self.armed.as_ref().is_none_or(|(v, ..)| *v != w.variable) {
            self.armed = Some((w.variable.clone(), s.inputs.writes_of(&w.variable), now_s));
        }
    }

    /// `rtde_set_watchdog`: whether it just stopped or paused the program (the arm then holds).
    fn check_watchdog(&mut self, s: &mut DeviceState, now_s: f64) -> bool {
        if s.program != ProgramState::Playing {
            return false;
        }
        let (Some(w), Some((variable, seen, at))) = (&s.watchdog, &mut self.armed) else { return false };
        let writes = s.inputs.writes_of(variable);
        if writes != *seen {
            (*seen, *at) = (writes, now_s);
            return false;
        }
        if now_s - *at <= 1.0 / w.min_frequency_hz {
            return false;
        }
        match w.action {
            WatchdogAction::Ignore => false,
            WatchdogAction::Pause => {
                s.program = ProgramState::Paused;
                true
            }
            WatchdogAction::Stop => {
                s.program = ProgramState::Stopped;
                true
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::controller::VirtualUrSetup;
    use tendril_drivers::HardwareConfig;
    use tendril_fbg::SpectralConfig;
    use tendril_rtde::RtdeValue;

    /// The devices' state of the default hardware.
    fn default_devices() -> std::sync::Arc<std::sync::Mutex<DeviceState>> {
        let (state, _) = crate::state::shared_state(
            &HardwareConfig::default(),
            &SpectralConfig::default(),
            &VirtualUrSetup::default(),
        )
        .unwrap();
        state
    }

    /// What `serve_script` does when a complete program arrives.
    fn upload(s: &mut DeviceState) {
        s.program_source = Some(FOLLOW_SCRIPT.to_string());
        s.program_uploads += 1;
        s.program = ProgramState::Playing;
    }

    /// The follow program's `servoj` targets, one per 2 ms cycle, fed a client's constant-speed
    /// stream (a stamped target every 10 ms, 0.2 ms on the way) by a twin that stalls for `stall_s`
    /// at twin time 1.003 s and then catches up at once: each cycle's step over the stream's.
    fn servo_speed_ratios(stall_s: f64) -> Vec<(f64, f64)> {
        let state = default_devices();
        let mut s = state.lock().unwrap();
        upload(&mut s);
        let home = [-1.57, -1.57, 1.57, -1.57, -1.57, 0.0];
        let speed = 0.05;
        let mut runner = ProgramRunner::default();
        let (mut next_package, mut last) = (0u32, None::<([f64; 6], f64)>);
        let mut ratios = Vec::new();
        for k in 0..3000u32 {
            let now_s = f64::from(k) * 1e-3;
            // The wall clock at this tick: the stalled ticks all run when the stall ends.
            let wall_s = if (1.003..1.003 + stall_s).contains(&now_s) { 1.003 + stall_s } else { now_s };
            // The client's packages that arrived by then, each stamped with its read time.
            while f64::from(next_package) * 0.01 + 0.0002 <= wall_s {
                let stamp_s = f64::from(next_package) * 0.01;
                let names = tendril_urscript::input_names();
                let values = home.map(|h| RtdeValue::Double(h + speed * stamp_s)).into_iter();
                let values = values.chain([RtdeValue::Double(stamp_s), RtdeValue::Int32(1)]);
                let s = &mut *s;
                s.inputs.apply_package(names.iter().map(String::as_str).zip(values));
                s.program_inputs.arrived_at(stamp_s + 0.0002, &s.inputs);
                next_package += 1;
            }
            let measured = last.map_or(home, |(q, _)| q);
            if let ArmCommand::Servo { q, at_s } = runner.tick(&mut s, now_s, measured) {
                if let Some((q0, t0)) = last
                    && at_s > 0.2
                {
                    ratios.push((at_s, (q[0] - q0[0]) / (at_s - t0) / speed));
                }
                last = Some((q, at_s));
            }
        }
        ratios
    }

    #[test]
    fn a_twin_that_stalls_and_catches_up_plays_the_stream_at_its_own_speed() {
        for stall_s in [0.0, 0.008, 0.02] {
            let ratios = servo_speed_ratios(stall_s);
            assert!(ratios.len() > 1000, "stall {stall_s} s: {} servo targets", ratios.len());
            for (at_s, r) in ratios {
                // Packages held back to their arrival: the arm's setpoint never jumps. Made visible
                // at once, a package that came during the stall reached the program up to a stall
                // early on its clock; the program took it for the new earliest arrival and its
                // playback jumped ahead in one cycle: 5 and 10 times the stream's speed for 8 and
                // 20 ms stalls (measured with the packages made visible at once).
                assert!(
                    (r - 1.0).abs() < 0.01,
                    "stall {stall_s} s: at {at_s:.3} s the setpoint moved {r:.3} times the stream's speed"
                );
            }
        }
    }

    #[test]
    fn a_dashboard_stop_before_the_twin_sees_an_upload_stands() {
        let state = default_devices();
        let mut s = state.lock().unwrap();
        let mut runner = ProgramRunner::default();
        upload(&mut s);
        // The dashboard stops it before the twin's next tick (a delayed twin thread).
        s.program = ProgramState::Stopped;
        runner.tick(&mut s, 0.0, [0.0; 6]);
        assert_eq!(s.program, ProgramState::Stopped, "the stop stands");
        // Played again, it runs the uploaded program.
        s.program = ProgramState::Playing;
        runner.tick(&mut s, 0.002, [0.0; 6]);
        assert_eq!(s.program, ProgramState::Playing);
        assert!(runner.interpreter.is_some(), "the program started");
        // A second upload replaces it and plays.
        upload(&mut s);
        runner.tick(&mut s, 0.004, [0.0; 6]);
        assert_eq!(s.program, ProgramState::Playing);
        assert_eq!(runner.uploads_seen, 2);
    }
}
