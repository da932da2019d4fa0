//! What the virtual UR5e puts in its primary and secondary interface packages
//! ([`tendril_rtde::primary`]): the version message, and the robot state made of the twin's
//! values (joints, TCP, force, IO, modes) and the UR5e's fixed description.
//!
//! - Kinematics info: the nominal UR5e's DH parameters (the twin's arm is exactly that arm), so
//!   UR's client library computes the checksum its examples expect of a UR5e,
//!   `calib_12788084448423163542` (URSim's), the same every run; calibration status 2
//!   (linearized: the twin's kinematics are known exactly), per-joint checksums 0 (our choice).
//! - Configuration data: the twin's safety limits (`tendril_ur5e::safety`: joint ranges, π rad/s),
//!   the UR5e's DH table; PolyScope's default speeds (60 °/s, 80 °/s², 0.25 m/s, 1.2 m/s²), the
//!   equivalent radius, the masterboard version (6), controller box type (4), robot type (1, UR5)
//!   and sub-type (3) as URSim 5.8's UR5e reports them; joint accelerations 40 rad/s² likewise
//!   (the twin's setpoint generator has no acceleration limit of its own).
//! - What the twin does not model (motor currents, voltages, temperatures) is 0, as RTDE serves
//!   it.

use super::state::{DeviceState, ProgramState};
use tendril_rtde::dashboard::{PolyscopeVersion, RobotMode};
use tendril_rtde::primary::message::source;
use tendril_rtde::primary::state::*;
use tendril_rtde::primary::{Message, Package, RobotMessage, Version};
use tendril_rtde::state::SAFETY_MODE_NORMAL;
use tendril_ur5e::kinematics as ur5e;
use tendril_ur5e::safety::{JOINT_RANGE_RAD, MAX_JOINT_SPEED_RAD_S};

/// Joint mode of a running joint.
const JOINT_RUNNING: u8 = 253;
/// Joint mode of a joint without power.
const JOINT_POWER_OFF: u8 = 239;

/// The UR5e's kinematics as the virtual controller reports them.
pub fn kinematics() -> KinematicsInfo {
    KinematicsInfo {
        checksum: [0; 6],
        dh_theta: [0.0; 6],
        dh_a: ur5e::A,
        dh_d: ur5e::D,
        dh_alpha: ur5e::ALPHA,
        calibration_status: 2,
    }
}

/// The version message for the PolyScope version the controller reports on its dashboard
/// (`URSoftware 5.11.1.108318 (Mar 23 2021)`: 5.11, bugfix 1, build 108318, the date in brackets).
pub fn version(s: &DeviceState) -> Package {
    let text = &s.ur.polyscope_version;
    let v =
        PolyscopeVersion::parse_reply(text).unwrap_or(PolyscopeVersion { major: 5, minor: 11, bugfix: 1, build: 0 });
    let date = text.split_once('(').map_or("", |(_, d)| d.trim_end_matches(')')).to_string();
    Package::Message(Message {
        timestamp: 0,
        source: source::ROBOT_INTERFACE,
        body: RobotMessage::Version(Version {
            project_name: "URControl".into(),
            major: v.major as u8,
            minor: v.minor as u8,
            bugfix: v.bugfix as i32,
            build: v.build as i32,
            build_date: date,
        }),
    })
}

