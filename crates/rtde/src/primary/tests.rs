//! The primary interface's packages byte for byte against the layouts of UR's "Client
//! Interfaces" document (the fields listed in its order, assembled by hand here), their sizes
//! against a UR5e's robot state from URSim 5.8, and decoding back what was encoded.

use super::message::{kind as msg, source};
use super::state::*;
use super::*;
use tendril_codec::Decoded;

fn robot_mode() -> RobotModeData {
    RobotModeData {
        timestamp: 0x0102_0304_0506_0708,
        is_real_robot_connected: true,
        is_real_robot_enabled: true,
        is_robot_power_on: true,
        is_emergency_stopped: false,
        is_protective_stopped: true,
        is_program_running: true,
        is_program_paused: false,
        robot_mode: 7,
        control_mode: 0,
        target_speed_fraction: 0.5,
        speed_scaling: 1.0,
        target_speed_fraction_limit: 1.0,
    }
}

fn joints() -> [Joint; 6] {
    std::array::from_fn(|k| Joint {
        q_actual: k as f64,
        q_target: k as f64 + 0.5,
        qd_actual: -(k as f64),
        i_actual: 0.25,
        v_actual: 48.0,
        t_motor: 30.0,
        t_micro: 0.0,
        mode: 253,
    })
}

/// The nominal UR5e's DH parameters (UR's published table).
fn ur5e_kinematics() -> KinematicsInfo {
    let half_pi = std::f64::consts::FRAC_PI_2;
    KinematicsInfo {
        checksum: [7; 6],
        dh_theta: [0.0; 6],
        dh_a: [0.0, -0.425, -0.3922, 0.0, 0.0, 0.0],
        dh_d: [0.1625, 0.0, 0.0, 0.1333, 0.0997, 0.0996],
        dh_alpha: [half_pi, 0.0, 0.0, half_pi, -half_pi, 0.0],
        calibration_status: 2,
    }
}

