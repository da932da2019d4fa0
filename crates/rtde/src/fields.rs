//! RTDE field names and types the virtual UR5e serves.
//!
//! Source: Universal Robots, "Real-Time Data Exchange (RTDE) Guide" (output and input tables),
//! as recalled for PolyScope 5.11+; cross-checked against the names and types SDU's `ur_rtde`
//! requests by default and parses (its `RobotState` table). Names not listed here are answered
//! with `NOT_FOUND`. The twin fills [`TWIN_OUTPUTS`] with simulated values; the other output
//! names are served with their type's zero (or a fixed plausible value, see `server.rs`), so
//! clients that ask for everything (ur_rtde's 58 default names) still get a valid recipe.

use super::types::RtdeType;
use super::types::RtdeType::*;

/// Number of int and double registers in each direction (0..=47).
pub const REGISTER_COUNT: usize = 48;
/// First individually addressable bit register (`*_bit_register_64` .. `_127`).
pub const FIRST_BIT_REGISTER: u32 = 64;
/// One past the last bit register.
pub const BIT_REGISTER_END: u32 = 128;

/// Output fields with a fixed name (registers are matched by pattern, see [`output_type`]).
pub const FIXED_OUTPUTS: &[(&str, RtdeType)] = &[
    ("timestamp", Double),
    ("target_q", Vector6d),
    ("target_qd", Vector6d),
    ("target_qdd", Vector6d),
    ("target_current", Vector6d),
    ("target_moment", Vector6d),
    ("actual_q", Vector6d),
    ("actual_qd", Vector6d),
    ("actual_current", Vector6d),
    ("actual_current_window", Vector6d),
    ("joint_control_output", Vector6d),
    ("actual_TCP_pose", Vector6d),
    ("actual_TCP_speed", Vector6d),
    ("actual_TCP_force", Vector6d),
    ("target_TCP_pose", Vector6d),
    ("target_TCP_speed", Vector6d),
    ("actual_digital_input_bits", Uint64),
    ("joint_temperatures", Vector6d),
    ("actual_execution_time", Double),
    ("robot_mode", Int32),
    ("joint_mode", Vector6Int32),
    ("safety_mode", Int32),
    ("safety_status", Int32),
    ("actual_tool_accelerometer", Vector3d),
    ("speed_scaling", Double),
    ("target_speed_fraction", Double),
    ("actual_momentum", Double),
    ("actual_main_voltage", Double),
    ("actual_robot_voltage", Double),
    ("actual_robot_current", Double),
    ("actual_joint_voltage", Vector6d),
    ("actual_digital_output_bits", Uint64),
    ("runtime_state", Uint32),
    ("elbow_position", Vector3d),
    ("elbow_velocity", Vector3d),
    ("robot_status_bits", Uint32),
    ("safety_status_bits", Uint32),
    ("analog_io_types", Uint32),
    ("standard_analog_input0", Double),
    ("standard_analog_input1", Double),
    ("standard_analog_output0", Double),
    ("standard_analog_output1", Double),
    ("io_current", Double),
    ("euromap67_input_bits", Uint32),
    ("euromap67_output_bits", Uint32),
    ("euromap67_24V_voltage", Double),
    ("euromap67_24V_current", Double),
    ("tool_mode", Uint32),
    ("tool_analog_input_types", Uint32),
    ("tool_analog_input0", Double),
    ("tool_analog_input1", Double),
    ("tool_output_voltage", Int32),
    ("tool_output_current", Double),
    ("tool_temperature", Double),
    ("tcp_force_scalar", Double),
    ("output_bit_registers0_to_31", Uint32),
    ("output_bit_registers32_to_63", Uint32),
    ("input_bit_registers0_to_31", Uint32),
    ("input_bit_registers32_to_63", Uint32),
    ("tool_output_mode", Uint8),
    ("tool_digital_output0_mode", Uint8),
    ("tool_digital_output1_mode", Uint8),
    ("payload", Double),
    ("payload_cog", Vector3d),
    ("payload_inertia", Vector6d),
    ("script_control_line", Uint32),
    ("ft_raw_wrench", Vector6d),
    ("joint_position_deviation_ratio", Double),
    ("collision_detection_ratio", Double),
    // Added after SDU ur_rtde's `RTDEReceiveInterface` with all variables hit "Unknown data
    // type: NOT_FOUND" on them. Types from the type table of the fake RTDE server in UR's own
    // `ur_client_library` tests (UR's RTDE guide itself was not at hand to check). Values:
    // `tcp_offset` is the configured TCP offset (`RobotOutputs::tcp_offset`, zeros: we set none);
    // the configurable digital IO bits are 0 (nothing wired) and both encoders read 0 (none fitted).
    ("tcp_offset", Vector6d),
    ("actual_configurable_digital_input_bits", Uint64),
    ("actual_configurable_digital_output_bits", Uint64),
    ("encoder0_raw", Int32),
    ("encoder1_raw", Int32),
    // Newer controllers' outputs, as UR's client library lists them in its exhaustive recipe
    // (types from its `DataPackage` table): the TCP accelerations, differenced from the twin's
    // TCP speeds; the gravity vector the program set (`set_gravity`, URScript's default
    // [0, 0, 9.82] m/s² until then).
    ("actual_TCP_acceleration", Vector6d),
    ("target_TCP_acceleration", Vector6d),
    ("target_gravity", Vector3d),
];

