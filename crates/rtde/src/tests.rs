//! Session tests: the virtual controller against our client and against ur_rtde's byte sequence.

use super::fields::output_type;
use super::*;
use tendril_codec::Decoded;

fn decode_all(mut bytes: &[u8]) -> Vec<ServerPacket> {
    let mut packets = Vec::new();
    while !bytes.is_empty() {
        match ServerPacket::decode(bytes) {
            Decoded::Frame { packet, consumed } => {
                packets.push(packet);
                bytes = &bytes[consumed..];
            }
            other => panic!("bad server bytes: {other:?}"),
        }
    }
    packets
}

#[test]
fn ur_rtde_receive_handshake_byte_sequence() {
    let mut server = ServerSession::new(1, ServerConfig::default());
    let mut shared = SharedInputs::new();
    let names = super::fields::ur_rtde_default_outputs();
    assert_eq!(names.len(), 58);

    // What RTDEReceiveInterface sends: V (as 00 02), v, v, O at 500 Hz with a trailing comma, S.
    let mut wire = vec![0x00, 0x05, b'V', 0x00, 0x02, 0x00, 0x03, b'v', 0x00, 0x03, b'v'];
    let mut payload = 500.0f64.to_be_bytes().to_vec();
    for n in &names {
        payload.extend_from_slice(n.as_bytes());
        payload.push(b',');
    }
    wire.extend_from_slice(&((payload.len() + 3) as u16).to_be_bytes());
    wire.push(b'O');
    wire.extend_from_slice(&payload);
    wire.extend_from_slice(&[0x00, 0x03, b'S']);

    let replies = decode_all(&server.feed(&mut wire, &mut shared).unwrap());
    assert!(wire.is_empty());
    assert_eq!(replies.len(), 5, "exactly one reply per request, no text messages");
    assert_eq!(replies[0], ServerPacket::ProtocolVersion { accepted: true });
    assert!(matches!(replies[1], ServerPacket::ControllerVersion(v) if v.major == 5 && v.minor >= 11));
    assert_eq!(replies[1], replies[2]);
    let ServerPacket::SetupOutputs { recipe_id, types } = &replies[3] else { panic!("{:?}", replies[3]) };
    assert_eq!(*recipe_id, 1);
    assert_eq!(types.len(), 58);
    assert!(types.iter().all(|t| matches!(t, FieldType::Known(_))));
    assert_eq!(replies[4], ServerPacket::Start { accepted: true });

    let outputs = RobotOutputs { actual_q: [-1.5, -1.5, 1.5, -1.5, -1.5, 0.0], ..RobotOutputs::default() };
    let data = server.poll_outputs(0.0, &outputs, &shared);
    let ServerPacket::Data { recipe_id: 1, data } = &data[0] else { panic!("no data package") };
    let recipe = server.output_recipes().next().unwrap().0.clone();
    assert_eq!(data.len(), recipe.data_len());
    let values = recipe.decode(data).unwrap();
    assert_eq!(values[recipe.index_of("actual_q").unwrap()], RtdeValue::Vector6d(outputs.actual_q));
    assert_eq!(values[recipe.index_of("robot_mode").unwrap()], RtdeValue::Int32(7));
}

#[test]
fn unknown_names_get_not_found_and_an_invalid_recipe() {
    let mut server = ServerSession::new(1, ServerConfig::default());
    let mut shared = SharedInputs::new();
    server.handle(ClientPacket::RequestProtocolVersion { version: 2 }, &mut shared);
    let reply = server.handle(
        ClientPacket::SetupOutputs { frequency_hz: 125.0, names: vec!["actual_q".into(), "warp_drive".into()] },
        &mut shared,
    );
    assert_eq!(
        reply,
        vec![ServerPacket::SetupOutputs {
            recipe_id: 0,
            types: vec![FieldType::Known(RtdeType::Vector6d), FieldType::NotFound]
        }]
    );
    // Nothing valid to stream: start is refused.
    assert_eq!(server.handle(ClientPacket::Start, &mut shared), vec![ServerPacket::Start { accepted: false }]);
}

#[test]
fn version_other_than_2_is_refused_and_setup_needs_negotiation() {
    let mut server = ServerSession::new(1, ServerConfig::default());
    let mut shared = SharedInputs::new();
    let r = server.handle(ClientPacket::RequestProtocolVersion { version: 1 }, &mut shared);
    assert_eq!(r, vec![ServerPacket::ProtocolVersion { accepted: false }]);
    let r =
        server.handle(ClientPacket::SetupOutputs { frequency_hz: 10.0, names: vec!["actual_q".into()] }, &mut shared);
    assert!(matches!(r[0], ServerPacket::SetupOutputs { recipe_id: 0, .. }));
}

