//! The virtual UR5e's data behind the RTDE fields: what it reports and what clients wrote.

use std::collections::BTreeMap;

use super::fields::{REGISTER_COUNT, Register, register};
use super::types::{RtdeType, RtdeValue};

/// `robot_mode` value for a running robot (RTDE guide: ROBOT_MODE_RUNNING).
pub const ROBOT_MODE_RUNNING: i32 = 7;
/// `safety_mode` value for normal operation (SAFETY_MODE_NORMAL).
pub const SAFETY_MODE_NORMAL: i32 = 1;
/// `safety_mode` and `safety_status` value in a protective stop (SAFETY_MODE_PROTECTIVE_STOP).
pub const SAFETY_MODE_PROTECTIVE_STOP: i32 = 3;
/// `runtime_state` value while a program plays (PLAYING).
pub const RUNTIME_STATE_PLAYING: u32 = 2;
/// `runtime_state` value when no program runs (STOPPED).
pub const RUNTIME_STATE_STOPPED: u32 = 1;
/// `runtime_state` value of a paused program (PAUSED).
pub const RUNTIME_STATE_PAUSED: u32 = 4;
/// URScript's default gravity vector (`set_gravity`'s \[0, 0, 9.82\] m/s², base frame).
pub const DEFAULT_GRAVITY: [f64; 3] = [0.0, 0.0, 9.82];
/// `joint_mode` value of a running joint (JOINT_RUNNING_MODE).
pub const JOINT_MODE_RUNNING: i32 = 253;

/// What the virtual UR5e reports; the twin fills it every control tick.
/// Units: rad, rad/s, m, N, N·m, s (RTDE guide conventions; TCP pose is x, y, z, rotation vector).
#[derive(Debug, Clone, PartialEq)]
pub struct RobotOutputs {
    /// Controller time since start, s.
    pub timestamp_s: f64,
    /// Commanded joint positions, rad.
    pub target_q: [f64; 6],
    /// Commanded joint velocities, rad/s.
    pub target_qd: [f64; 6],
    /// Measured joint positions, rad.
    pub actual_q: [f64; 6],
    /// Measured joint velocities, rad/s.
    pub actual_qd: [f64; 6],
    /// TCP pose (m, rotation vector in rad).
    pub actual_tcp_pose: [f64; 6],
    /// TCP twist (m/s, rad/s).
    pub actual_tcp_speed: [f64; 6],
    /// TCP wrench (N, N·m).
    pub actual_tcp_force: [f64; 6],
    /// Commanded TCP pose.
    pub target_tcp_pose: [f64; 6],
    /// Commanded TCP twist (m/s, rad/s).
    pub target_tcp_speed: [f64; 6],
    /// TCP acceleration (m/s², rad/s²).
    pub actual_tcp_acceleration: [f64; 6],
    /// Commanded TCP acceleration (m/s², rad/s²).
    pub target_tcp_acceleration: [f64; 6],
    /// The gravity vector the program set with `set_gravity` \[m/s²\] (base frame; URScript's
    /// default \[0, 0, 9.82\]).
    pub gravity: [f64; 3],
    /// The payload the program set with `set_payload` \[kg\].
    pub payload_kg: f64,
    /// Its centre of gravity from the flange \[m\].
    pub payload_cog: [f64; 3],
    /// Its inertia matrix \[Ixx, Iyy, Izz, Ixy, Ixz, Iyz\] \[kg·m²\] (`set_target_payload`).
    pub payload_inertia: [f64; 6],
    /// The tool output voltage the program set with `set_tool_voltage` \[V\] (0, 12 or 24).
    pub tool_output_voltage: i32,
    /// The TCP's offset from the tool flange (m, rotation vector in rad; zeros: the flange).
    pub tcp_offset: [f64; 6],
    /// Robot mode (7 running).
    pub robot_mode: i32,
    /// Safety mode (1 normal, 3 protective stop); also served as `safety_status`.
    pub safety_mode: i32,
    /// Runtime state (2 playing).
    pub runtime_state: u32,
    /// Speed scaling in [0, 1].
    pub speed_scaling: f64,
    /// Speed slider fraction in [0, 1].
    pub target_speed_fraction: f64,
    /// `output_int_register_0..47`.
    pub int_registers: [i32; REGISTER_COUNT],
    /// `output_double_register_0..47`.
    pub double_registers: [f64; REGISTER_COUNT],
    /// `output_bit_register_0..127` as bits (0..63 are read as the two 32-bit words).
    pub bit_registers: u128,
    /// `actual_digital_output_bits`: 0-7 standard, 8-15 configurable, 16-17 tool (RTDE guide).
    pub digital_output_bits: u64,
    /// `standard_analog_output0/1` \[A or V\].
    pub standard_analog_output: [f64; 2],
    /// `analog_io_types`: bits 0-1 inputs, 2-3 outputs 0 and 1; set = voltage, clear = current.
    pub analog_io_types: u32,
}

