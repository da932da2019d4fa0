//! The robot state message's sub-packages (message type 16): each `i32 size` (its own 5-byte
//! header included), `u8 type`, then the fields of UR's "Client Interfaces" document for
//! PolyScope 5 (e-Series), in its order and sizes. Cross-checked against the sizes of a UR5e's
//! robot state as URSim 5.8 sends it (47, 251, 37, 75, 101, 225, 445, 61, 9, 53, 26 and 8 bytes
//! for types 0-9, 11, 12) and against the fields UR's C++ client library parses.
//!
//! Not modelled: SAFETY_DATA (10) and the other types UR marks as used by its own software only;
//! a decoder keeps them as [`SubPackage::Other`].

use super::error::PrimaryError;
use super::wire::{Reader, Writer};

/// Sub-package type bytes.
pub mod kind {
    /// Robot mode data.
    pub const ROBOT_MODE_DATA: u8 = 0;
    /// Joint data.
    pub const JOINT_DATA: u8 = 1;
    /// Tool data.
    pub const TOOL_DATA: u8 = 2;
    /// Masterboard data.
    pub const MASTERBOARD_DATA: u8 = 3;
    /// Cartesian info.
    pub const CARTESIAN_INFO: u8 = 4;
    /// Kinematics info.
    pub const KINEMATICS_INFO: u8 = 5;
    /// Configuration data.
    pub const CONFIGURATION_DATA: u8 = 6;
    /// Force mode data.
    pub const FORCE_MODE_DATA: u8 = 7;
    /// Additional info.
    pub const ADDITIONAL_INFO: u8 = 8;
    /// Calibration data.
    pub const CALIBRATION_DATA: u8 = 9;
    /// Tool communication info.
    pub const TOOL_COMM_INFO: u8 = 11;
    /// Tool mode info.
    pub const TOOL_MODE_INFO: u8 = 12;
}

/// Robot mode data (type 0).
#[derive(Debug, Clone, PartialEq)]
pub struct RobotModeData {
    /// Controller time (we send microseconds of twin time; UR does not state the unit).
    pub timestamp: u64,
    /// A real robot is connected (true on a controller with an arm).
    pub is_real_robot_connected: bool,
    /// The real robot is enabled.
    pub is_real_robot_enabled: bool,
    /// The arm is powered.
    pub is_robot_power_on: bool,
    /// Emergency stop pressed.
    pub is_emergency_stopped: bool,
    /// In a protective stop.
    pub is_protective_stopped: bool,
    /// A program runs.
    pub is_program_running: bool,
    /// The program is paused.
    pub is_program_paused: bool,
    /// Robot mode (RTDE's `robot_mode` numbers: 3 power off, 5 idle, 7 running, ...).
    pub robot_mode: i8,
    /// Control mode (0 position, 1 teach, 2 force, 3 torque).
    pub control_mode: u8,
    /// Speed slider fraction.
    pub target_speed_fraction: f64,
    /// Speed scaling.
    pub speed_scaling: f64,
    /// Speed slider limit.
    pub target_speed_fraction_limit: f64,
}

/// One joint of the joint data (type 1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Joint {
    /// Measured angle \[rad\].
    pub q_actual: f64,
    /// Commanded angle \[rad\].
    pub q_target: f64,
    /// Measured speed \[rad/s\].
    pub qd_actual: f64,
    /// Current \[A\].
    pub i_actual: f32,
    /// Voltage \[V\].
    pub v_actual: f32,
    /// Motor temperature \[°C\].
    pub t_motor: f32,
    /// Deprecated by UR (ignore).
    pub t_micro: f32,
    /// Joint mode (253 running).
    pub mode: u8,
}

/// Tool data (type 2).
#[derive(Debug, Clone, PartialEq)]
pub struct ToolData {
    /// Analog input ranges 0 and 1.
    pub analog_input_range: [u8; 2],
    /// Analog inputs \[V or A\].
    pub analog_input: [f64; 2],
    /// Tool supply voltage \[V\].
    pub voltage_48v: f32,
    /// Tool output voltage \[V\] (0, 12 or 24).
    pub output_voltage: u8,
    /// Tool current \[A\].
    pub current: f32,
    /// Tool temperature \[°C\].
    pub temperature: f32,
    /// Tool mode (253 running).
    pub mode: u8,
}