#[test]
fn inputs_claimed_by_another_connection_are_in_use_until_released() {
    let mut shared = SharedInputs::new();
    let mut a = ServerSession::new(1, ServerConfig::default());
    let mut b = ServerSession::new(2, ServerConfig::default());
    for s in [&mut a, &mut b] {
        s.handle(ClientPacket::RequestProtocolVersion { version: 2 }, &mut shared);
    }
    let names = vec!["input_int_register_0".to_string(), "input_double_register_0".to_string()];
    let ra = a.handle(ClientPacket::SetupInputs { names: names.clone() }, &mut shared);
    assert!(matches!(ra[0], ServerPacket::SetupInputs { recipe_id: 1, .. }));
    // The same connection may reuse its registers in another recipe (ur_rtde does).
    let ra2 = a.handle(ClientPacket::SetupInputs { names: names[..1].to_vec() }, &mut shared);
    assert!(matches!(ra2[0], ServerPacket::SetupInputs { recipe_id: 2, .. }));
    let rb = b.handle(ClientPacket::SetupInputs { names: names.clone() }, &mut shared);
    assert_eq!(rb, vec![ServerPacket::SetupInputs { recipe_id: 0, types: vec![FieldType::InUse, FieldType::InUse] }]);
    shared.release(1);
    let rb = b.handle(ClientPacket::SetupInputs { names }, &mut shared);
    assert!(matches!(rb[0], ServerPacket::SetupInputs { recipe_id: 1, .. }));
}

#[test]
fn client_and_server_sessions_talk() {
    let mut shared = SharedInputs::new();
    let mut server = ServerSession::new(7, ServerConfig::default());
    let mut client = ClientSession::new();
    let mut to_server = Vec::new();
    let mut to_client = Vec::new();
    let mut exchange = |packet: ClientPacket, client: &mut ClientSession, server: &mut ServerSession| {
        to_server.extend_from_slice(&packet.encode().unwrap());
        to_client.extend_from_slice(&server.feed(&mut to_server, &mut shared).unwrap());
        client.feed(&mut to_client).unwrap()
    };
    let p = client.request_protocol_version();
    assert_eq!(exchange(p, &mut client, &mut server), vec![ClientEvent::ProtocolVersion { accepted: true }]);
    let p = client.setup_outputs(500.0, &["timestamp", "actual_q", "runtime_state", "input_int_register_1"]).unwrap();
    let events = exchange(p, &mut client, &mut server);
    assert!(matches!(&events[0], ClientEvent::OutputRecipe(r) if r.id == 1));
    let p = client.setup_inputs(&["input_double_register_0", "input_int_register_1"]).unwrap();
    let events = exchange(p, &mut client, &mut server);
    assert!(matches!(&events[0], ClientEvent::InputRecipe(r) if r.id == 1));
    let p = client.start();
    assert_eq!(exchange(p, &mut client, &mut server), vec![ClientEvent::Started { accepted: true }]);
    let p = client.input_data(1, &[RtdeValue::Double(0.25), RtdeValue::Int32(42)]).unwrap();
    assert!(exchange(p, &mut client, &mut server).is_empty());
    assert_eq!(shared.values.double_registers[0], 0.25);
    assert_eq!(shared.values.int_registers[1], 42);
    assert_eq!(shared.packages, 1, "each input package is counted (the arm's command cadence)");

    let outputs = RobotOutputs { timestamp_s: 1.25, ..RobotOutputs::default() };
    let mut to_client: Vec<u8> = Vec::new();
    for p in server.poll_outputs(1.25, &outputs, &shared) {
        to_client.extend_from_slice(&p.encode().unwrap());
    }
    let events = client.feed(&mut to_client).unwrap();
    assert_eq!(
        events,
        vec![ClientEvent::Data {
            recipe_id: 1,
            values: vec![
                RtdeValue::Double(1.25),
                RtdeValue::Vector6d([0.0; 6]),
                RtdeValue::Uint32(2),
                RtdeValue::Int32(42)
            ]
        }]
    );
    // A refused recipe is an error naming the field.
    let p = client.setup_outputs(10.0, &["actual_q", "nope"]).unwrap();
    to_server.extend_from_slice(&p.encode().unwrap());
    let mut replies = server.feed(&mut to_server, &mut shared).unwrap();
    let err = client.feed(&mut replies).unwrap_err();
    assert_eq!(err, RtdeError::RecipeRejected { not_found: vec!["nope".into()], in_use: vec![] });
}