impl Default for RobotOutputs {
    fn default() -> Self {
        Self {
            timestamp_s: 0.0,
            target_q: [0.0; 6],
            target_qd: [0.0; 6],
            actual_q: [0.0; 6],
            actual_qd: [0.0; 6],
            actual_tcp_pose: [0.0; 6],
            actual_tcp_speed: [0.0; 6],
            actual_tcp_force: [0.0; 6],
            target_tcp_pose: [0.0; 6],
            target_tcp_speed: [0.0; 6],
            actual_tcp_acceleration: [0.0; 6],
            target_tcp_acceleration: [0.0; 6],
            gravity: DEFAULT_GRAVITY,
            payload_kg: 0.0,
            payload_cog: [0.0; 3],
            payload_inertia: [0.0; 6],
            tool_output_voltage: 0,
            tcp_offset: [0.0; 6],
            robot_mode: ROBOT_MODE_RUNNING,
            safety_mode: SAFETY_MODE_NORMAL,
            runtime_state: RUNTIME_STATE_PLAYING,
            speed_scaling: 1.0,
            target_speed_fraction: 1.0,
            int_registers: [0; REGISTER_COUNT],
            double_registers: [0.0; REGISTER_COUNT],
            bit_registers: 0,
            digital_output_bits: 0,
            // Current mode at 0: 4 mA, the bottom of the 4-20 mA range.
            standard_analog_output: [0.004; 2],
            analog_io_types: 0,
        }
    }
}

/// What clients have written through input recipes (the motion program reads these).
#[derive(Debug, Clone, PartialEq)]
pub struct RobotInputs {
    /// `input_int_register_0..47`.
    pub int_registers: [i32; REGISTER_COUNT],
    /// `input_double_register_0..47`.
    pub double_registers: [f64; REGISTER_COUNT],
    /// `input_bit_register_0..127` as bits.
    pub bit_registers: u128,
    /// Other inputs by name (speed slider, digital outputs, external wrench...).
    pub other: BTreeMap<String, RtdeValue>,
}

impl Default for RobotInputs {
    fn default() -> Self {
        Self {
            int_registers: [0; REGISTER_COUNT],
            double_registers: [0.0; REGISTER_COUNT],
            bit_registers: 0,
            other: BTreeMap::new(),
        }
    }
}

impl RobotInputs {
    /// Stores a written value (the name and type were checked by the recipe).
    pub fn apply(&mut self, name: &str, value: RtdeValue) {
        match (register(name, "input"), value) {
            (Some(Register::Int(i)), RtdeValue::Int32(v)) => self.int_registers[i] = v,
            (Some(Register::Double(i)), RtdeValue::Double(v)) => self.double_registers[i] = v,
            (Some(Register::Bit(i)), RtdeValue::Bool(v)) => set_bit(&mut self.bit_registers, i, v),
            _ => match (name, value) {
                ("input_bit_registers0_to_31", RtdeValue::Uint32(w)) => set_word(&mut self.bit_registers, 0, w),
                ("input_bit_registers32_to_63", RtdeValue::Uint32(w)) => set_word(&mut self.bit_registers, 1, w),
                _ => {
                    self.other.insert(name.to_string(), value);
                }
            },
        }
    }
}

fn set_bit(bits: &mut u128, index: u32, value: bool) {
    if value {
        *bits |= 1 << index;
    } else {
        *bits &= !(1 << index);
    }
}

fn set_word(bits: &mut u128, word: u32, value: u32) {
    let shift = 32 * word;
    *bits = (*bits & !(u128::from(u32::MAX) << shift)) | (u128::from(value) << shift);
}

fn word(bits: u128, word: u32) -> u32 {
    (bits >> (32 * word)) as u32
}

