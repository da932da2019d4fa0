//! Byte-for-byte checks against a third party's encoder, round trips, schemas and names.
//!
//! The expected payloads were serialised by the `rosbags` package (0.11.9, PyPI;
//! `get_typestore(Stores.ROS2_HUMBLE).serialize_cdr(...)`), a CDR implementation that shares no
//! code with this crate, for the values each test builds.

use super::*;
use proptest::prelude::*;

fn hex(s: &str) -> Vec<u8> {
    (0..s.len()).step_by(2).map(|i| u8::from_str_radix(&s[i..i + 2], 16).unwrap()).collect()
}

fn same_as_rosbags<M: Message + PartialEq + std::fmt::Debug>(m: &M, expected_hex: &str) {
    let expected = hex(expected_hex);
    assert_eq!(to_payload(m), expected, "{}", M::TYPE.name);
    assert_eq!(&from_payload::<M>(&expected).unwrap(), m);
}

#[test]
fn joint_state_bytes_are_what_rosbags_writes() {
    let m = JointState {
        header: Header::at(12.5, "base"),
        name: vec!["elbow_joint".into(), "twine_motor_joint".into()],
        position: vec![1.5, -0.25],
        velocity: vec![0.125],
        effort: vec![],
    };
    same_as_rosbags(
        &m,
        "000100000c0000000065cd1d050000006261736500000000020000000c000000656c626f775f6a6f696e7400120000007477696e655f6d6f746f725f6a6f696e740000000200000000000000000000000000f83f000000000000d0bf0100000000000000000000000000c03f00000000",
    );
}

#[test]
fn wrench_clock_and_peaks_bytes_are_what_rosbags_writes() {
    let mut w = WrenchStamped::force_z(1.0, "fbg_pad0", 0.75);
    w.header.stamp.nanosec = 2;
    same_as_rosbags(
        &w,
        "000100000100000002000000090000006662675f706164300000000000000000000000000000000000000000000000000000e83f000000000000000000000000000000000000000000000000",
    );
    same_as_rosbags(&Clock { clock: Time::from_secs_f64(3.01) }, "000100000300000080969800");
    let peaks = FbgPeaks {
        header: Header::at(0.01, "fbg_pad0"),
        grating: vec!["pad0/fbg1".into(), "pad0/fbg2".into()],
        wavelength_nm: vec![1545.125, 1550.5],
    };
    same_as_rosbags(
        &peaks,
        "000100000000000080969800090000006662675f7061643000000000020000000a000000706164302f666267310000000a000000706164302f6662673200000002000000000000008024984000000000003a9840",
    );
}

#[test]
fn dds_type_names_are_the_middlewares() {
    assert_eq!(JointState::TYPE.dds_name(), "sensor_msgs::msg::dds_::JointState_");
    assert_eq!(Clock::TYPE.dds_name(), "rosgraph_msgs::msg::dds_::Clock_");
    assert_eq!(graph::ParticipantEntitiesInfo::INFO.dds_name(), "rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_");
    assert_eq!(FbgPeaks::TYPE.package(), "tendril_msgs");
}

#[test]
fn a_schema_carries_every_nested_definition_once() {
    let s = WrenchStamped::TYPE.schema();
    assert!(s.starts_with("std_msgs/Header header\nWrench wrench\n"), "{s}");
    for msg in [
        "MSG: std_msgs/Header",
        "MSG: builtin_interfaces/Time",
        "MSG: geometry_msgs/Wrench",
        "MSG: geometry_msgs/Vector3",
    ] {
        assert_eq!(s.matches(msg).count(), 1, "{msg} in\n{s}");
    }
    assert_eq!(s.matches(SCHEMA_SEPARATOR).count(), 4);
}

#[test]
fn times_round_to_the_nanosecond_and_carry() {
    assert_eq!(Time::from_secs_f64(1.9999999999), Time { sec: 2, nanosec: 0 });
    assert_eq!(Time::from_secs_f64(-0.5), Time { sec: -1, nanosec: 500_000_000 });
    assert_eq!(Time::from_secs_f64(0.01).as_nanos(), 10_000_000);
    assert_eq!(Time { sec: 3, nanosec: 250_000_000 }.as_secs_f64(), 3.25);
}

#[test]
fn the_graph_info_has_the_distributions_gid_length() {
    use graph::{Gid, GidFormat, NodeEntitiesInfo, ParticipantEntitiesInfo};
    let node = NodeEntitiesInfo {
        node_namespace: "/".into(),
        node_name: "tendril".into(),
        reader_gid_seq: vec![Gid([1; 16])],
        writer_gid_seq: vec![Gid([2; 16]), Gid([3; 16])],
    };
    for (format, len) in [(GidFormat::Humble, 24), (GidFormat::Iron, 16)] {
        let info = ParticipantEntitiesInfo { format, gid: Gid([9; 16]), node_entities_info_seq: vec![node.clone()] };
        let mut w = CdrWriter::new();
        info.encode(&mut w);
        let bytes = w.into_bytes();
        // gid, node count, two strings (4+2 "/", 4+8 "tendril"), then 1 + 2 gids with their counts.
        let strings = 4 + 2 + 2 + 4 + 8;
        assert_eq!(bytes.len(), len + 4 + strings + 4 + len + 4 + 2 * len);
        assert_eq!(ParticipantEntitiesInfo::decode(format, &mut CdrReader::new(&bytes)).unwrap(), info);
    }
}

fn finite() -> impl Strategy<Value = f64> {
    prop::num::f64::NORMAL | prop::num::f64::ZERO
}

proptest! {
    #[test]
    fn joint_states_round_trip(
        sec in any::<i32>(), nanosec in 0u32..1_000_000_000, frame in "[a-z_]{0,12}",
        name in prop::collection::vec("[a-z_0-9]{0,20}", 0..10),
        position in prop::collection::vec(finite(), 0..10),
        velocity in prop::collection::vec(finite(), 0..10),
    ) {
        let m = JointState { header: Header { stamp: Time { sec, nanosec }, frame_id: frame }, name, position, velocity, effort: vec![] };
        prop_assert_eq!(from_payload::<JointState>(&to_payload(&m)).unwrap(), m);
    }

    #[test]
    fn control_ticks_round_trip(phase in "[a-z]{0,8}", x in finite(), on in any::<bool>(), pads in prop::collection::vec(finite(), 0..8)) {
        let m = ControlTick { phase, force_n: x, over_range: on, pad_force_n: pads.clone(), pad_true_force_n: pads, ..ControlTick::default() };
        prop_assert_eq!(from_payload::<ControlTick>(&to_payload(&m)).unwrap(), m);
    }

    #[test]
    fn arbitrary_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..200)) {
        let _ = from_payload::<JointState>(&bytes);
        let _ = from_payload::<ControlTick>(&bytes);
        let _ = from_body::<FbgPeaks>(&bytes);
        let _ = graph::ParticipantEntitiesInfo::decode(graph::GidFormat::Humble, &mut CdrReader::new(&bytes));
    }

    #[test]
    fn truncated_messages_are_errors(cut in 0usize..60) {
        let m = JointState { name: vec!["shoulder_pan_joint".into()], position: vec![1.0], ..JointState::default() };
        let payload = to_payload(&m);
        if cut < payload.len() - 4 {
            prop_assert!(from_payload::<JointState>(&payload[..cut]).is_err());
        }
    }
}
