//! Property tests for the sans-IO protocol codecs: decoders never panic on arbitrary bytes,
//! encode -> decode round-trips, and the Dynamixel stream resynchronises after garbage.

use proptest::prelude::*;
use tendril_codec::Decoded;
use tendril_dynamixel::{self as dxl, InstructionPacket, RawPacket, StatusPacket, StreamDecoder, VirtualBus};
use tendril_hyperion::{self as hyperion, PeakFrame, PeakHeader, Request, Response, VirtualInterrogator};
use tendril_rtde::{
    self, ClientPacket, ClientSession, Recipe, RtdeType, RtdeValue, ServerConfig, ServerPacket, ServerSession,
    SharedInputs,
};

fn config() -> ProptestConfig {
    ProptestConfig { cases: 256, ..ProptestConfig::default() }
}

/// Checks the `Decoded` contract: progress on error, never past the buffer.
fn check_decoded<P, E>(d: &Decoded<P, E>, len: usize) {
    match d {
        Decoded::NeedMore => {}
        Decoded::Frame { consumed, .. } => assert!(*consumed > 0 && *consumed <= len),
        Decoded::Invalid { consumed, .. } => assert!(*consumed > 0 && *consumed <= len),
    }
}

// ---------- Dynamixel ----------

fn raw_packet() -> impl Strategy<Value = RawPacket> {
    (any::<u8>(), any::<u8>(), prop::collection::vec(prop_oneof![Just(0xFFu8), Just(0xFD), any::<u8>()], 0..120))
        .prop_map(|(id, instruction, body)| RawPacket { id, instruction, body })
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn dxl_decode_never_panics(bytes in prop::collection::vec(any::<u8>(), 0..300)) {
        let d = RawPacket::decode(&bytes);
        check_decoded(&d, bytes.len());
        if let Decoded::Frame { packet, .. } = d {
            let _ = InstructionPacket::from_raw(&packet);
            let _ = StatusPacket::from_raw(&packet);
            let mut bus = VirtualBus::with_ids(&[1, 2]).unwrap();
            let _ = bus.handle(&packet);
        }
    }

    #[test]
    fn dxl_stuffing_round_trips(body in prop::collection::vec(prop_oneof![Just(0xFFu8), Just(0xFD), any::<u8>()], 0..200)) {
        let stuffed = dxl::stuffing::stuff(&body);
        prop_assert_eq!(dxl::stuffing::unstuff(&stuffed), body);
        // Every FF FF FD in the stuffed bytes is followed by the stuffing FD.
        for i in 0..stuffed.len().saturating_sub(2) {
            if stuffed[i..i + 3] == [0xFF, 0xFF, 0xFD] {
                prop_assert_eq!(stuffed.get(i + 3), Some(&0xFD));
            }
        }
    }

    #[test]
    fn dxl_packet_round_trips(packet in raw_packet()) {
        let wire = packet.encode().unwrap();
        prop_assert_eq!(RawPacket::decode(&wire), Decoded::Frame { packet, consumed: wire.len() });
    }

    #[test]
    fn dxl_stream_finds_packet_after_garbage(
        garbage in prop::collection::vec(any::<u8>(), 0..64),
        packet in raw_packet(),
        chunk in 1usize..17,
    ) {
        let wire = packet.encode().unwrap();
        let mut stream = StreamDecoder::new();
        let mut found = Vec::new();
        let bytes: Vec<u8> = garbage.iter().chain(&wire).copied().collect();
        for piece in bytes.chunks(chunk) {
            stream.push(piece);
            while let Some(item) = stream.next_packet() {
                if let Ok(p) = item {
                    found.push(p);
                }
            }
        }
        // Garbage can itself hold a valid packet by chance; ours must be the last one found.
        prop_assert_eq!(found.last(), Some(&packet));
    }

    #[test]
    fn dxl_sync_read_round_trips(address in any::<u16>(), length in 1u16..8, ids in prop::collection::vec(0u8..253, 1..10)) {
        let packet = InstructionPacket {
            id: dxl::BROADCAST_ID,
            instruction: dxl::Instruction::SyncRead { address, length, ids },
        };
        let Decoded::Frame { packet: raw, .. } = RawPacket::decode(&packet.encode().unwrap()) else {
            return Err(TestCaseError::fail("no frame"));
        };
        prop_assert_eq!(InstructionPacket::from_raw(&raw).unwrap(), packet);
    }
}