/// Where an output field's value comes from, resolved once when the recipe is set up.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum OutputSource {
    Timestamp,
    TargetQ,
    TargetQd,
    ActualQ,
    ActualQd,
    ActualTcpPose,
    ActualTcpSpeed,
    ActualTcpForce,
    TargetTcpPose,
    TargetTcpSpeed,
    ActualTcpAcceleration,
    TargetTcpAcceleration,
    Gravity,
    Payload,
    PayloadCog,
    PayloadInertia,
    ToolOutputVoltage,
    TcpOffset,
    RobotMode,
    SafetyMode,
    SafetyStatusBits,
    RuntimeState,
    SpeedScaling,
    TargetSpeedFraction,
    RobotStatusBits,
    DigitalOutputBits,
    ConfigurableDigitalOutputBits,
    StandardAnalogOutput(usize),
    AnalogIoTypes,
    OutputRegister(Register),
    OutputBitWord(u32),
    InputRegister(Register),
    InputBitWord(u32),
    Constant(RtdeValue),
}

impl OutputSource {
    /// Resolves a known output name of type `t`.
    pub(crate) fn resolve(name: &str, t: RtdeType) -> OutputSource {
        use OutputSource::*;
        if let Some(r) = register(name, "output") {
            return OutputRegister(r);
        }
        if let Some(r) = register(name, "input") {
            return InputRegister(r);
        }
        match name {
            "timestamp" => Timestamp,
            "target_q" => TargetQ,
            "target_qd" => TargetQd,
            "actual_q" => ActualQ,
            "actual_qd" => ActualQd,
            "actual_TCP_pose" => ActualTcpPose,
            "actual_TCP_speed" => ActualTcpSpeed,
            "actual_TCP_force" => ActualTcpForce,
            "target_TCP_pose" => TargetTcpPose,
            "target_TCP_speed" => TargetTcpSpeed,
            "actual_TCP_acceleration" => ActualTcpAcceleration,
            "target_TCP_acceleration" => TargetTcpAcceleration,
            "target_gravity" => Gravity,
            "payload" => Payload,
            "payload_cog" => PayloadCog,
            "payload_inertia" => PayloadInertia,
            "tool_output_voltage" => ToolOutputVoltage,
            "tcp_offset" => TcpOffset,
            "robot_mode" => RobotMode,
            "safety_mode" => SafetyMode,
            "runtime_state" => RuntimeState,
            "speed_scaling" => SpeedScaling,
            "target_speed_fraction" => TargetSpeedFraction,
            "robot_status_bits" => RobotStatusBits,
            "actual_digital_output_bits" => DigitalOutputBits,
            "actual_configurable_digital_output_bits" => ConfigurableDigitalOutputBits,
            "standard_analog_output0" => StandardAnalogOutput(0),
            "standard_analog_output1" => StandardAnalogOutput(1),
            "analog_io_types" => AnalogIoTypes,
            "output_bit_registers0_to_31" => OutputBitWord(0),
            "output_bit_registers32_to_63" => OutputBitWord(1),
            "input_bit_registers0_to_31" => InputBitWord(0),
            "input_bit_registers32_to_63" => InputBitWord(1),
            "joint_mode" => Constant(RtdeValue::Vector6Int32([JOINT_MODE_RUNNING; 6])),
            // safety_status uses safety_mode's values (finer only in states the twin never enters).
            "safety_status" => SafetyMode,
            "safety_status_bits" => SafetyStatusBits,
            _ => Constant(RtdeValue::zero(t)),
        }
    }