/// One of every sub-package the virtual UR5e sends.
fn every_sub_package() -> Vec<SubPackage> {
    let k = ur5e_kinematics();
    vec![
        SubPackage::RobotMode(robot_mode()),
        SubPackage::Joints(joints()),
        SubPackage::Cartesian(CartesianInfo { tcp_pose: [0.1, 0.2, 0.3, 0.0, 3.1, 0.0], tcp_offset: [0.0; 6] }),
        SubPackage::Kinematics(k.clone()),
        SubPackage::Calibration([0.0; 6]),
        SubPackage::Masterboard(MasterboardData {
            digital_input_bits: 0x0003_0001,
            digital_output_bits: 0x80,
            analog_input_range: [1, 1],
            analog_input: [0.0, 0.0],
            analog_output_domain: [0, 1],
            analog_output: [0.004, 5.0],
            temperature: 24.0,
            robot_voltage_48v: 48.0,
            robot_current: 0.5,
            io_current: 0.0,
            safety_mode: 1,
            in_reduced_mode: false,
            reserved: 0,
            operational_mode_selector_input: 1,
            three_position_enabling_device_input: 1,
            reserved_2: 1,
        }),
        SubPackage::Tool(ToolData {
            analog_input_range: [1, 1],
            analog_input: [0.0, 0.0],
            voltage_48v: 24.0,
            output_voltage: 24,
            current: 0.1,
            temperature: 30.0,
            mode: 253,
        }),
        SubPackage::Configuration(ConfigurationData {
            joint_position_limits: [(-6.3, 6.3); 6],
            joint_motion_limits: [(3.0, 40.0); 6],
            v_joint_default: 1.0,
            a_joint_default: 1.4,
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
        SubPackage::ForceMode(ForceModeData { wrench: [0.0, 0.0, -2.5, 0.0, 0.0, 0.0], robot_dexterity: 0.0 }),
        SubPackage::Additional(AdditionalInfo {
            tp_button_state: 0,
            freedrive_button_enabled: true,
            io_enabled_freedrive: false,
            reserved: 1,
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
    ]
}

#[test]
fn each_sub_package_has_the_size_a_ur5e_sends() {
    // Sizes of a UR5e's robot state sub-packages as URSim 5.8 sends them (header included).
    let expected = [
        (0u8, 47usize),
        (1, 251),
        (4, 101),
        (5, 225),
        (9, 53),
        (3, 75),
        (2, 37),
        (6, 445),
        (7, 61),
        (8, 9),
        (11, 26),
        (12, 8),
    ];
    let subs = every_sub_package();
    for (sub, (kind, size)) in subs.iter().zip(expected) {
        let bytes = sub.encode();
        assert_eq!(sub.kind(), kind);
        assert_eq!(bytes.len(), size, "sub-package {kind}");
        assert_eq!(u32::from_be_bytes(bytes[..4].try_into().unwrap()) as usize, size, "its size field");
        assert_eq!(bytes[4], kind, "its type byte");
    }
    let whole = Package::State(subs).encode().unwrap();
    assert_eq!(whole.len(), 5 + expected.iter().map(|(_, s)| s).sum::<usize>());
    assert_eq!(whole[4], ROBOT_STATE);
}

#[test]
fn robot_mode_data_is_byte_for_byte_the_documented_layout() {
    let mut expected = vec![0, 0, 0, 47, 0];
    expected.extend_from_slice(&0x0102_0304_0506_0708_u64.to_be_bytes());
    // isRealRobotConnected, Enabled, PowerOn, EmergencyStopped, ProtectiveStopped, ProgramRunning,
    // ProgramPaused.
    expected.extend_from_slice(&[1, 1, 1, 0, 1, 1, 0]);
    // robotMode, controlMode.
    expected.extend_from_slice(&[7, 0]);
    for v in [0.5f64, 1.0, 1.0] {
        expected.extend_from_slice(&v.to_be_bytes());
    }
    // reserved.
    expected.push(0);
    assert_eq!(SubPackage::RobotMode(robot_mode()).encode(), expected);
}

#[test]
fn joint_data_interleaves_each_joints_fields() {
    let bytes = SubPackage::Joints(joints()).encode();
    // Joint k starts at 5 + 41 k: q_actual, q_target, qd_actual, I, V, T_motor, T_micro, mode.
    for k in 0..6 {
        let at = 5 + 41 * k;
        let f64_at = |o: usize| f64::from_be_bytes(bytes[at + o..at + o + 8].try_into().unwrap());
        let f32_at = |o: usize| f32::from_be_bytes(bytes[at + o..at + o + 4].try_into().unwrap());
        assert_eq!(f64_at(0), k as f64);
        assert_eq!(f64_at(8), k as f64 + 0.5);
        assert_eq!(f64_at(16), -(k as f64));
        assert_eq!([f32_at(24), f32_at(28), f32_at(32), f32_at(36)], [0.25, 48.0, 30.0, 0.0]);
        assert_eq!(bytes[at + 40], 253);
    }
}

#[test]
fn kinematics_info_is_checksums_then_theta_a_d_alpha_then_status() {
    let k = ur5e_kinematics();
    let bytes = SubPackage::Kinematics(k.clone()).encode();
    assert_eq!(&bytes[5..9], &[0, 0, 0, 7]);
    let f64_at = |o: usize| f64::from_be_bytes(bytes[o..o + 8].try_into().unwrap());
    let base = 5 + 24;
    assert_eq!(f64_at(base + 48 + 8), -0.425, "a[1] after six thetas");
    assert_eq!(f64_at(base + 96), 0.1625, "d[0]");
    assert_eq!(f64_at(base + 144), std::f64::consts::FRAC_PI_2, "alpha[0]");
    assert_eq!(&bytes[221..225], &[0, 0, 0, 2], "calibration status, a u32");
}

#[test]
fn the_nominal_ur5e_kinematics_give_the_client_librarys_ursim_checksum() {
    // The checksum UR's client library compares (its examples' CALIBRATION_CHECKSUM, URSim's
    // UR5e): the nominal DH table reproduces it.
    assert_eq!(ur5e_kinematics().client_library_checksum(), "calib_12788084448423163542");
    let mut off = ur5e_kinematics();
    off.dh_d[0] += 1e-3;
    assert_ne!(off.client_library_checksum(), "calib_12788084448423163542");
}

#[test]
fn masterboard_data_leaves_out_the_euromap_fields_and_reads_past_them() {
    let SubPackage::Masterboard(m) = &every_sub_package()[5] else { unreachable!() };
    let bytes = SubPackage::Masterboard(m.clone()).encode();
    assert_eq!(&bytes[5..13], &[0, 3, 0, 1, 0, 0, 0, 0x80], "digital input and output bits, u32 each");
    // safetyMode, InReducedMode, euromap67InterfaceInstalled, then the reserved u32.
    assert_eq!(&bytes[65..68], &[1, 0, 0]);
    assert_eq!(&bytes[68..72], &[0, 0, 0, 0]);
    assert_eq!(&bytes[72..75], &[1, 1, 1]);
    // With a Euromap67 interface the body has 16 bytes more, which a decoder skips.
    let mut with_euromap = bytes[5..67].to_vec();
    with_euromap.push(1);
    with_euromap.extend_from_slice(&[9; 16]);
    with_euromap.extend_from_slice(&bytes[68..]);
    assert_eq!(SubPackage::decode(kind::MASTERBOARD_DATA, &with_euromap).unwrap(), SubPackage::Masterboard(m.clone()));
}

fn message(body: RobotMessage) -> Package {
    Package::Message(Message { timestamp: 0, source: source::ROBOT_INTERFACE, body })
}

/// The header of a robot message of `size` bytes and type `kind`: size, 20, timestamp 0, source -2.
fn message_header(size: u8, kind: u8) -> Vec<u8> {
    let mut h = vec![0, 0, 0, size, 20];
    h.extend_from_slice(&[0; 8]);
    h.extend_from_slice(&[0xfe, kind]);
    h
}

#[test]
fn the_version_message_is_byte_for_byte_the_documented_layout() {
    let bytes = message(RobotMessage::Version(Version {
        project_name: "URControl".into(),
        major: 5,
        minor: 11,
        bugfix: 1,
        build: 108_318,
        build_date: "23-03-2021, 00:00:00".into(),
    }))
    .encode()
    .unwrap();
    let mut expected = message_header(55, msg::VERSION);
    expected.push(9);
    expected.extend_from_slice(b"URControl");
    expected.extend_from_slice(&[5, 11, 0, 0, 0, 1]);
    expected.extend_from_slice(&108_318_i32.to_be_bytes());
    expected.extend_from_slice(b"23-03-2021, 00:00:00");
    assert_eq!(bytes, expected);
}

#[test]
fn key_and_runtime_exception_messages_are_byte_for_byte_the_documented_layout() {
    let key =
        message(RobotMessage::Key { code: 0, argument: 0, title: "PROGRAM_XXX_STARTED".into(), text: "prog".into() })
            .encode()
            .unwrap();
    let mut expected = message_header(15 + 8 + 1 + 19 + 4, msg::KEY);
    expected.extend_from_slice(&[0; 8]);
    expected.push(19);
    expected.extend_from_slice(b"PROGRAM_XXX_STARTEDprog");
    assert_eq!(key, expected);

    let exception = message(RobotMessage::RuntimeException { line: 3, column: 0, text: "name_not_found:x".into() })
        .encode()
        .unwrap();
    let mut expected = message_header(15 + 8 + 16, msg::RUNTIME_EXCEPTION);
    expected.extend_from_slice(&[0, 0, 0, 3, 0, 0, 0, 0]);
    expected.extend_from_slice(b"name_not_found:x");
    assert_eq!(exception, expected);

    let error = message(RobotMessage::ErrorCode {
        code: 210,
        argument: 0,
        level: message::report_level::VIOLATION,
        data_type: 0,
        data: 0,
        text: "".into(),
    })
    .encode()
    .unwrap();
    let mut expected = message_header(15 + 20, msg::ERROR_CODE);
    expected.extend_from_slice(&[0, 0, 0, 210, 0, 0, 0, 0, 0, 0, 0, 3, 0, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(error, expected);

    let safety =
        message(RobotMessage::SafetyMode { code: 0, argument: 0, mode: 3, data_type: 0, data: 1 }).encode().unwrap();
    let mut expected = message_header(32, msg::SAFETY_MODE);
    expected.extend_from_slice(&[0, 0, 0, 0, 0, 0, 0, 0, 3, 0, 0, 0, 0, 0, 0, 0, 1]);
    assert_eq!(safety, expected);
}

#[test]
fn every_package_decodes_to_what_was_encoded() {
    let packages = vec![
        Package::State(every_sub_package()),
        message(RobotMessage::Text("hello".into())),
        message(RobotMessage::ProgramLabel { id: 4, text: "label".into() }),
        message(RobotMessage::Popup {
            request_id: 0,
            requested_type: 8,
            warning: true,
            error: false,
            blocking: false,
            title: "Popup".into(),
            text: "text".into(),
        }),
        message(RobotMessage::Key { code: 1, argument: 2, title: "PROGRAM_XXX_STOPPED".into(), text: "p".into() }),
        Package::Other { kind: 25, body: vec![1, 2, 3] },
    ];
    let mut stream: Vec<u8> = packages.iter().flat_map(|p| p.encode().unwrap()).collect();
    for expected in &packages {
        match Package::decode(&stream) {
            Decoded::Frame { packet, consumed } => {
                assert_eq!(&packet, expected);
                stream.drain(..consumed);
            }
            other => panic!("{other:?}"),
        }
    }
    assert!(stream.is_empty());
}

#[test]
fn partial_and_malformed_packages_are_told_apart() {
    let bytes = Package::State(every_sub_package()).encode().unwrap();
    for cut in [0, 3, 5, 100, bytes.len() - 1] {
        assert_eq!(Package::decode(&bytes[..cut]), Decoded::NeedMore, "cut at {cut}");
    }
    assert!(matches!(Package::decode(&[0, 0, 0, 2, 16]), Decoded::Invalid { error: PrimaryError::BadSize(2), .. }));
    assert!(matches!(Package::decode(&[0xff, 0xff, 0xff, 0xff, 16]), Decoded::Invalid { .. }));
    // A sub-package whose size runs past its package.
    let mut broken = bytes.clone();
    broken[8] = 0xff;
    assert!(matches!(Package::decode(&broken), Decoded::Invalid { .. }));
    // A body cut short inside a sub-package's fields.
    let short = [0u8, 0, 0, 15, 16, 0, 0, 0, 10, 0, 1, 2, 3, 4, 5];
    assert!(matches!(Package::decode(&short), Decoded::Invalid { error: PrimaryError::Truncated { .. }, .. }));
    // A title longer than its length byte cannot be encoded.
    let long = message(RobotMessage::Key { code: 0, argument: 0, title: "x".repeat(256), text: String::new() });
    assert_eq!(long.encode(), Err(PrimaryError::TooLong(256)));
}