// ---------- RTDE ----------

fn rtde_value() -> impl Strategy<Value = RtdeValue> {
    let f = prop::num::f64::NORMAL | prop::num::f64::ZERO;
    prop_oneof![
        any::<bool>().prop_map(RtdeValue::Bool),
        any::<u8>().prop_map(RtdeValue::Uint8),
        any::<u32>().prop_map(RtdeValue::Uint32),
        any::<u64>().prop_map(RtdeValue::Uint64),
        any::<i32>().prop_map(RtdeValue::Int32),
        f.prop_map(RtdeValue::Double),
        prop::array::uniform3(f).prop_map(RtdeValue::Vector3d),
        prop::array::uniform6(f).prop_map(RtdeValue::Vector6d),
        prop::array::uniform6(any::<i32>()).prop_map(RtdeValue::Vector6Int32),
        prop::array::uniform6(any::<u32>()).prop_map(RtdeValue::Vector6Uint32),
    ]
}

fn name() -> impl Strategy<Value = String> {
    "[a-zA-Z_][a-zA-Z0-9_]{0,30}"
}

fn client_packet() -> impl Strategy<Value = ClientPacket> {
    prop_oneof![
        any::<u16>().prop_map(|version| ClientPacket::RequestProtocolVersion { version }),
        Just(ClientPacket::GetControllerVersion),
        Just(ClientPacket::Start),
        Just(ClientPacket::Pause),
        (1.0f64..1000.0, prop::collection::vec(name(), 0..20))
            .prop_map(|(frequency_hz, names)| ClientPacket::SetupOutputs { frequency_hz, names }),
        prop::collection::vec(name(), 0..20).prop_map(|names| ClientPacket::SetupInputs { names }),
        (any::<u8>(), prop::collection::vec(any::<u8>(), 0..200))
            .prop_map(|(recipe_id, data)| ClientPacket::Data { recipe_id, data }),
    ]
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn rtde_decoders_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..300)) {
        check_decoded(&ClientPacket::decode(&bytes), bytes.len());
        check_decoded(&ServerPacket::decode(&bytes), bytes.len());
        if let Decoded::Frame { packet, .. } = ServerPacket::decode(&bytes) {
            let _ = ClientSession::new().handle(packet);
        }
    }

    #[test]
    fn rtde_server_survives_arbitrary_streams(
        prefix in prop::collection::vec(client_packet(), 0..6),
        junk in prop::collection::vec(any::<u8>(), 0..200),
    ) {
        let mut server = ServerSession::new(1, ServerConfig::default());
        let mut shared = SharedInputs::new();
        let mut buf = Vec::new();
        for p in &prefix {
            buf.extend_from_slice(&p.encode().unwrap());
        }
        buf.extend_from_slice(&junk);
        // Either replies or an error that closes the connection; never a panic or a hang.
        while !buf.is_empty() {
            let before = buf.len();
            if server.feed(&mut buf, &mut shared).is_err() || buf.len() == before {
                break;
            }
        }
        let _ = server.poll_outputs(0.0, &tendril_rtde::RobotOutputs::default(), &shared);
    }

    #[test]
    fn rtde_client_packets_round_trip(packet in client_packet()) {
        let wire = packet.encode().unwrap();
        prop_assert_eq!(ClientPacket::decode(&wire), Decoded::Frame { packet, consumed: wire.len() });
    }

    #[test]
    fn rtde_recipe_values_round_trip(values in prop::collection::vec(rtde_value(), 1..30), id in 1u8..=255) {
        let types: Vec<RtdeType> = values.iter().map(RtdeValue::rtde_type).collect();
        let names = (0..values.len()).map(|i| format!("f{i}")).collect();
        let recipe = Recipe { id, names, types };
        let data = recipe.encode(&values).unwrap();
        prop_assert_eq!(data.len(), recipe.data_len());
        let wire = ServerPacket::Data { recipe_id: id, data: data.clone() }.encode().unwrap();
        let Decoded::Frame { packet: ServerPacket::Data { data: got, .. }, .. } = ServerPacket::decode(&wire) else {
            return Err(TestCaseError::fail("no data frame"));
        };
        prop_assert_eq!(recipe.decode(&got).unwrap(), values);
    }
}