/// The robot state now.
pub fn robot_state(s: &DeviceState) -> Package {
    let o = &s.outputs;
    let powered = !matches!(s.ur.robot_mode, RobotMode::PowerOff);
    let safety_mode = o.safety_mode as u8;
    let joints = std::array::from_fn(|j| Joint {
        q_actual: o.actual_q[j],
        q_target: o.target_q[j],
        qd_actual: o.actual_qd[j],
        i_actual: 0.0,
        v_actual: 0.0,
        t_motor: 0.0,
        t_micro: 0.0,
        mode: if powered { JOINT_RUNNING } else { JOINT_POWER_OFF },
    });
    let k = kinematics();
    let domain = |i: u32| u8::from(o.analog_io_types >> (2 + i) & 1 == 1);
    Package::State(vec![
        SubPackage::RobotMode(RobotModeData {
            timestamp: (s.status.time_s * 1e6) as u64,
            is_real_robot_connected: true,
            is_real_robot_enabled: true,
            is_robot_power_on: powered,
            is_emergency_stopped: false,
            is_protective_stopped: s.protective_stop.is_some(),
            is_program_running: s.program == ProgramState::Playing,
            is_program_paused: s.program == ProgramState::Paused,
            robot_mode: s.ur.robot_mode.rtde() as i8,
            // Teach (1) in freedrive, else position (0).
            control_mode: u8::from(s.program_setup.freedrive),
            target_speed_fraction: o.target_speed_fraction,
            speed_scaling: o.speed_scaling,
            target_speed_fraction_limit: 1.0,
        }),
        SubPackage::Joints(joints),
        SubPackage::Cartesian(CartesianInfo { tcp_pose: o.actual_tcp_pose, tcp_offset: o.tcp_offset }),
        SubPackage::Kinematics(k.clone()),
        SubPackage::Calibration([0.0; 6]),
        SubPackage::Masterboard(MasterboardData {
            digital_input_bits: 0,
            digital_output_bits: o.digital_output_bits as u32,
            analog_input_range: [0, 0],
            analog_input: [0.0, 0.0],
            analog_output_domain: [domain(0), domain(1)],
            analog_output: o.standard_analog_output,
            temperature: 0.0,
            robot_voltage_48v: 0.0,
            robot_current: 0.0,
            io_current: 0.0,
            safety_mode: if safety_mode == 0 { SAFETY_MODE_NORMAL as u8 } else { safety_mode },
            in_reduced_mode: false,
            reserved: 0,
            operational_mode_selector_input: 0,
            three_position_enabling_device_input: 0,
            reserved_2: 0,
        }),
        SubPackage::Tool(ToolData {
            analog_input_range: [0, 0],
            analog_input: [0.0, 0.0],
            voltage_48v: 0.0,
            output_voltage: o.tool_output_voltage as u8,
            current: 0.0,
            temperature: 0.0,
            mode: if powered { JOINT_RUNNING } else { JOINT_POWER_OFF },
        }),
        SubPackage::Configuration(ConfigurationData {
            joint_position_limits: JOINT_RANGE_RAD.map(|r| (-r, r)),
            joint_motion_limits: [(MAX_JOINT_SPEED_RAD_S, 40.0); 6],
            v_joint_default: 60f64.to_radians(),
            a_joint_default: 80f64.to_radians(),
            v_tool_default: 0.25,
            a_tool_default: 1.2,
            eq_radius: 0.25,
            dh_a: k.dh_a,
            dh_d: k.dh_d,
            dh_alpha: k.dh_alpha,
            dh_theta: k.dh_theta,
            masterboard_version: 6,
            controller_box_type: 4,
            robot_type: 1,
            robot_sub_type: 3,
        }),
        SubPackage::ForceMode(ForceModeData { wrench: o.actual_tcp_force, robot_dexterity: 0.0 }),
        SubPackage::Additional(AdditionalInfo {
            tp_button_state: 0,
            freedrive_button_enabled: false,
            io_enabled_freedrive: false,
            reserved: 0,
        }),
        SubPackage::ToolCommunication(ToolCommunicationInfo {
            enabled: false,
            baud_rate: 115_200,
            parity: 0,
            stop_bits: 1,
            rx_idle_chars: 1.5,
            tx_idle_chars: 3.5,
        }),
        SubPackage::ToolMode(ToolModeInfo { output_mode: 0, digital_output_mode_0: 1, digital_output_mode_1: 1 }),
    ])
}

#[cfg(test)]
mod tests {
    use super::*;
    use tendril_codec::Decoded;

    #[test]
    fn the_state_carries_the_twins_joints_and_decodes_whole() {
        let (state, _) = crate::state::shared_state(
            &tendril_drivers::HardwareConfig::default(),
            &tendril_fbg::SpectralConfig::default(),
            &crate::VirtualUrSetup::default(),
        )
        .unwrap();
        let mut s = state.lock().unwrap();
        s.outputs.actual_q = ur5e::HOME;
        s.program_setup.freedrive = true;
        let bytes = robot_state(&s).encode().unwrap();
        let Decoded::Frame { packet: Package::State(subs), consumed } = Package::decode(&bytes) else { panic!() };
        assert_eq!(consumed, bytes.len());
        assert_eq!(subs.len(), 12);
        let SubPackage::Joints(j) = &subs[1] else { panic!("{:?}", subs[1]) };
        assert_eq!(j.map(|j| j.q_actual), ur5e::HOME);
        let SubPackage::RobotMode(m) = &subs[0] else { panic!() };
        assert_eq!((m.robot_mode, m.control_mode, m.is_program_running), (7, 1, false));
        assert_eq!(kinematics().client_library_checksum(), "calib_12788084448423163542");
        let Package::Message(v) = version(&s) else { panic!() };
        let RobotMessage::Version(v) = v.body else { panic!() };
        assert_eq!((v.major, v.minor, v.bugfix, v.build, v.build_date.as_str()), (5, 11, 1, 108318, "Mar 23 2021"));
    }
}