/// Masterboard data (type 3), without a Euromap67 interface.
#[derive(Debug, Clone, PartialEq)]
pub struct MasterboardData {
    /// Digital inputs: 0-7 standard, 8-15 configurable, 16-17 tool.
    pub digital_input_bits: u32,
    /// Digital outputs, the same bits.
    pub digital_output_bits: u32,
    /// Analog input ranges.
    pub analog_input_range: [u8; 2],
    /// Analog inputs \[V or A\].
    pub analog_input: [f64; 2],
    /// Analog output domains (0 current, 1 voltage).
    pub analog_output_domain: [u8; 2],
    /// Analog outputs \[A or V\].
    pub analog_output: [f64; 2],
    /// Masterboard temperature \[°C\].
    pub temperature: f32,
    /// Robot supply voltage \[V\].
    pub robot_voltage_48v: f32,
    /// Robot current \[A\].
    pub robot_current: f32,
    /// IO current \[A\].
    pub io_current: f32,
    /// Safety mode (1 normal, 3 protective stop).
    pub safety_mode: u8,
    /// In reduced mode.
    pub in_reduced_mode: bool,
    /// "Used by UR software only".
    pub reserved: u32,
    /// Operational mode selector input.
    pub operational_mode_selector_input: u8,
    /// Three-position enabling device input.
    pub three_position_enabling_device_input: u8,
    /// "Used by UR software only".
    pub reserved_2: u8,
}

/// Cartesian info (type 4).
#[derive(Debug, Clone, PartialEq)]
pub struct CartesianInfo {
    /// TCP pose: x, y, z \[m\], rotation vector \[rad\].
    pub tcp_pose: [f64; 6],
    /// TCP offset from the flange, the same units.
    pub tcp_offset: [f64; 6],
}

/// Kinematics info (type 5): the arm's DH parameters and their calibration.
#[derive(Debug, Clone, PartialEq)]
pub struct KinematicsInfo {
    /// Per-joint checksums of the calibration.
    pub checksum: [u32; 6],
    /// DH θ offsets \[rad\].
    pub dh_theta: [f64; 6],
    /// DH a \[m\].
    pub dh_a: [f64; 6],
    /// DH d \[m\].
    pub dh_d: [f64; 6],
    /// DH α \[rad\].
    pub dh_alpha: [f64; 6],
    /// Calibration status: 2 linearized (calibrated); a u32 on the wire, as UR's client library
    /// reads it.
    pub calibration_status: u32,
}

/// Configuration data (type 6).
#[derive(Debug, Clone, PartialEq)]
pub struct ConfigurationData {
    /// Joint position limits, min and max per joint \[rad\].
    pub joint_position_limits: [(f64, f64); 6],
    /// Joint speed and acceleration limits per joint \[rad/s, rad/s²\].
    pub joint_motion_limits: [(f64, f64); 6],
    /// Default joint speed \[rad/s\].
    pub v_joint_default: f64,
    /// Default joint acceleration \[rad/s²\].
    pub a_joint_default: f64,
    /// Default tool speed \[m/s\].
    pub v_tool_default: f64,
    /// Default tool acceleration \[m/s²\].
    pub a_tool_default: f64,
    /// Equivalent radius \[m\].
    pub eq_radius: f64,
    /// DH a \[m\].
    pub dh_a: [f64; 6],
    /// DH d \[m\].
    pub dh_d: [f64; 6],
    /// DH α \[rad\].
    pub dh_alpha: [f64; 6],
    /// DH θ \[rad\].
    pub dh_theta: [f64; 6],
    /// Masterboard version.
    pub masterboard_version: i32,
    /// Controller box type.
    pub controller_box_type: i32,
    /// Robot type (1 UR5, 2 UR10, 3 UR3, 4 UR16).
    pub robot_type: i32,
    /// Robot sub-type.
    pub robot_sub_type: i32,
}

/// Force mode data (type 7).
#[derive(Debug, Clone, PartialEq)]
pub struct ForceModeData {
    /// The TCP wrench: force \[N\] and torque \[N·m\].
    pub wrench: [f64; 6],
    /// Robot dexterity.
    pub robot_dexterity: f64,
}

/// Additional info (type 8).
#[derive(Debug, Clone, PartialEq)]
pub struct AdditionalInfo {
    /// Teach pendant button state.
    pub tp_button_state: u8,
    /// Freedrive button enabled.
    pub freedrive_button_enabled: bool,
    /// Freedrive by IO enabled.
    pub io_enabled_freedrive: bool,
    /// Reserved.
    pub reserved: u8,
}

/// Tool communication info (type 11).
#[derive(Debug, Clone, PartialEq)]
pub struct ToolCommunicationInfo {
    /// Tool communication on.
    pub enabled: bool,
    /// Baud rate.
    pub baud_rate: i32,
    /// Parity (0 none).
    pub parity: i32,
    /// Stop bits.
    pub stop_bits: i32,
    /// Receive idle characters.
    pub rx_idle_chars: f32,
    /// Transmit idle characters.
    pub tx_idle_chars: f32,
}