// ---------- HYPERION ----------

fn peak_frame() -> impl Strategy<Value = PeakFrame> {
    (
        any::<(u8, u8, u32, u64, u32, u32)>(),
        prop::collection::vec(prop::collection::vec(1460.0f64..1620.0, 0..8), 0..17),
    )
        .prop_map(|((buffer_available, version, reserved, serial_number, timestamp_s, timestamp_ns), channels)| {
            PeakFrame {
                header: PeakHeader { buffer_available, version, reserved, serial_number, timestamp_s, timestamp_ns },
                channels,
            }
        })
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn hyperion_decoders_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..300)) {
        check_decoded(&Request::decode(&bytes), bytes.len());
        check_decoded(&Response::decode(&bytes), bytes.len());
        let _ = PeakFrame::decode(&bytes);
        if let Decoded::Frame { packet, .. } = Request::decode(&bytes) {
            let mut dev = VirtualInterrogator::new(hyperion::InterrogatorConfig::default()).unwrap();
            let reply = dev.handle(&packet);
            prop_assert!(reply.encode().is_ok());
        }
    }

    #[test]
    fn hyperion_peak_frames_round_trip(frame in peak_frame()) {
        let content = frame.encode().unwrap();
        prop_assert_eq!(PeakFrame::decode(&content).unwrap(), frame.clone());
        let wire = Response::ok("", content).encode().unwrap();
        let Decoded::Frame { packet, consumed } = Response::decode(&wire) else {
            return Err(TestCaseError::fail("no frame"));
        };
        prop_assert_eq!(consumed, wire.len());
        prop_assert_eq!(PeakFrame::decode(&packet.into_result().unwrap()).unwrap(), frame);
    }

    #[test]
    fn hyperion_requests_round_trip(command in "#[A-Za-z]{1,40}", argument in "[ -~]{0,40}", options in any::<u8>()) {
        let request = Request { options, command, argument };
        let wire = request.encode().unwrap();
        prop_assert_eq!(Request::decode(&wire), Decoded::Frame { packet: request, consumed: wire.len() });
    }
}

// ---------- New command surfaces of the virtual devices ----------

/// The commands the virtual HYPERION gained for Luna's client, with arbitrary arguments.
fn luna_command() -> impl Strategy<Value = &'static str> {
    prop::sample::select(vec![
        "#SetInstrumentName",
        "#getDetectionSetting",
        "#GetChannelDetectionSettingId",
        "#SetChannelDetectionSettingID",
        "#setActiveFullSpectrumDutChannelNumbers",
        "#GetSpectrum",
        "#SetPeakDataStreamingDivider",
    ])
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn the_virtual_bus_survives_arbitrary_byte_streams(
        chunks in prop::collection::vec(prop::collection::vec(prop_oneof![Just(0xFFu8), Just(0xFD), Just(0x00), any::<u8>()], 0..80), 0..8)
    ) {
        let mut bus = VirtualBus::with_ids(&[1, 2]).unwrap();
        let mut decoder = StreamDecoder::new();
        for chunk in &chunks {
            let _ = bus.respond_to_bytes(&mut decoder, chunk);
        }
        prop_assert!(bus.ids().len() <= 2);
    }

    #[test]
    fn hyperion_commands_with_arbitrary_arguments_answer_and_never_panic(
        command in luna_command(), argument in "[ -~]{0,70}"
    ) {
        let mut dev = VirtualInterrogator::new(hyperion::InterrogatorConfig::default()).unwrap();
        let reply = dev.handle(&Request::new(command, &argument));
        prop_assert!(reply.encode().is_ok());
        // Streaming stays consistent whatever the divider became.
        dev.set_peaks(PeakFrame::default()).unwrap();
        prop_assert!(dev.stream_after(None).is_ok());
    }

    #[test]
    fn dashboard_lines_parse_without_panicking(line in "\\PC{0,60}") {
        use tendril_rtde::dashboard::{Command, PolyscopeVersion, RobotMode, SafetyStatus};
        let _ = Command::parse(&line).line();
        let _ = (RobotMode::parse_reply(&line), SafetyStatus::parse_reply(&line), PolyscopeVersion::parse_reply(&line));
    }
}

