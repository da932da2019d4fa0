//! Two virtual MX-106 on one bus: ping both, set a goal, read it back:
//! `cargo run -p tendril-dynamixel --example bus`.

use tendril_dynamixel::control_table::addr;
use tendril_dynamixel::{BROADCAST_ID, Instruction, InstructionPacket, StatusPacket, StreamDecoder, VirtualBus};

/// Sends one instruction over the bus and decodes every status packet that comes back.
fn transact(bus: &mut VirtualBus, packet: InstructionPacket) -> Vec<StatusPacket> {
    let wire = packet.encode().unwrap();
    let reply = bus.respond_to_bytes(&mut StreamDecoder::new(), &wire);
    let mut decoder = StreamDecoder::new();
    decoder.push(&reply);
    std::iter::from_fn(|| decoder.next_packet()).map(|raw| StatusPacket::from_raw(&raw.unwrap()).unwrap()).collect()
}

fn main() {
    let mut bus = VirtualBus::with_ids(&[1, 2]).unwrap();
    for status in transact(&mut bus, InstructionPacket { id: BROADCAST_ID, instruction: Instruction::Ping }) {
        println!("ID {} answers: model {}", status.id, u16::from_le_bytes([status.params[0], status.params[1]]));
    }
    let enable = Instruction::Write { address: addr::TORQUE_ENABLE, data: vec![1] };
    transact(&mut bus, InstructionPacket { id: 2, instruction: enable });
    let goal = Instruction::Write { address: addr::GOAL_POSITION, data: 3000i32.to_le_bytes().to_vec() };
    transact(&mut bus, InstructionPacket { id: 2, instruction: goal });
    let read = Instruction::Read { address: addr::GOAL_POSITION, length: 4 };
    let status = &transact(&mut bus, InstructionPacket { id: 2, instruction: read })[0];
    println!("ID 2 goal position: {} ticks", i32::from_le_bytes(status.params[..4].try_into().unwrap()));
}