/// Tool mode info (type 12).
#[derive(Debug, Clone, PartialEq)]
pub struct ToolModeInfo {
    /// Output mode.
    pub output_mode: u8,
    /// Digital output mode of output 0.
    pub digital_output_mode_0: u8,
    /// Digital output mode of output 1.
    pub digital_output_mode_1: u8,
}

/// One sub-package of a robot state message.
#[derive(Debug, Clone, PartialEq)]
pub enum SubPackage {
    /// Type 0.
    RobotMode(RobotModeData),
    /// Type 1.
    Joints([Joint; 6]),
    /// Type 2.
    Tool(ToolData),
    /// Type 3.
    Masterboard(MasterboardData),
    /// Type 4.
    Cartesian(CartesianInfo),
    /// Type 5.
    Kinematics(KinematicsInfo),
    /// Type 6.
    Configuration(ConfigurationData),
    /// Type 7.
    ForceMode(ForceModeData),
    /// Type 8.
    Additional(AdditionalInfo),
    /// Type 9: the force/torque calibration (6 doubles).
    Calibration([f64; 6]),
    /// Type 11.
    ToolCommunication(ToolCommunicationInfo),
    /// Type 12.
    ToolMode(ToolModeInfo),
    /// A type not modelled: its type byte and body as received.
    Other {
        /// Type byte.
        kind: u8,
        /// The body after the 5-byte header.
        body: Vec<u8>,
    },
}

impl SubPackage {
    /// The type byte.
    pub fn kind(&self) -> u8 {
        use kind::*;
        match self {
            SubPackage::RobotMode(_) => ROBOT_MODE_DATA,
            SubPackage::Joints(_) => JOINT_DATA,
            SubPackage::Tool(_) => TOOL_DATA,
            SubPackage::Masterboard(_) => MASTERBOARD_DATA,
            SubPackage::Cartesian(_) => CARTESIAN_INFO,
            SubPackage::Kinematics(_) => KINEMATICS_INFO,
            SubPackage::Configuration(_) => CONFIGURATION_DATA,
            SubPackage::ForceMode(_) => FORCE_MODE_DATA,
            SubPackage::Additional(_) => ADDITIONAL_INFO,
            SubPackage::Calibration(_) => CALIBRATION_DATA,
            SubPackage::ToolCommunication(_) => TOOL_COMM_INFO,
            SubPackage::ToolMode(_) => TOOL_MODE_INFO,
            SubPackage::Other { kind, .. } => *kind,
        }
    }