/// Outputs of newer PolyScope 5 controllers the virtual UR5e answers with `NOT_FOUND`, as a
/// controller answers a name it does not serve, and why: a client that asks for them either
/// drops them (UR's client library with `ignore_unavailable_outputs`) or learns at setup that the
/// twin does not have them, instead of reading a made-up value.
pub const NOT_SERVED: &[(&str, &str)] = &[
    ("actual_current_as_torque", "the twin models no motor currents"),
    ("wrench_calc_from_currents", "the twin models no motor currents"),
    ("actual_robot_energy_consumed", "the twin models no electrical power"),
    ("actual_robot_braking_energy_dissipated", "the twin models no electrical power"),
    ("target_base_acceleration", "not defined in the RTDE documentation we work from"),
    ("target_base_wrench", "not defined in the RTDE documentation we work from"),
    ("target_execution_time", "not defined in the RTDE documentation we work from"),
    ("control_step", "not defined in the RTDE documentation we work from"),
    ("time_scale_source", "not defined in the RTDE documentation we work from"),
];

/// Input fields with a fixed name.
pub const FIXED_INPUTS: &[(&str, RtdeType)] = &[
    ("speed_slider_mask", Uint32),
    ("speed_slider_fraction", Double),
    ("standard_digital_output_mask", Uint8),
    ("standard_digital_output", Uint8),
    ("configurable_digital_output_mask", Uint8),
    ("configurable_digital_output", Uint8),
    ("tool_digital_output_mask", Uint8),
    ("tool_digital_output", Uint8),
    ("standard_analog_output_mask", Uint8),
    ("standard_analog_output_type", Uint8),
    ("standard_analog_output_0", Double),
    ("standard_analog_output_1", Double),
    ("input_bit_registers0_to_31", Uint32),
    ("input_bit_registers32_to_63", Uint32),
    ("external_force_torque", Vector6d),
    ("ft_rtde_input_enable", Bool),
];

/// Outputs the twin computes from the simulation; the rest are served as constants.
pub const TWIN_OUTPUTS: &[&str] = &[
    "timestamp",
    "target_q",
    "target_qd",
    "actual_q",
    "actual_qd",
    "actual_TCP_pose",
    "actual_TCP_speed",
    "actual_TCP_force",
    "target_TCP_pose",
    "target_TCP_speed",
    "actual_TCP_acceleration",
    "target_TCP_acceleration",
    "target_gravity",
    "payload",
    "payload_cog",
    "payload_inertia",
    "tool_output_voltage",
    "tcp_offset",
    "robot_mode",
    "safety_mode",
    "runtime_state",
    "speed_scaling",
    "target_speed_fraction",
];

/// A register named by pattern.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Register {
    /// `*_int_register_N`, N in 0..48.
    Int(usize),
    /// `*_double_register_N`, N in 0..48.
    Double(usize),
    /// `*_bit_register_N`, N in 64..128.
    Bit(u32),
}

/// Parses `{prefix}_int_register_N`, `{prefix}_double_register_N` or `{prefix}_bit_register_N`.
pub fn register(name: &str, prefix: &str) -> Option<Register> {
    let rest = name.strip_prefix(prefix)?.strip_prefix('_')?;
    let number = |s: &str| -> Option<u32> {
        // Reject "+1", "01" and the like: the controller matches exact names.
        (!s.is_empty() && s.bytes().all(|b| b.is_ascii_digit()) && (s == "0" || !s.starts_with('0')))
            .then(|| s.parse().ok())
            .flatten()
    };
    if let Some(n) = rest.strip_prefix("int_register_").and_then(number) {
        return (n < REGISTER_COUNT as u32).then_some(Register::Int(n as usize));
    }
    if let Some(n) = rest.strip_prefix("double_register_").and_then(number) {
        return (n < REGISTER_COUNT as u32).then_some(Register::Double(n as usize));
    }
    let n = rest.strip_prefix("bit_register_").and_then(number)?;
    (FIRST_BIT_REGISTER..BIT_REGISTER_END).contains(&n).then_some(Register::Bit(n))
}

fn register_type(r: Register) -> RtdeType {
    match r {
        Register::Int(_) => Int32,
        Register::Double(_) => Double,
        Register::Bit(_) => Bool,
    }
}

