//! A sans-IO virtual Dynamixel bus: MX-106 control tables that answer instruction packets with
//! the status packets real devices would send.
//!
//! Replies follow Protocol 2.0: no status to a broadcast instruction except Ping (every device)
//! and Sync/Bulk Read (the listed devices, in listed order); Status Return Level 0 answers only
//! Ping, 1 also Read, 2 everything. The physics (how Present Position follows Goal Position) is
//! not here: the twin writes Present values through [`VirtualBus::table_mut`].

use std::collections::BTreeMap;

use super::control_table::{Access, ControlTable, FIELDS, RAM_START, addr};
use super::instruction::{ALERT_BIT, Instruction, InstructionPacket, StatusErrorCode, StatusPacket, code};
use super::packet::{BROADCAST_ID, RawPacket, STATUS_INSTRUCTION};
use super::{DxlError, StreamDecoder};

/// Highest ID a device may take (253..=255 are reserved or broadcast).
pub const MAX_DEVICE_ID: u8 = 252;

/// From this Firmware Version on, an MX(2.0) ignores a Factory Reset 0xFF sent to the broadcast
/// ID (e-manual, Protocol 2.0 "Factory Reset").
pub const FACTORY_RESET_BROADCAST_GUARD_FIRMWARE: u8 = 42;

#[derive(Debug, Clone)]
struct Device {
    table: ControlTable,
    registered: Option<(u16, Vec<u8>)>,
}

/// Devices sharing one bus, keyed by ID.
#[derive(Debug, Clone, Default)]
pub struct VirtualBus {
    devices: BTreeMap<u8, Device>,
}

/// How much a reply needs from Status Return Level.
#[derive(Clone, Copy)]
enum ReplyClass {
    Ping,
    Read,
    Other,
}

impl VirtualBus {
    /// An empty bus.
    pub fn new() -> Self {
        Self::default()
    }

    /// A bus with factory-default MX-106s at `ids`.
    pub fn with_ids(ids: &[u8]) -> Result<Self, DxlError> {
        let mut bus = Self::new();
        for &id in ids {
            bus.add(ControlTable::with_id(id))?;
        }
        Ok(bus)
    }

    /// Adds a device; its ID is the table's (address 7).
    pub fn add(&mut self, table: ControlTable) -> Result<(), DxlError> {
        let id = table.id();
        if id > MAX_DEVICE_ID || self.devices.contains_key(&id) {
            return Err(DxlError::BadDeviceId(id));
        }
        self.devices.insert(id, Device { table, registered: None });
        Ok(())
    }

    /// IDs on the bus, ascending.
    pub fn ids(&self) -> Vec<u8> {
        self.devices.keys().copied().collect()
    }

    /// The control table of device `id`.
    pub fn table(&self, id: u8) -> Option<&ControlTable> {
        self.devices.get(&id).map(|d| &d.table)
    }

    /// The control table of device `id`, to update Present values from the simulation.
    pub fn table_mut(&mut self, id: u8) -> Option<&mut ControlTable> {
        self.devices.get_mut(&id).map(|d| &mut d.table)
    }

    /// Feeds received bytes through `decoder` and returns the wire bytes of every reply.
    /// Bytes that are no packet are dropped; an instruction packet with a wrong CRC gets the CRC
    /// error status (0x03) from the device it names ([`VirtualBus::crc_error`]).
    pub fn respond_to_bytes(&mut self, decoder: &mut StreamDecoder, bytes: &[u8]) -> Vec<u8> {
        decoder.push(bytes);
        let mut out = Vec::new();
        while let Some(item) = decoder.next_packet() {
            let replies = match item {
                Ok(raw) => self.handle(&raw),
                Err(DxlError::BadCrc { id, instruction, .. }) => self.crc_error(id, instruction),
                Err(_) => Vec::new(),
            };
            for status in replies {
                // A status packet is at most a few hundred bytes here; encoding cannot fail.
                if let Ok(bytes) = status.encode() {
                    out.extend_from_slice(&bytes);
                }
            }
        }
        out
    }