    /// The sub-package with its header (`i32` size, `u8` type).
    pub fn encode(&self) -> Vec<u8> {
        let mut w = Writer::default();
        match self {
            SubPackage::RobotMode(m) => {
                w.u64(m.timestamp)
                    .bool(m.is_real_robot_connected)
                    .bool(m.is_real_robot_enabled)
                    .bool(m.is_robot_power_on)
                    .bool(m.is_emergency_stopped)
                    .bool(m.is_protective_stopped)
                    .bool(m.is_program_running)
                    .bool(m.is_program_paused)
                    .i8(m.robot_mode)
                    .u8(m.control_mode)
                    .f64(m.target_speed_fraction)
                    .f64(m.speed_scaling)
                    .f64(m.target_speed_fraction_limit)
                    // "unsigned char reserved".
                    .u8(0);
            }
            SubPackage::Joints(joints) => {
                for j in joints {
                    w.f64(j.q_actual)
                        .f64(j.q_target)
                        .f64(j.qd_actual)
                        .f32(j.i_actual)
                        .f32(j.v_actual)
                        .f32(j.t_motor)
                        .f32(j.t_micro)
                        .u8(j.mode);
                }
            }
            SubPackage::Tool(t) => {
                w.u8(t.analog_input_range[0])
                    .u8(t.analog_input_range[1])
                    .f64s(&t.analog_input)
                    .f32(t.voltage_48v)
                    .u8(t.output_voltage)
                    .f32(t.current)
                    .f32(t.temperature)
                    .u8(t.mode);
            }
            SubPackage::Masterboard(m) => {
                w.u32(m.digital_input_bits)
                    .u32(m.digital_output_bits)
                    .u8(m.analog_input_range[0])
                    .u8(m.analog_input_range[1])
                    .f64s(&m.analog_input)
                    .u8(m.analog_output_domain[0])
                    .u8(m.analog_output_domain[1])
                    .f64s(&m.analog_output)
                    .f32(m.temperature)
                    .f32(m.robot_voltage_48v)
                    .f32(m.robot_current)
                    .f32(m.io_current)
                    .u8(m.safety_mode)
                    .bool(m.in_reduced_mode)
                    // No Euromap67 interface installed: its four fields are left out.
                    .u8(0)
                    .u32(m.reserved)
                    .u8(m.operational_mode_selector_input)
                    .u8(m.three_position_enabling_device_input)
                    .u8(m.reserved_2);
            }
            SubPackage::Cartesian(c) => {
                w.f64s(&c.tcp_pose).f64s(&c.tcp_offset);
            }
            SubPackage::Kinematics(k) => {
                for c in k.checksum {
                    w.u32(c);
                }
                w.f64s(&k.dh_theta).f64s(&k.dh_a).f64s(&k.dh_d).f64s(&k.dh_alpha).u32(k.calibration_status);
            }
            SubPackage::Configuration(c) => {
                for (min, max) in c.joint_position_limits {
                    w.f64(min).f64(max);
                }
                for (speed, acceleration) in c.joint_motion_limits {
                    w.f64(speed).f64(acceleration);
                }
                w.f64(c.v_joint_default)
                    .f64(c.a_joint_default)
                    .f64(c.v_tool_default)
                    .f64(c.a_tool_default)
                    .f64(c.eq_radius)
                    .f64s(&c.dh_a)
                    .f64s(&c.dh_d)
                    .f64s(&c.dh_alpha)
                    .f64s(&c.dh_theta)
                    .i32(c.masterboard_version)
                    .i32(c.controller_box_type)
                    .i32(c.robot_type)
                    .i32(c.robot_sub_type);
            }
            SubPackage::ForceMode(f) => {
                w.f64s(&f.wrench).f64(f.robot_dexterity);
            }
            SubPackage::Additional(a) => {
                w.u8(a.tp_button_state).bool(a.freedrive_button_enabled).bool(a.io_enabled_freedrive).u8(a.reserved);
            }
            SubPackage::Calibration(f) => {
                w.f64s(f);
            }
            SubPackage::ToolCommunication(t) => {
                w.bool(t.enabled)
                    .i32(t.baud_rate)
                    .i32(t.parity)
                    .i32(t.stop_bits)
                    .f32(t.rx_idle_chars)
                    .f32(t.tx_idle_chars);
            }
            SubPackage::ToolMode(t) => {
                w.u8(t.output_mode).u8(t.digital_output_mode_0).u8(t.digital_output_mode_1);
            }
            SubPackage::Other { body, .. } => {
                w.bytes(body);
            }
        }
        let body = w.0;
        let mut out = Vec::with_capacity(body.len() + 5);
        out.extend_from_slice(&((body.len() + 5) as u32).to_be_bytes());
        out.push(self.kind());
        out.extend_from_slice(&body);
        out
    }

