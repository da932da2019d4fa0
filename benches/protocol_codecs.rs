//! Cost of the protocol codecs per control tick (500 Hz budget: 2 ms, goal p99 < 1 ms for the
//! whole real path): the RTDE 58-field data package both ways, a Dynamixel sync write + sync read
//! of the two motors through the virtual bus, and a HYPERION peak frame both ways.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use tendril_codec::Decoded;
use tendril_dynamixel::{BROADCAST_ID, Instruction, InstructionPacket, StreamDecoder, VirtualBus};
use tendril_hyperion::{PeakFrame, Response, decode_stream_frame};
use tendril_rtde::{ClientPacket, ClientSession, RobotOutputs, ServerConfig, ServerSession, SharedInputs, fields};

fn rtde_tick(c: &mut Criterion) {
    let mut shared = SharedInputs::new();
    let mut server = ServerSession::new(1, ServerConfig::default());
    let mut client = ClientSession::new();
    let names: Vec<&str> = fields::FIXED_OUTPUTS.iter().map(|(n, _)| *n).take(58).collect();
    let mut wire = Vec::new();
    for p in [client.request_protocol_version(), client.setup_outputs(500.0, &names).unwrap(), client.start()] {
        wire.extend_from_slice(&p.encode().unwrap());
    }
    let mut replies = server.feed(&mut wire, &mut shared).unwrap();
    client.feed(&mut replies).unwrap();
    let outputs = RobotOutputs::default();
    let mut t = 0.0;
    c.bench_function("rtde: 58-field output package, server encode + client decode", |b| {
        b.iter(|| {
            t += 0.002;
            let mut bytes = Vec::new();
            for p in server.poll_outputs(t, black_box(&outputs), &shared) {
                bytes.extend_from_slice(&p.encode().unwrap());
            }
            black_box(client.feed(&mut bytes).unwrap())
        })
    });
    let input = ClientPacket::Data { recipe_id: 9, data: vec![0; 12] };
    c.bench_function("rtde: client packet encode + frame", |b| {
        b.iter(|| black_box(ClientPacket::decode(&black_box(&input).encode().unwrap())))
    });
}

fn dynamixel_tick(c: &mut Criterion) {
    let mut bus = VirtualBus::with_ids(&[1, 2]).unwrap();
    let mut decoder = StreamDecoder::new();
    let write = InstructionPacket {
        id: BROADCAST_ID,
        instruction: Instruction::SyncWrite {
            address: 116,
            length: 4,
            entries: vec![(1, 150u32.to_le_bytes().to_vec()), (2, 170u32.to_le_bytes().to_vec())],
        },
    };
    let read = InstructionPacket {
        id: BROADCAST_ID,
        instruction: Instruction::SyncRead { address: 126, length: 10, ids: vec![1, 2] },
    };
    c.bench_function("dynamixel: sync write + sync read of 2 motors (encode, device, decode)", |b| {
        b.iter(|| {
            let mut bytes = write.encode().unwrap();
            bytes.extend_from_slice(&read.encode().unwrap());
            let replies = bus.respond_to_bytes(&mut decoder, &bytes);
            let mut client = StreamDecoder::new();
            client.push(&replies);
            let mut n = 0;
            while let Some(Ok(_)) = client.next_packet() {
                n += 1;
            }
            black_box(n)
        })
    });
}

fn hyperion_tick(c: &mut Criterion) {
    let frame = PeakFrame { channels: vec![vec![1540.1, 1550.2], vec![], vec![], vec![]], ..PeakFrame::default() };
    c.bench_function("hyperion: 4-channel peak frame, encode + stream decode", |b| {
        b.iter(|| {
            let bytes = Response::ok("", black_box(&frame).encode().unwrap()).encode().unwrap();
            match decode_stream_frame(&bytes) {
                Decoded::Frame { packet, .. } => black_box(packet),
                _ => unreachable!("a frame we just encoded decodes"),
            }
        })
    });
}

criterion_group!(benches, rtde_tick, dynamixel_tick, hyperion_tick);
criterion_main!(benches);