/// Type of an output field, or `None` (answered `NOT_FOUND`).
/// Both output and input registers can be read as outputs.
pub fn output_type(name: &str) -> Option<RtdeType> {
    FIXED_OUTPUTS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, t)| *t)
        .or_else(|| register(name, "output").or_else(|| register(name, "input")).map(register_type))
}

/// Type of an input field, or `None` (answered `NOT_FOUND`).
pub fn input_type(name: &str) -> Option<RtdeType> {
    FIXED_INPUTS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, t)| *t)
        .or_else(|| register(name, "input").map(register_type))
}

/// Whether an input name sets an output of the controller's IO (digital and analog outputs and
/// their masks, the speed slider) rather than a register.
pub fn is_io_input(name: &str) -> bool {
    [
        "speed_slider_",
        "standard_digital_output",
        "configurable_digital_output",
        "tool_digital_output",
        "standard_analog_output_",
    ]
    .iter()
    .any(|p| name.starts_with(p))
}

#[cfg(test)]
/// The 58 names SDU's `ur_rtde` `RTDEReceiveInterface` asks for by default on PolyScope 5.11+.
pub(crate) fn ur_rtde_default_outputs() -> Vec<String> {
    let mut names: Vec<String> = [
        "timestamp",
        "target_q",
        "target_qd",
        "target_qdd",
        "target_current",
        "target_moment",
        "actual_q",
        "actual_qd",
        "actual_current",
        "joint_control_output",
        "actual_TCP_pose",
        "actual_TCP_speed",
        "actual_TCP_force",
        "target_TCP_pose",
        "target_TCP_speed",
        "actual_digital_input_bits",
        "joint_temperatures",
        "actual_execution_time",
        "robot_mode",
        "joint_mode",
        "safety_mode",
        "actual_tool_accelerometer",
        "speed_scaling",
        "target_speed_fraction",
        "actual_momentum",
        "actual_main_voltage",
        "actual_robot_voltage",
        "actual_robot_current",
        "actual_joint_voltage",
        "actual_digital_output_bits",
        "runtime_state",
        "standard_analog_input0",
        "standard_analog_input1",
        "standard_analog_output0",
        "standard_analog_output1",
        "robot_status_bits",
        "safety_status_bits",
        "ft_raw_wrench",
        "payload",
        "payload_cog",
        "payload_inertia",
        "output_int_register_2",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    names.extend((12..=19).map(|i| format!("output_int_register_{i}")));
    names.extend((12..=19).map(|i| format!("output_double_register_{i}")));
    names
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ur_rtde_defaults_are_all_known() {
        let names = ur_rtde_default_outputs();
        assert_eq!(names.len(), 58);
        for name in &names {
            assert!(output_type(name).is_some(), "{name} would be NOT_FOUND");
        }
    }

    #[test]
    fn types_of_common_fields() {
        assert_eq!(output_type("actual_q"), Some(Vector6d));
        assert_eq!(output_type("robot_mode"), Some(Int32));
        assert_eq!(output_type("runtime_state"), Some(Uint32));
        assert_eq!(output_type("output_bit_register_64"), Some(Bool));
        assert_eq!(output_type("input_double_register_47"), Some(Double));
        assert_eq!(input_type("input_int_register_0"), Some(Int32));
        assert_eq!(input_type("input_bit_register_127"), Some(Bool));
    }

    #[test]
    fn out_of_range_and_malformed_registers_are_unknown() {
        for name in
            ["output_int_register_48", "input_bit_register_63", "input_bit_register_128", "input_int_register_01"]
        {
            assert_eq!(output_type(name), None, "{name}");
        }
        assert_eq!(input_type("output_int_register_0"), None);
        assert_eq!(input_type("actual_q"), None);
        assert_eq!(output_type("no_such_field"), None);
    }

    #[test]
    fn names_once_answered_not_found_have_urs_types() {
        assert_eq!(output_type("tcp_offset"), Some(Vector6d));
        assert_eq!(output_type("actual_configurable_digital_input_bits"), Some(Uint64));
        assert_eq!(output_type("actual_configurable_digital_output_bits"), Some(Uint64));
        assert_eq!(output_type("encoder0_raw"), Some(Int32));
        assert_eq!(output_type("encoder1_raw"), Some(Int32));
    }

    #[test]
    fn newer_controllers_outputs_are_served_or_not_found() {
        assert_eq!(output_type("actual_TCP_acceleration"), Some(Vector6d));
        assert_eq!(output_type("target_TCP_acceleration"), Some(Vector6d));
        assert_eq!(output_type("target_gravity"), Some(Vector3d));
        for (name, why) in NOT_SERVED {
            assert_eq!(output_type(name), None, "{name} is answered NOT_FOUND: {why}");
        }
    }

    #[test]
    fn twin_outputs_are_known() {
        for name in TWIN_OUTPUTS {
            assert!(output_type(name).is_some(), "{name}");
        }
    }
}