    /// Decodes a body (after the 5-byte header) of type `kind`. A body longer than the fields is
    /// accepted (UR may append fields in later versions, its document says); a shorter one is an
    /// error.
    pub fn decode(kind: u8, body: &[u8]) -> Result<SubPackage, PrimaryError> {
        let mut r = Reader(body);
        let r = &mut r;
        Ok(match kind {
            kind::ROBOT_MODE_DATA => SubPackage::RobotMode(RobotModeData {
                timestamp: r.u64()?,
                is_real_robot_connected: r.bool()?,
                is_real_robot_enabled: r.bool()?,
                is_robot_power_on: r.bool()?,
                is_emergency_stopped: r.bool()?,
                is_protective_stopped: r.bool()?,
                is_program_running: r.bool()?,
                is_program_paused: r.bool()?,
                robot_mode: r.i8()?,
                control_mode: r.u8()?,
                target_speed_fraction: r.f64()?,
                speed_scaling: r.f64()?,
                target_speed_fraction_limit: r.f64()?,
            }),
            kind::JOINT_DATA => {
                let mut joints = [Joint {
                    q_actual: 0.0,
                    q_target: 0.0,
                    qd_actual: 0.0,
                    i_actual: 0.0,
                    v_actual: 0.0,
                    t_motor: 0.0,
                    t_micro: 0.0,
                    mode: 0,
                }; 6];
                for j in &mut joints {
                    *j = Joint {
                        q_actual: r.f64()?,
                        q_target: r.f64()?,
                        qd_actual: r.f64()?,
                        i_actual: r.f32()?,
                        v_actual: r.f32()?,
                        t_motor: r.f32()?,
                        t_micro: r.f32()?,
                        mode: r.u8()?,
                    };
                }
                SubPackage::Joints(joints)
            }
            kind::TOOL_DATA => SubPackage::Tool(ToolData {
                analog_input_range: [r.u8()?, r.u8()?],
                analog_input: r.f64s()?,
                voltage_48v: r.f32()?,
                output_voltage: r.u8()?,
                current: r.f32()?,
                temperature: r.f32()?,
                mode: r.u8()?,
            }),
            kind::MASTERBOARD_DATA => {
                let mut m = MasterboardData {
                    digital_input_bits: r.u32()?,
                    digital_output_bits: r.u32()?,
                    analog_input_range: [r.u8()?, r.u8()?],
                    analog_input: r.f64s()?,
                    analog_output_domain: [r.u8()?, r.u8()?],
                    analog_output: r.f64s()?,
                    temperature: r.f32()?,
                    robot_voltage_48v: r.f32()?,
                    robot_current: r.f32()?,
                    io_current: r.f32()?,
                    safety_mode: r.u8()?,
                    in_reduced_mode: r.bool()?,
                    reserved: 0,
                    operational_mode_selector_input: 0,
                    three_position_enabling_device_input: 0,
                    reserved_2: 0,
                };
                if r.u8()? != 0 {
                    // Euromap67 inputs, outputs, voltage, current: read past them.
                    r.bytes(16)?;
                }
                m.reserved = r.u32()?;
                m.operational_mode_selector_input = r.u8()?;
                m.three_position_enabling_device_input = r.u8()?;
                m.reserved_2 = r.u8()?;
                SubPackage::Masterboard(m)
            }
            kind::CARTESIAN_INFO => SubPackage::Cartesian(CartesianInfo { tcp_pose: r.f64s()?, tcp_offset: r.f64s()? }),
            kind::KINEMATICS_INFO => SubPackage::Kinematics(KinematicsInfo {
                checksum: [r.u32()?, r.u32()?, r.u32()?, r.u32()?, r.u32()?, r.u32()?],
                dh_theta: r.f64s()?,
                dh_a: r.f64s()?,
                dh_d: r.f64s()?,
                dh_alpha: r.f64s()?,
                calibration_status: r.u32()?,
            }),
            kind::CONFIGURATION_DATA => {
                let mut limits = [(0.0, 0.0); 6];
                for l in &mut limits {
                    *l = (r.f64()?, r.f64()?);
                }
                let mut motion = [(0.0, 0.0); 6];
                for l in &mut motion {
                    *l = (r.f64()?, r.f64()?);
                }
                SubPackage::Configuration(ConfigurationData {
                    joint_position_limits: limits,
                    joint_motion_limits: motion,
                    v_joint_default: r.f64()?,
                    a_joint_default: r.f64()?,
                    v_tool_default: r.f64()?,
                    a_tool_default: r.f64()?,
                    eq_radius: r.f64()?,
                    dh_a: r.f64s()?,
                    dh_d: r.f64s()?,
                    dh_alpha: r.f64s()?,
                    dh_theta: r.f64s()?,
                    masterboard_version: r.i32()?,
                    controller_box_type: r.i32()?,
                    robot_type: r.i32()?,
                    robot_sub_type: r.i32()?,
                })
            }
            kind::FORCE_MODE_DATA => {
                SubPackage::ForceMode(ForceModeData { wrench: r.f64s()?, robot_dexterity: r.f64()? })
            }
            kind::ADDITIONAL_INFO => SubPackage::Additional(AdditionalInfo {
                tp_button_state: r.u8()?,
                freedrive_button_enabled: r.bool()?,
                io_enabled_freedrive: r.bool()?,
                reserved: r.u8()?,
            }),
            kind::CALIBRATION_DATA => SubPackage::Calibration(r.f64s()?),
            kind::TOOL_COMM_INFO => SubPackage::ToolCommunication(ToolCommunicationInfo {
                enabled: r.bool()?,
                baud_rate: r.i32()?,
                parity: r.i32()?,
                stop_bits: r.i32()?,
                rx_idle_chars: r.f32()?,
                tx_idle_chars: r.f32()?,
            }),
            kind::TOOL_MODE_INFO => SubPackage::ToolMode(ToolModeInfo {
                output_mode: r.u8()?,
                digital_output_mode_0: r.u8()?,
                digital_output_mode_1: r.u8()?,
            }),
            other => SubPackage::Other { kind: other, body: body.to_vec() },
        })
    }
}