// ---------- URScript ----------

/// A controller with nothing behind it: registers read 0, writes go nowhere.
struct NullController;

impl tendril_urscript::Controller for NullController {
    fn input_int(&self, _: usize) -> i32 {
        0
    }
    fn input_float(&self, _: usize) -> f64 {
        0.0
    }
    fn input_bool(&self, _: usize) -> bool {
        false
    }
    fn set_output_int(&mut self, _: usize, _: i32) {}
    fn set_output_float(&mut self, _: usize, _: f64) {}
    fn set_output_bool(&mut self, _: usize, _: bool) {}
    fn set_digital_out(&mut self, _: tendril_urscript::DigitalOut, _: usize, _: bool) {}
    fn set_analog_out(&mut self, _: usize, _: f64) {}
    fn actual_q(&self) -> [f64; 6] {
        [0.0, -1.57, 1.57, -1.57, -1.57, 0.0]
    }
    fn actual_qd(&self) -> [f64; 6] {
        [0.0; 6]
    }
    fn actual_tcp_force(&self) -> [f64; 6] {
        [0.0; 6]
    }
    fn input_packages(&self) -> u64 {
        0
    }
    fn set_watchdog(&mut self, _: tendril_urscript::RtdeWatchdog) {}
    fn message(&mut self, _: &str) {}
}

/// Program text made of URScript's own pieces, so that the parser gets past the first token.
fn urscript_text() -> impl Strategy<Value = String> {
    let piece = prop_oneof![
        Just("def "),
        Just("thread "),
        Just("end\n"),
        Just("if "),
        Just("elif "),
        Just("else"),
        Just("while "),
        Just("return "),
        Just("global "),
        Just("run "),
        Just("kill "),
        Just("join "),
        Just("x"),
        Just("f"),
        Just("p["),
        Just("["),
        Just("]"),
        Just("("),
        Just(")"),
        Just(":"),
        Just(","),
        Just("="),
        Just("=="),
        Just("+"),
        Just("-"),
        Just("*"),
        Just("/"),
        Just("%"),
        Just(" and "),
        Just(" not "),
        Just("1"),
        Just("0.5"),
        Just("\"s\""),
        Just("True"),
        Just("\n"),
        Just("sync()"),
        Just("movej("),
        Just("servoj("),
        Just("speedj("),
        Just("stopj(1)"),
        Just("sleep(0.01)"),
        Just("textmsg("),
        Just("# c\n"),
        Just("1e308"),
    ];
    prop::collection::vec(piece, 0..60).prop_map(|v| format!("def prog():\n{}\nend\n", v.concat()))
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn urscript_never_panics_on_arbitrary_text(text in ".{0,300}") {
        let _ = tendril_urscript::Interpreter::new(&text, [0.0; 6]);
    }

    #[test]
    fn urscript_programs_of_its_own_pieces_parse_or_fail_and_run_without_panicking(text in urscript_text()) {
        if let Ok(mut p) = tendril_urscript::Interpreter::new(&text, [0.0; 6]) {
            for k in 0..20 {
                let _ = p.step(k as f64 * 0.002, &mut NullController);
            }
        }
    }
}