    /// The current value.
    pub(crate) fn value(&self, out: &RobotOutputs, inp: &RobotInputs) -> RtdeValue {
        use OutputSource::*;
        use RtdeValue as V;
        match *self {
            Timestamp => V::Double(out.timestamp_s),
            TargetQ => V::Vector6d(out.target_q),
            TargetQd => V::Vector6d(out.target_qd),
            ActualQ => V::Vector6d(out.actual_q),
            ActualQd => V::Vector6d(out.actual_qd),
            ActualTcpPose => V::Vector6d(out.actual_tcp_pose),
            ActualTcpSpeed => V::Vector6d(out.actual_tcp_speed),
            ActualTcpForce => V::Vector6d(out.actual_tcp_force),
            TargetTcpPose => V::Vector6d(out.target_tcp_pose),
            TargetTcpSpeed => V::Vector6d(out.target_tcp_speed),
            ActualTcpAcceleration => V::Vector6d(out.actual_tcp_acceleration),
            TargetTcpAcceleration => V::Vector6d(out.target_tcp_acceleration),
            Gravity => V::Vector3d(out.gravity),
            Payload => V::Double(out.payload_kg),
            PayloadCog => V::Vector3d(out.payload_cog),
            PayloadInertia => V::Vector6d(out.payload_inertia),
            ToolOutputVoltage => V::Int32(out.tool_output_voltage),
            TcpOffset => V::Vector6d(out.tcp_offset),
            RobotMode => V::Int32(out.robot_mode),
            SafetyMode => V::Int32(out.safety_mode),
            SafetyStatusBits => {
                // Bit 0 normal mode, bit 2 protective stopped (RTDE guide).
                V::Uint32(match out.safety_mode {
                    SAFETY_MODE_NORMAL => 1,
                    SAFETY_MODE_PROTECTIVE_STOP => 1 << 2,
                    _ => 0,
                })
            }
            RuntimeState => V::Uint32(out.runtime_state),
            SpeedScaling => V::Double(out.speed_scaling),
            TargetSpeedFraction => V::Double(out.target_speed_fraction),
            RobotStatusBits => {
                // Bit 0 power on, bit 1 program running (RTDE guide).
                let power = u32::from(out.robot_mode == ROBOT_MODE_RUNNING);
                let running = u32::from(out.runtime_state == RUNTIME_STATE_PLAYING);
                V::Uint32(power | running << 1)
            }
            DigitalOutputBits => V::Uint64(out.digital_output_bits),
            ConfigurableDigitalOutputBits => V::Uint64(out.digital_output_bits >> 8 & 0xFF),
            StandardAnalogOutput(i) => V::Double(out.standard_analog_output[i]),
            AnalogIoTypes => V::Uint32(out.analog_io_types),
            OutputRegister(r) => register_value(r, &out.int_registers, &out.double_registers, out.bit_registers),
            OutputBitWord(w) => V::Uint32(word(out.bit_registers, w)),
            InputRegister(r) => register_value(r, &inp.int_registers, &inp.double_registers, inp.bit_registers),
            InputBitWord(w) => V::Uint32(word(inp.bit_registers, w)),
            Constant(v) => v,
        }
    }
}

fn register_value(r: Register, ints: &[i32], doubles: &[f64], bits: u128) -> RtdeValue {
    match r {
        Register::Int(i) => RtdeValue::Int32(ints[i]),
        Register::Double(i) => RtdeValue::Double(doubles[i]),
        Register::Bit(i) => RtdeValue::Bool(bits >> i & 1 == 1),
    }
}

#[cfg(test)]
mod tests {
    use super::super::fields::{FIXED_OUTPUTS, output_type};
    use super::*;

    #[test]
    fn every_known_output_resolves_to_a_value_of_its_type() {
        let out = RobotOutputs::default();
        let inp = RobotInputs::default();
        let mut names: Vec<String> = FIXED_OUTPUTS.iter().map(|(n, _)| n.to_string()).collect();
        names
            .extend(["output_int_register_3", "input_double_register_47", "output_bit_register_100"].map(String::from));
        for name in names {
            let t = output_type(&name).unwrap();
            assert_eq!(OutputSource::resolve(&name, t).value(&out, &inp).rtde_type(), t, "{name}");
        }
    }

    #[test]
    fn inputs_written_are_readable_as_outputs() {
        let mut inp = RobotInputs::default();
        inp.apply("input_int_register_5", RtdeValue::Int32(-3));
        inp.apply("input_bit_register_70", RtdeValue::Bool(true));
        inp.apply("input_bit_registers0_to_31", RtdeValue::Uint32(0xF0));
        let out = RobotOutputs::default();
        let get = |name: &str| OutputSource::resolve(name, output_type(name).unwrap()).value(&out, &inp);
        assert_eq!(get("input_int_register_5"), RtdeValue::Int32(-3));
        assert_eq!(get("input_bit_register_70"), RtdeValue::Bool(true));
        assert_eq!(get("input_bit_registers0_to_31"), RtdeValue::Uint32(0xF0));
        assert_eq!(get("input_bit_registers32_to_63"), RtdeValue::Uint32(0));
    }
}