#[test]
fn outputs_follow_the_recipe_frequency() {
    let mut shared = SharedInputs::new();
    let mut server = ServerSession::new(1, ServerConfig::default());
    server.handle(ClientPacket::RequestProtocolVersion { version: 2 }, &mut shared);
    server.handle(ClientPacket::SetupOutputs { frequency_hz: 125.0, names: vec!["timestamp".into()] }, &mut shared);
    let outputs = RobotOutputs::default();
    assert!(server.poll_outputs(0.0, &outputs, &shared).is_empty(), "nothing before start");
    server.handle(ClientPacket::Start, &mut shared);
    // 500 Hz ticks for 0.1 s: a 125 Hz recipe yields every 4th tick.
    let count: usize = (0..50).map(|k| server.poll_outputs(k as f64 * 0.002, &outputs, &shared).len()).sum();
    assert_eq!(count, 13);
    server.handle(ClientPacket::Pause, &mut shared);
    assert!(server.poll_outputs(1.0, &outputs, &shared).is_empty());
}

#[test]
fn bad_input_package_gets_an_error_message_not_a_panic() {
    let mut shared = SharedInputs::new();
    let mut server = ServerSession::new(1, ServerConfig::default());
    server.handle(ClientPacket::RequestProtocolVersion { version: 2 }, &mut shared);
    let r = server.handle(ClientPacket::Data { recipe_id: 9, data: vec![1, 2] }, &mut shared);
    assert!(matches!(&r[0], ServerPacket::Text(t) if t.level == MessageLevel::Error));
    assert!(output_type("actual_q").is_some());
}

#[test]
fn newer_controllers_outputs_are_typed_valued_or_not_found() {
    let mut server = ServerSession::new(1, ServerConfig::default());
    let mut shared = SharedInputs::new();
    server.handle(ClientPacket::RequestProtocolVersion { version: 2 }, &mut shared);
    let served =
        ["actual_TCP_acceleration", "target_TCP_acceleration", "target_gravity", "target_TCP_speed", "payload"];
    let names: Vec<String> = served.iter().map(|s| s.to_string()).collect();
    let reply = server.handle(ClientPacket::SetupOutputs { frequency_hz: 125.0, names }, &mut shared);
    let ServerPacket::SetupOutputs { recipe_id: 1, types } = &reply[0] else { panic!("{reply:?}") };
    use RtdeType::*;
    let known = [Vector6d, Vector6d, Vector3d, Vector6d, Double].map(FieldType::Known);
    assert_eq!(types, &known);
    server.handle(ClientPacket::Start, &mut shared);
    let outputs = RobotOutputs {
        actual_tcp_acceleration: [0.5, 0.0, 0.0, 0.0, 0.0, 0.1],
        target_tcp_speed: [0.0, 0.0, -0.02, 0.0, 0.0, 0.0],
        payload_kg: 2.0,
        ..RobotOutputs::default()
    };
    let data = server.poll_outputs(0.0, &outputs, &shared);
    let ServerPacket::Data { data, .. } = &data[0] else { panic!("no data package") };
    let recipe = server.output_recipes().next().unwrap().0.clone();
    let values = recipe.decode(data).unwrap();
    assert_eq!(values[0], RtdeValue::Vector6d(outputs.actual_tcp_acceleration));
    assert_eq!(values[2], RtdeValue::Vector3d([0.0, 0.0, 9.82]), "URScript's default gravity");
    assert_eq!(values[3], RtdeValue::Vector6d(outputs.target_tcp_speed));
    assert_eq!(values[4], RtdeValue::Double(2.0));

    // The names the twin cannot give are answered as a controller answers a name it lacks.
    let mut server = ServerSession::new(2, ServerConfig::default());
    server.handle(ClientPacket::RequestProtocolVersion { version: 2 }, &mut shared);
    let names: Vec<String> = super::fields::NOT_SERVED.iter().map(|(n, _)| n.to_string()).collect();
    let reply = server.handle(ClientPacket::SetupOutputs { frequency_hz: 125.0, names }, &mut shared);
    let ServerPacket::SetupOutputs { recipe_id: 0, types } = &reply[0] else { panic!("{reply:?}") };
    assert!(types.iter().all(|t| *t == FieldType::NotFound), "{types:?}");
}