    /// The reply to an instruction packet whose CRC does not match: status error 0x03 (CRC
    /// Error) from device `id`, subject to its Status Return Level as the instruction would be;
    /// nothing for a broadcast, an absent ID or a (corrupt) status packet.
    pub fn crc_error(&self, id: u8, instruction: u8) -> Vec<StatusPacket> {
        if instruction == STATUS_INSTRUCTION || id == BROADCAST_ID {
            return Vec::new();
        }
        let class = match instruction {
            code::PING => ReplyClass::Ping,
            code::READ => ReplyClass::Read,
            _ => ReplyClass::Other,
        };
        self.reply(id, class, Err(StatusErrorCode::Crc))
    }

    /// The status packets the devices send in answer to `raw`, in bus order.
    pub fn handle(&mut self, raw: &RawPacket) -> Vec<StatusPacket> {
        if raw.instruction == STATUS_INSTRUCTION {
            return Vec::new(); // another device's reply on the shared line
        }
        let broadcast = raw.id == BROADCAST_ID;
        if !broadcast && !self.devices.contains_key(&raw.id) {
            return Vec::new();
        }
        let packet = match InstructionPacket::from_raw(raw) {
            Ok(p) => p,
            Err(error) => {
                let code = match error {
                    DxlError::UnknownInstruction(_) => StatusErrorCode::Instruction,
                    _ => StatusErrorCode::DataLength,
                };
                return if broadcast { Vec::new() } else { self.reply(raw.id, ReplyClass::Other, Err(code)) };
            }
        };
        let id = packet.id;
        match packet.instruction {
            Instruction::Ping => {
                let ids = if broadcast { self.ids() } else { vec![id] };
                ids.into_iter().flat_map(|id| self.reply(id, ReplyClass::Ping, Ok(self.ping_data(id)))).collect()
            }
            Instruction::Read { address, length } if !broadcast => {
                let result = self.read(id, address, length);
                self.reply(id, ReplyClass::Read, result)
            }
            Instruction::Write { address, data } => self.for_targets(id, |bus, id| bus.write(id, address, &data)),
            Instruction::RegWrite { address, data } => {
                self.for_targets(id, |bus, id| bus.reg_write(id, address, data.clone()))
            }
            Instruction::Action => self.for_targets(id, Self::action),
            Instruction::Reboot => self.for_targets(id, |bus, id| bus.reset(id, ResetKind::Reboot)),
            Instruction::FactoryReset { mode } => self.for_targets(id, |bus, id| {
                // e-manual, Protocol 2.0 "Factory Reset": with the broadcast ID and option 0xFF
                // (reset all) the instruction is not activated on MX(2.0) firmware 42 and later.
                if broadcast && mode == 0xFF && bus.firmware(id) >= FACTORY_RESET_BROADCAST_GUARD_FIRMWARE {
                    return Ok(Vec::new());
                }
                bus.reset(id, ResetKind::Factory(mode))
            }),
            Instruction::Clear { params } => self.for_targets(id, |bus, id| bus.clear(id, &params)),
            Instruction::SyncRead { address, length, ids } if broadcast => ids
                .into_iter()
                .filter(|id| self.devices.contains_key(id))
                .flat_map(|id| {
                    let result = self.read(id, address, length);
                    self.reply(id, ReplyClass::Read, result)
                })
                .collect(),
            Instruction::BulkRead { entries } if broadcast => entries
                .into_iter()
                .filter(|e| self.devices.contains_key(&e.id))
                .flat_map(|e| {
                    let result = self.read(e.id, e.address, e.length);
                    self.reply(e.id, ReplyClass::Read, result)
                })
                .collect(),
            Instruction::SyncWrite { address, entries, .. } if broadcast => {
                for (id, data) in entries {
                    if self.devices.contains_key(&id) {
                        let _ = self.write(id, address, &data); // no status: errors are silent
                    }
                }
                Vec::new()
            }
            Instruction::BulkWrite { entries } if broadcast => {
                for e in entries {
                    if self.devices.contains_key(&e.id) {
                        let _ = self.write(e.id, e.address, &e.data);
                    }
                }
                Vec::new()
            }
            // Read to the broadcast ID has no defined reply; Sync/Bulk to a single ID is invalid.
            Instruction::Read { .. } => Vec::new(),
            Instruction::SyncRead { .. }
            | Instruction::BulkRead { .. }
            | Instruction::SyncWrite { .. }
            | Instruction::BulkWrite { .. } => self.reply(id, ReplyClass::Other, Err(StatusErrorCode::Instruction)),
        }
    }

    /// Runs `op` on the addressed device (reply) or on every device (broadcast: no reply).
    fn for_targets<F>(&mut self, id: u8, mut op: F) -> Vec<StatusPacket>
    where
        F: FnMut(&mut Self, u8) -> Result<Vec<u8>, StatusErrorCode>,
    {
        if id == BROADCAST_ID {
            for id in self.ids() {
                let _ = op(self, id);
            }
            return Vec::new();
        }
        // The reply goes out under the ID the device had when it received the instruction.
        let status_return_level = self.devices.get(&id).map(|d| d.table.status_return_level());
        let result = op(self, id);
        let mut replies = self.reply(id, ReplyClass::Other, result.clone());
        if replies.is_empty() && status_return_level >= Some(2) {
            // The device changed its own ID (write to address 7): it still answers under the old one.
            replies.push(status_for(id, 0, result));
        }
        replies
    }

    fn reply(&self, id: u8, class: ReplyClass, result: Result<Vec<u8>, StatusErrorCode>) -> Vec<StatusPacket> {
        let Some(device) = self.devices.get(&id) else { return Vec::new() };
        let level = device.table.status_return_level();
        let allowed = match class {
            ReplyClass::Ping => true,
            ReplyClass::Read => level >= 1,
            ReplyClass::Other => level >= 2,
        };
        if !allowed {
            return Vec::new();
        }
        let alert = if device.table.read(addr::HARDWARE_ERROR_STATUS, 1).map(|b| b[0]).unwrap_or(0) != 0 {
            ALERT_BIT
        } else {
            0
        };
        vec![status_for(id, alert, result)]
    }

    /// Firmware Version of device `id` (0 when absent).
    fn firmware(&self, id: u8) -> u8 {
        self.devices.get(&id).and_then(|d| d.table.read(addr::FIRMWARE_VERSION, 1).ok()).map_or(0, |b| b[0])
    }

    fn ping_data(&self, id: u8) -> Vec<u8> {
        let table = &self.devices[&id].table;
        let mut data = table.u16_at(addr::MODEL_NUMBER).to_le_bytes().to_vec();
        data.push(table.read(addr::FIRMWARE_VERSION, 1).map(|b| b[0]).unwrap_or(0));
        data
    }

    fn read(&self, id: u8, address: u16, length: u16) -> Result<Vec<u8>, StatusErrorCode> {
        let table = &self.devices.get(&id).ok_or(StatusErrorCode::ResultFail)?.table;
        table.read(address, length).map(<[u8]>::to_vec).map_err(|_| StatusErrorCode::Access)
    }

    fn write(&mut self, id: u8, address: u16, data: &[u8]) -> Result<Vec<u8>, StatusErrorCode> {
        let new_id = id_written(address, data);
        if let Some(new_id) = new_id {
            if new_id > MAX_DEVICE_ID {
                return Err(StatusErrorCode::DataRange);
            }
            if new_id != id && self.devices.contains_key(&new_id) {
                return Err(StatusErrorCode::ResultFail); // would collide with another device on this bus
            }
        }
        let device = self.devices.get_mut(&id).ok_or(StatusErrorCode::ResultFail)?;
        device.table.write(address, data).map_err(|e| status_code(&e))?;
        if let Some(new_id) = new_id.filter(|&n| n != id) {
            let device = self.devices.remove(&id).ok_or(StatusErrorCode::ResultFail)?;
            self.devices.insert(new_id, device);
        }
        Ok(Vec::new())
    }

    fn reg_write(&mut self, id: u8, address: u16, data: Vec<u8>) -> Result<Vec<u8>, StatusErrorCode> {
        let device = self.devices.get_mut(&id).ok_or(StatusErrorCode::ResultFail)?;
        // Validate now (on a copy) so the error comes with this instruction, as on the device.
        device.table.clone().write(address, &data).map_err(|e| status_code(&e))?;
        device.registered = Some((address, data));
        device.table.put(addr::REGISTERED_INSTRUCTION, &[1]);
        Ok(Vec::new())
    }

    fn action(&mut self, id: u8) -> Result<Vec<u8>, StatusErrorCode> {
        let device = self.devices.get_mut(&id).ok_or(StatusErrorCode::ResultFail)?;
        let (address, data) = device.registered.take().ok_or(StatusErrorCode::Instruction)?;
        device.table.put(addr::REGISTERED_INSTRUCTION, &[0]);
        self.write(id, address, &data)
    }

    fn reset(&mut self, id: u8, kind: ResetKind) -> Result<Vec<u8>, StatusErrorCode> {
        let device = self.devices.get_mut(&id).ok_or(StatusErrorCode::ResultFail)?;
        let old = device.table.clone();
        let fresh = ControlTable::with_id(id);
        match kind {
            ResetKind::Reboot => {
                // RAM settings return to defaults; EEPROM and the Present (read-only) values stay.
                for field in FIELDS.iter().filter(|f| f.address >= RAM_START && f.access == Access::ReadWrite) {
                    if let Ok(bytes) = fresh.read(field.address, field.size) {
                        device.table.put(field.address, bytes);
                    }
                }
            }
            ResetKind::Factory(mode) => {
                let keep_baud = match mode {
                    0xFF => false,
                    0x02 => true,
                    0x01 => false,
                    _ => return Err(StatusErrorCode::DataRange),
                };
                let mut table = if mode == 0xFF { ControlTable::with_id(1) } else { fresh };
                if keep_baud {
                    table.put(addr::BAUD_RATE, old.read(addr::BAUD_RATE, 1).unwrap_or(&[1]));
                }
                // Present values are measurements, not settings.
                table.put(addr::PRESENT_POSITION, old.read(addr::PRESENT_POSITION, 4).unwrap_or(&[0; 4]));
                let new_id = table.id();
                if new_id != id && self.devices.contains_key(&new_id) {
                    return Err(StatusErrorCode::ResultFail);
                }
                let mut device = self.devices.remove(&id).ok_or(StatusErrorCode::ResultFail)?;
                device.table = table;
                self.devices.insert(new_id, device);
                return Ok(Vec::new());
            }
        }
        device.registered = None;
        Ok(Vec::new())
    }

    fn clear(&mut self, id: u8, params: &[u8]) -> Result<Vec<u8>, StatusErrorCode> {
        // 0x01 'D' 'X' 'L' 0x22: reset the multi-turn count (only with torque off).
        if params != [0x01, 0x44, 0x58, 0x4C, 0x22] {
            return Err(StatusErrorCode::DataRange);
        }
        let device = self.devices.get_mut(&id).ok_or(StatusErrorCode::ResultFail)?;
        if device.table.torque_enabled() {
            return Err(StatusErrorCode::Access);
        }
        let position = device.table.present_position().rem_euclid(4096);
        device.table.set_present_position(position);
        Ok(Vec::new())
    }
}

#[derive(Clone, Copy)]
enum ResetKind {
    Reboot,
    Factory(u8),
}

/// The new ID if this write covers address 7.
fn id_written(address: u16, data: &[u8]) -> Option<u8> {
    let offset = usize::from(addr::ID.checked_sub(address)?);
    data.get(offset).copied()
}

/// The status error a device answers a failed control-table access with.
fn status_code(error: &DxlError) -> StatusErrorCode {
    match error {
        DxlError::DataLength { .. } => StatusErrorCode::DataLength,
        DxlError::OutOfRange { .. } => StatusErrorCode::DataRange,
        _ => StatusErrorCode::Access,
    }
}

fn status_for(id: u8, alert: u8, result: Result<Vec<u8>, StatusErrorCode>) -> StatusPacket {
    match result {
        Ok(params) => StatusPacket { id, error: alert, params },
        Err(code) => StatusPacket { id, error: alert | code as u8, params: Vec::new() },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::BulkReadEntry;

    fn raw(id: u8, instruction: Instruction) -> RawPacket {
        InstructionPacket { id, instruction }.to_raw()
    }

    #[test]
    fn ping_returns_model_321_and_broadcast_ping_every_device() {
        let mut bus = VirtualBus::with_ids(&[1, 2]).unwrap();
        let replies = bus.handle(&raw(1, Instruction::Ping));
        assert_eq!(replies.len(), 1);
        assert_eq!(u16::from_le_bytes([replies[0].params[0], replies[0].params[1]]), 321);
        let ids: Vec<u8> = bus.handle(&raw(BROADCAST_ID, Instruction::Ping)).iter().map(|s| s.id).collect();
        assert_eq!(ids, vec![1, 2]);
        assert!(bus.handle(&raw(3, Instruction::Ping)).is_empty());
    }

    #[test]
    fn read_present_position_gives_the_manual_status_bytes() {
        let mut bus = VirtualBus::with_ids(&[1]).unwrap();
        bus.table_mut(1).unwrap().set_present_position(166);
        let request = [0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x07, 0x00, 0x02, 0x84, 0x00, 0x04, 0x00, 0x1D, 0x15];
        let reply = bus.respond_to_bytes(&mut StreamDecoder::new(), &request);
        assert_eq!(
            reply,
            vec![0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x08, 0x00, 0x55, 0x00, 0xA6, 0x00, 0x00, 0x00, 0x8C, 0xC0]
        );
    }

    #[test]
    fn sync_write_sets_goal_positions_without_reply() {
        let mut bus = VirtualBus::with_ids(&[1, 2]).unwrap();
        let request = [
            0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x11, 0x00, 0x83, 0x74, 0x00, 0x04, 0x00, 0x01, 0x96, 0x00, 0x00, 0x00, 0x02,
            0xAA, 0x00, 0x00, 0x00, 0x82, 0x87,
        ];
        assert!(bus.respond_to_bytes(&mut StreamDecoder::new(), &request).is_empty());
        assert_eq!(bus.table(1).unwrap().goal_position(), 150);
        assert_eq!(bus.table(2).unwrap().goal_position(), 170);
    }

    #[test]
    fn sync_read_answers_in_listed_order_and_skips_absent_ids() {
        let mut bus = VirtualBus::with_ids(&[1, 2]).unwrap();
        bus.table_mut(1).unwrap().set_present_position(10);
        bus.table_mut(2).unwrap().set_present_position(-20);
        let replies = bus.handle(&raw(
            BROADCAST_ID,
            Instruction::SyncRead { address: addr::PRESENT_POSITION, length: 4, ids: vec![2, 9, 1] },
        ));
        let got: Vec<(u8, i32)> =
            replies.iter().map(|s| (s.id, i32::from_le_bytes(s.params.clone().try_into().unwrap()))).collect();
        assert_eq!(got, vec![(2, -20), (1, 10)]);
        let bulk = bus.handle(&raw(
            BROADCAST_ID,
            Instruction::BulkRead { entries: vec![BulkReadEntry { id: 1, address: addr::OPERATING_MODE, length: 1 }] },
        ));
        assert_eq!(bulk[0].params, vec![3]);
    }

    #[test]
    fn errors_come_back_as_status_error_codes() {
        let mut bus = VirtualBus::with_ids(&[1]).unwrap();
        let read_past_end = bus.handle(&raw(1, Instruction::Read { address: 146, length: 4 }));
        assert_eq!(read_past_end[0].error_code(), Some(StatusErrorCode::Access as u8));
        let write_ro = bus.handle(&raw(1, Instruction::Write { address: addr::PRESENT_POSITION, data: vec![0; 4] }));
        assert_eq!(write_ro[0].error_code(), Some(StatusErrorCode::Access as u8));
        let unknown = bus.handle(&RawPacket { id: 1, instruction: 0x42, body: vec![] });
        assert_eq!(unknown[0].error_code(), Some(StatusErrorCode::Instruction as u8));
        let short = bus.handle(&RawPacket { id: 1, instruction: 0x02, body: vec![0x84] });
        assert_eq!(short[0].error_code(), Some(StatusErrorCode::DataLength as u8));
        let action = bus.handle(&raw(1, Instruction::Action));
        assert_eq!(action[0].error_code(), Some(StatusErrorCode::Instruction as u8));
        // Broadcast instructions never get a status, even failing ones.
        assert!(bus.handle(&RawPacket { id: BROADCAST_ID, instruction: 0x42, body: vec![] }).is_empty());
    }

    #[test]
    fn reg_write_waits_for_action_and_reboot_turns_torque_off() {
        let mut bus = VirtualBus::with_ids(&[1]).unwrap();
        bus.handle(&raw(
            1,
            Instruction::RegWrite { address: addr::GOAL_POSITION, data: 1000i32.to_le_bytes().to_vec() },
        ));
        assert_eq!(bus.table(1).unwrap().goal_position(), 2048);
        assert!(bus.handle(&raw(BROADCAST_ID, Instruction::Action)).is_empty());
        assert_eq!(bus.table(1).unwrap().goal_position(), 1000);
        bus.handle(&raw(1, Instruction::Write { address: addr::TORQUE_ENABLE, data: vec![1] }));
        assert!(bus.table(1).unwrap().torque_enabled());
        let reply = bus.handle(&raw(1, Instruction::Reboot));
        assert_eq!(reply[0].error, 0);
        assert!(!bus.table(1).unwrap().torque_enabled());
    }

    #[test]
    fn status_return_level_zero_answers_only_ping() {
        let mut bus = VirtualBus::with_ids(&[1]).unwrap();
        bus.handle(&raw(1, Instruction::Write { address: addr::STATUS_RETURN_LEVEL, data: vec![0] }));
        assert!(bus.handle(&raw(1, Instruction::Read { address: 0, length: 2 })).is_empty());
        assert_eq!(bus.handle(&raw(1, Instruction::Ping)).len(), 1);
    }

    #[test]
    fn writing_the_id_moves_the_device() {
        let mut bus = VirtualBus::with_ids(&[1, 2]).unwrap();
        let reply = bus.handle(&raw(1, Instruction::Write { address: addr::ID, data: vec![5] }));
        assert_eq!((reply[0].id, reply[0].error), (1, 0));
        assert_eq!(bus.ids(), vec![2, 5]);
        let clash = bus.handle(&raw(5, Instruction::Write { address: addr::ID, data: vec![2] }));
        assert_eq!(clash[0].error_code(), Some(StatusErrorCode::ResultFail as u8));
    }

    /// Wire bytes of the status of ID 1 with error number `error` and no data, as the e-manual
    /// frames it (CRC computed independently of this crate).
    fn error_status(error: u8) -> Vec<u8> {
        let crc = match error {
            0x03 => [0xAB, 0x0C],
            0x04 => [0xBA, 0x8C],
            0x05 => [0xBF, 0x0C],
            0x07 => [0xB0, 0x8C],
            _ => panic!("no CRC for error {error}"),
        };
        vec![0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x04, 0x00, 0x55, error, crc[0], crc[1]]
    }

    fn send(bus: &mut VirtualBus, packet: InstructionPacket) -> Vec<u8> {
        bus.respond_to_bytes(&mut StreamDecoder::new(), &packet.encode().unwrap())
    }

    #[test]
    fn a_wrong_crc_gets_the_crc_error_status() {
        let mut bus = VirtualBus::with_ids(&[1]).unwrap();
        // The manual's Write of 512 to Goal Position, its CRC corrupted.
        let mut request =
            vec![0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x09, 0x00, 0x03, 0x74, 0x00, 0x00, 0x02, 0x00, 0x00, 0xCA, 0x89];
        let n = request.len();
        request[n - 1] ^= 0xFF;
        let mut decoder = StreamDecoder::new();
        assert_eq!(bus.respond_to_bytes(&mut decoder, &request), error_status(0x03));
        assert_eq!(bus.table(1).unwrap().goal_position(), 2048, "a corrupt write changes nothing");
        // The stream resynchronises: the next good packet gets its normal reply.
        request[n - 1] ^= 0xFF;
        let ok = bus.respond_to_bytes(&mut decoder, &request);
        assert_eq!(ok, vec![0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x04, 0x00, 0x55, 0x00, 0xA1, 0x0C]);
        assert_eq!(bus.table(1).unwrap().goal_position(), 512);
        // No reply for another ID, the broadcast ID, or a corrupt status packet.
        for (id, instruction) in [(7, 0x03), (BROADCAST_ID, 0x03), (1, 0x55)] {
            assert!(bus.crc_error(id, instruction).is_empty(), "id {id} instruction {instruction:#x}");
        }
    }

    #[test]
    fn a_two_byte_write_to_goal_position_is_a_data_length_error() {
        let mut bus = VirtualBus::with_ids(&[1]).unwrap();
        // The e-manual's own example of error 0x05: 2 bytes to the 4-byte Goal Position.
        let request = [0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x07, 0x00, 0x03, 0x74, 0x00, 0x00, 0x02, 0x42, 0x4D];
        assert_eq!(bus.respond_to_bytes(&mut StreamDecoder::new(), &request), error_status(0x05));
        assert_eq!(bus.table(1).unwrap().goal_position(), 2048);
        // Starting inside a field is the same error; a write spanning whole fields is fine.
        let tail = send(
            &mut bus,
            InstructionPacket { id: 1, instruction: Instruction::Write { address: 118, data: vec![0, 0] } },
        );
        assert_eq!(tail, error_status(0x05));
        let mut both = 100i32.to_le_bytes().to_vec();
        both.extend_from_slice(&50i32.to_le_bytes());
        let whole = send(
            &mut bus,
            InstructionPacket {
                id: 1,
                instruction: Instruction::Write { address: addr::PROFILE_ACCELERATION, data: both },
            },
        );
        assert_eq!(whole[8], 0x00);
        assert_eq!(bus.table(1).unwrap().u32_at(addr::PROFILE_VELOCITY), 50);
    }

    #[test]
    fn read_only_undefined_and_locked_addresses_are_access_errors() {
        let mut bus = VirtualBus::with_ids(&[1]).unwrap();
        let write =
            |address, data: Vec<u8>| InstructionPacket { id: 1, instruction: Instruction::Write { address, data } };
        assert_eq!(send(&mut bus, write(addr::PRESENT_POSITION, vec![0; 4])), error_status(0x07), "read-only");
        assert_eq!(send(&mut bus, write(14, vec![0])), error_status(0x07), "undefined (a gap)");
        assert_eq!(send(&mut bus, write(200, vec![0])), error_status(0x07), "beyond the table");
        let read = InstructionPacket { id: 1, instruction: Instruction::Read { address: 146, length: 2 } };
        assert_eq!(send(&mut bus, read), error_status(0x07), "a read past the table");
        send(&mut bus, write(addr::TORQUE_ENABLE, vec![1]));
        assert_eq!(send(&mut bus, write(addr::OPERATING_MODE, vec![4])), error_status(0x07), "EEPROM, torque on");
    }

    #[test]
    fn values_outside_their_range_are_data_range_errors() {
        let mut bus = VirtualBus::with_ids(&[1]).unwrap();
        let write =
            |address, data: Vec<u8>| InstructionPacket { id: 1, instruction: Instruction::Write { address, data } };
        let goal = |ticks: i32| write(addr::GOAL_POSITION, ticks.to_le_bytes().to_vec());
        // Position mode (the default): Goal Position within Min/Max Position Limit (0..4095).
        assert_eq!(send(&mut bus, goal(5000)), error_status(0x04));
        assert_eq!(send(&mut bus, goal(-1)), error_status(0x04));
        assert_eq!(bus.table(1).unwrap().goal_position(), 2048);
        assert_eq!(send(&mut bus, goal(4095))[8], 0);
        send(&mut bus, write(addr::MAX_POSITION_LIMIT, 3000u32.to_le_bytes().to_vec()));
        assert_eq!(send(&mut bus, goal(3500)), error_status(0x04), "the limit moved");
        // No Operating Mode 9; extended position mode takes ±256 turns.
        assert_eq!(send(&mut bus, write(addr::OPERATING_MODE, vec![9])), error_status(0x04));
        assert_eq!(bus.table(1).unwrap().operating_mode(), 3);
        assert_eq!(send(&mut bus, write(addr::OPERATING_MODE, vec![4]))[8], 0);
        assert_eq!(send(&mut bus, goal(5000))[8], 0);
        assert_eq!(send(&mut bus, goal(1_048_576)), error_status(0x04));
        // Goal Velocity within ±Velocity Limit (360 by default), Velocity Limit within 0..1023.
        let velocity = |v: i32| write(addr::GOAL_VELOCITY, v.to_le_bytes().to_vec());
        assert_eq!(send(&mut bus, velocity(-361)), error_status(0x04));
        assert_eq!(send(&mut bus, velocity(-360))[8], 0);
        assert_eq!(send(&mut bus, write(addr::VELOCITY_LIMIT, 1024u32.to_le_bytes().to_vec())), error_status(0x04));
        assert_eq!(send(&mut bus, write(addr::STATUS_RETURN_LEVEL, vec![3])), error_status(0x04));
    }

    #[test]
    fn velocity_limit_defaults_to_the_manuals_360() {
        let bus = VirtualBus::with_ids(&[1]).unwrap();
        assert_eq!(bus.table(1).unwrap().u32_at(addr::VELOCITY_LIMIT), 360);
    }

    #[test]
    fn broadcast_factory_reset_all_is_not_activated_from_firmware_42() {
        let mut bus = VirtualBus::with_ids(&[3]).unwrap();
        let limit = |bus: &VirtualBus, id| bus.table(id).unwrap().u32_at(addr::VELOCITY_LIMIT);
        bus.handle(&raw(3, Instruction::Write { address: addr::VELOCITY_LIMIT, data: 100u32.to_le_bytes().to_vec() }));
        assert_eq!(bus.table(3).unwrap().read(addr::FIRMWARE_VERSION, 1).unwrap(), [45]);
        assert!(bus.handle(&raw(BROADCAST_ID, Instruction::FactoryReset { mode: 0xFF })).is_empty());
        assert_eq!((bus.ids(), limit(&bus, 3)), (vec![3], 100), "firmware 45 ignores it");
        // Other options do reset over the broadcast ID; 0x02 keeps the ID.
        bus.handle(&raw(BROADCAST_ID, Instruction::FactoryReset { mode: 0x02 }));
        assert_eq!((bus.ids(), limit(&bus, 3)), (vec![3], 360));
        // Addressed to the device, 0xFF resets everything, the ID to 1 included.
        bus.handle(&raw(3, Instruction::Write { address: addr::VELOCITY_LIMIT, data: 100u32.to_le_bytes().to_vec() }));
        let reply = bus.handle(&raw(3, Instruction::FactoryReset { mode: 0xFF }));
        assert_eq!((reply[0].id, reply[0].error), (3, 0));
        assert_eq!((bus.ids(), limit(&bus, 1)), (vec![1], 360));
        // Firmware before 42 (no longer shipped) still resets over the broadcast ID.
        bus.table_mut(1).unwrap().put(addr::FIRMWARE_VERSION, &[41]);
        bus.handle(&raw(1, Instruction::Write { address: addr::ID, data: vec![3] }));
        bus.handle(&raw(BROADCAST_ID, Instruction::FactoryReset { mode: 0xFF }));
        assert_eq!(bus.ids(), vec![1]);
    }

    #[test]
    fn sync_read_and_bulk_read_give_the_manuals_status_bytes() {
        let mut bus = VirtualBus::with_ids(&[1, 2]).unwrap();
        bus.table_mut(1).unwrap().set_present_position(166);
        bus.table_mut(2).unwrap().set_present_position(2079);
        let sync_read =
            [0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x09, 0x00, 0x82, 0x84, 0x00, 0x04, 0x00, 0x01, 0x02, 0xCE, 0xFA];
        let mut expected =
            vec![0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x08, 0x00, 0x55, 0x00, 0xA6, 0x00, 0x00, 0x00, 0x8C, 0xC0];
        expected.extend([0xFF, 0xFF, 0xFD, 0x00, 0x02, 0x08, 0x00, 0x55, 0x00, 0x1F, 0x08, 0x00, 0x00, 0xBA, 0xBE]);
        assert_eq!(bus.respond_to_bytes(&mut StreamDecoder::new(), &sync_read), expected);
        bus.table_mut(1).unwrap().put(addr::PRESENT_INPUT_VOLTAGE, &119u16.to_le_bytes());
        bus.table_mut(2).unwrap().set_present_temperature(36);
        let bulk_read = [
            0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x0D, 0x00, 0x92, 0x01, 0x90, 0x00, 0x02, 0x00, 0x02, 0x92, 0x00, 0x01, 0x00,
            0x1A, 0x05,
        ];
        let mut expected = vec![0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x06, 0x00, 0x55, 0x00, 0x77, 0x00, 0xC3, 0x69];
        expected.extend([0xFF, 0xFF, 0xFD, 0x00, 0x02, 0x05, 0x00, 0x55, 0x00, 0x24, 0x8B, 0xA9]);
        assert_eq!(bus.respond_to_bytes(&mut StreamDecoder::new(), &bulk_read), expected);
    }
}
