//! Typed instruction and status packets on top of [`RawPacket`].

use super::DxlError;
use super::packet::{RawPacket, STATUS_INSTRUCTION};

/// Instruction bytes (ROBOTIS e-manual, Protocol 2.0 "Instruction").
pub mod code {
    /// Ping: is a device there, which model.
    pub const PING: u8 = 0x01;
    /// Read bytes from the control table.
    pub const READ: u8 = 0x02;
    /// Write bytes to the control table.
    pub const WRITE: u8 = 0x03;
    /// Register a write, executed on Action.
    pub const REG_WRITE: u8 = 0x04;
    /// Execute the registered write.
    pub const ACTION: u8 = 0x05;
    /// Reset the control table to factory defaults.
    pub const FACTORY_RESET: u8 = 0x06;
    /// Restart the device.
    pub const REBOOT: u8 = 0x08;
    /// Clear the multi-turn revolution count or errors.
    pub const CLEAR: u8 = 0x10;
    /// Read the same address range from several devices.
    pub const SYNC_READ: u8 = 0x82;
    /// Write the same address range on several devices.
    pub const SYNC_WRITE: u8 = 0x83;
    /// Read different ranges from several devices.
    pub const BULK_READ: u8 = 0x92;
    /// Write different ranges on several devices.
    pub const BULK_WRITE: u8 = 0x93;
}

/// One device's part of a bulk read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BulkReadEntry {
    /// Device ID.
    pub id: u8,
    /// Start address.
    pub address: u16,
    /// Number of bytes.
    pub length: u16,
}

/// One device's part of a bulk write.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BulkWriteEntry {
    /// Device ID.
    pub id: u8,
    /// Start address.
    pub address: u16,
    /// Bytes to write.
    pub data: Vec<u8>,
}

/// An instruction with its parameters decoded.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Instruction {
    /// Ping.
    Ping,
    /// Read `length` bytes from `address`.
    Read {
        /// Start address.
        address: u16,
        /// Number of bytes.
        length: u16,
    },
    /// Write `data` at `address`.
    Write {
        /// Start address.
        address: u16,
        /// Bytes.
        data: Vec<u8>,
    },
    /// Register a write for the next Action.
    RegWrite {
        /// Start address.
        address: u16,
        /// Bytes.
        data: Vec<u8>,
    },
    /// Execute registered writes.
    Action,
    /// Factory reset: 0xFF resets all, 0x01 all but ID, 0x02 all but ID and baud rate.
    FactoryReset {
        /// Which values to keep.
        mode: u8,
    },
    /// Reboot.
    Reboot,
    /// Clear (multi-turn count or errors); parameters kept raw (0x01 'D' 'X' 'L' 0x22 clears the count).
    Clear {
        /// Raw parameters.
        params: Vec<u8>,
    },
    /// Sync read `length` bytes at `address` from each of `ids` (sent to the broadcast ID).
    SyncRead {
        /// Start address.
        address: u16,
        /// Number of bytes per device.
        length: u16,
        /// Devices, in reply order.
        ids: Vec<u8>,
    },
    /// Sync write `length` bytes at `address`: one `(id, data)` per device.
    SyncWrite {
        /// Start address.
        address: u16,
        /// Number of bytes per device.
        length: u16,
        /// Per-device data, each exactly `length` bytes.
        entries: Vec<(u8, Vec<u8>)>,
    },
    /// Bulk read.
    BulkRead {
        /// Per-device ranges, in reply order.
        entries: Vec<BulkReadEntry>,
    },
    /// Bulk write.
    BulkWrite {
        /// Per-device writes.
        entries: Vec<BulkWriteEntry>,
    },
}

impl Instruction {
    /// The instruction byte.
    pub fn code(&self) -> u8 {
        match self {
            Instruction::Ping => code::PING,
            Instruction::Read { .. } => code::READ,
            Instruction::Write { .. } => code::WRITE,
            Instruction::RegWrite { .. } => code::REG_WRITE,
            Instruction::Action => code::ACTION,
            Instruction::FactoryReset { .. } => code::FACTORY_RESET,
            Instruction::Reboot => code::REBOOT,
            Instruction::Clear { .. } => code::CLEAR,
            Instruction::SyncRead { .. } => code::SYNC_READ,
            Instruction::SyncWrite { .. } => code::SYNC_WRITE,
            Instruction::BulkRead { .. } => code::BULK_READ,
            Instruction::BulkWrite { .. } => code::BULK_WRITE,
        }
    }

    /// The parameter bytes (unstuffed).
    pub fn params(&self) -> Vec<u8> {
        let mut p = Vec::new();
        match self {
            Instruction::Ping | Instruction::Action | Instruction::Reboot => {}
            Instruction::Read { address, length } => {
                p.extend_from_slice(&address.to_le_bytes());
                p.extend_from_slice(&length.to_le_bytes());
            }
            Instruction::Write { address, data } | Instruction::RegWrite { address, data } => {
                p.extend_from_slice(&address.to_le_bytes());
                p.extend_from_slice(data);
            }
            Instruction::FactoryReset { mode } => p.push(*mode),
            Instruction::Clear { params } => p.extend_from_slice(params),
            Instruction::SyncRead { address, length, ids } => {
                p.extend_from_slice(&address.to_le_bytes());
                p.extend_from_slice(&length.to_le_bytes());
                p.extend_from_slice(ids);
            }
            Instruction::SyncWrite { address, length, entries } => {
                p.extend_from_slice(&address.to_le_bytes());
                p.extend_from_slice(&length.to_le_bytes());
                for (id, data) in entries {
                    p.push(*id);
                    p.extend_from_slice(data);
                }
            }
            Instruction::BulkRead { entries } => {
                for e in entries {
                    p.push(e.id);
                    p.extend_from_slice(&e.address.to_le_bytes());
                    p.extend_from_slice(&e.length.to_le_bytes());
                }
            }
            Instruction::BulkWrite { entries } => {
                for e in entries {
                    p.push(e.id);
                    p.extend_from_slice(&e.address.to_le_bytes());
                    p.extend_from_slice(&(e.data.len() as u16).to_le_bytes());
                    p.extend_from_slice(&e.data);
                }
            }
        }
        p
    }

    /// Decodes an instruction from its byte and parameters.
    pub fn decode(instruction: u8, params: &[u8]) -> Result<Instruction, DxlError> {
        let bad = || DxlError::BadParameters { instruction, len: params.len() };
        let u16_at = |i: usize| u16::from_le_bytes([params[i], params[i + 1]]);
        Ok(match instruction {
            code::PING if params.is_empty() => Instruction::Ping,
            code::ACTION if params.is_empty() => Instruction::Action,
            code::REBOOT if params.is_empty() => Instruction::Reboot,
            code::READ if params.len() == 4 => Instruction::Read { address: u16_at(0), length: u16_at(2) },
            code::WRITE if params.len() >= 3 => Instruction::Write { address: u16_at(0), data: params[2..].to_vec() },
            code::REG_WRITE if params.len() >= 3 => {
                Instruction::RegWrite { address: u16_at(0), data: params[2..].to_vec() }
            }
            code::FACTORY_RESET if params.len() == 1 => Instruction::FactoryReset { mode: params[0] },
            code::CLEAR => Instruction::Clear { params: params.to_vec() },
            code::SYNC_READ if params.len() >= 5 => {
                Instruction::SyncRead { address: u16_at(0), length: u16_at(2), ids: params[4..].to_vec() }
            }
            code::SYNC_WRITE if params.len() >= 4 => {
                let (address, length) = (u16_at(0), u16_at(2));
                let stride = 1 + usize::from(length);
                let rest = &params[4..];
                if length == 0 || rest.is_empty() || !rest.len().is_multiple_of(stride) {
                    return Err(bad());
                }
                let entries = rest.chunks(stride).map(|c| (c[0], c[1..].to_vec())).collect();
                Instruction::SyncWrite { address, length, entries }
            }
            code::BULK_READ if !params.is_empty() && params.len().is_multiple_of(5) => {
                let entries = params
                    .chunks(5)
                    .map(|c| BulkReadEntry {
                        id: c[0],
                        address: u16::from_le_bytes([c[1], c[2]]),
                        length: u16::from_le_bytes([c[3], c[4]]),
                    })
                    .collect();
                Instruction::BulkRead { entries }
            }
            code::BULK_WRITE if !params.is_empty() => {
                let mut entries = Vec::new();
                let mut rest = params;
                while !rest.is_empty() {
                    if rest.len() < 5 {
                        return Err(bad());
                    }
                    let len = usize::from(u16::from_le_bytes([rest[3], rest[4]]));
                    if len == 0 || rest.len() < 5 + len {
                        return Err(bad());
                    }
                    entries.push(BulkWriteEntry {
                        id: rest[0],
                        address: u16::from_le_bytes([rest[1], rest[2]]),
                        data: rest[5..5 + len].to_vec(),
                    });
                    rest = &rest[5 + len..];
                }
                Instruction::BulkWrite { entries }
            }
            code::PING
            | code::ACTION
            | code::REBOOT
            | code::READ
            | code::WRITE
            | code::REG_WRITE
            | code::FACTORY_RESET
            | code::SYNC_READ
            | code::SYNC_WRITE
            | code::BULK_READ
            | code::BULK_WRITE => return Err(bad()),
            other => return Err(DxlError::UnknownInstruction(other)),
        })
    }
}

/// An instruction addressed to a device (or the broadcast ID).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InstructionPacket {
    /// Target ID, or [`super::BROADCAST_ID`].
    pub id: u8,
    /// What to do.
    pub instruction: Instruction,
}

impl InstructionPacket {
    /// The raw packet (for encoding).
    pub fn to_raw(&self) -> RawPacket {
        RawPacket { id: self.id, instruction: self.instruction.code(), body: self.instruction.params() }
    }

    /// Wire bytes.
    pub fn encode(&self) -> Result<Vec<u8>, DxlError> {
        self.to_raw().encode()
    }

    /// Typed view of a raw packet; a status packet is an error here.
    pub fn from_raw(raw: &RawPacket) -> Result<Self, DxlError> {
        if raw.instruction == STATUS_INSTRUCTION {
            return Err(DxlError::NotAnInstruction);
        }
        Ok(Self { id: raw.id, instruction: Instruction::decode(raw.instruction, &raw.body)? })
    }
}

/// Error numbers of the status error byte (bits 0..6; bit 7 is the hardware alert flag).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum StatusErrorCode {
    /// Failed to process the instruction.
    ResultFail = 0x01,
    /// Undefined instruction, or Action without a registered write.
    Instruction = 0x02,
    /// CRC mismatch.
    Crc = 0x03,
    /// Value out of range.
    DataRange = 0x04,
    /// Data shorter than the field.
    DataLength = 0x05,
    /// Value outside the limits.
    DataLimit = 0x06,
    /// Read-only, write-only or undefined address, or EEPROM written with torque on.
    Access = 0x07,
}

/// Bit 7 of the error byte: the device has a hardware error (see Hardware Error Status).
pub const ALERT_BIT: u8 = 0x80;

/// A status (reply) packet.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StatusPacket {
    /// Replying device.
    pub id: u8,
    /// Error byte: error number in bits 0..6, [`ALERT_BIT`] in bit 7.
    pub error: u8,
    /// Returned data (read values, ping model and firmware).
    pub params: Vec<u8>,
}

impl StatusPacket {
    /// The error number, or `None` when the instruction succeeded.
    pub fn error_code(&self) -> Option<u8> {
        match self.error & !ALERT_BIT {
            0 => None,
            n => Some(n),
        }
    }

    /// Whether the hardware alert bit is set.
    pub fn alert(&self) -> bool {
        self.error & ALERT_BIT != 0
    }

    /// The raw packet (for encoding).
    pub fn to_raw(&self) -> RawPacket {
        let mut body = Vec::with_capacity(1 + self.params.len());
        body.push(self.error);
        body.extend_from_slice(&self.params);
        RawPacket { id: self.id, instruction: STATUS_INSTRUCTION, body }
    }

    /// Wire bytes.
    pub fn encode(&self) -> Result<Vec<u8>, DxlError> {
        self.to_raw().encode()
    }

    /// Typed view of a raw packet; an instruction packet is an error here.
    pub fn from_raw(raw: &RawPacket) -> Result<Self, DxlError> {
        if raw.instruction != STATUS_INSTRUCTION {
            return Err(DxlError::NotAStatus(raw.instruction));
        }
        let (&error, params) = raw.body.split_first().ok_or(DxlError::MissingErrorByte)?;
        Ok(Self { id: raw.id, error, params: params.to_vec() })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tendril_codec::Decoded;

    fn decode_instruction(bytes: &[u8]) -> InstructionPacket {
        match RawPacket::decode(bytes) {
            Decoded::Frame { packet, consumed } => {
                assert_eq!(consumed, bytes.len());
                InstructionPacket::from_raw(&packet).unwrap()
            }
            other => panic!("not a frame: {other:?}"),
        }
    }

    #[test]
    fn read_present_position_example() {
        let wire = [0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x07, 0x00, 0x02, 0x84, 0x00, 0x04, 0x00, 0x1D, 0x15];
        let packet = InstructionPacket { id: 1, instruction: Instruction::Read { address: 132, length: 4 } };
        assert_eq!(packet.encode().unwrap(), wire.to_vec());
        assert_eq!(decode_instruction(&wire), packet);
    }

    #[test]
    fn present_position_status_example() {
        let wire = [0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x08, 0x00, 0x55, 0x00, 0xA6, 0x00, 0x00, 0x00, 0x8C, 0xC0];
        let status = StatusPacket { id: 1, error: 0, params: 166u32.to_le_bytes().to_vec() };
        assert_eq!(status.encode().unwrap(), wire.to_vec());
        let Decoded::Frame { packet, .. } = RawPacket::decode(&wire) else { panic!("no frame") };
        let decoded = StatusPacket::from_raw(&packet).unwrap();
        assert_eq!(decoded, status);
        assert_eq!(u32::from_le_bytes(decoded.params.try_into().unwrap()), 166);
    }

    #[test]
    fn sync_write_goal_position_example() {
        let wire = [
            0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x11, 0x00, 0x83, 0x74, 0x00, 0x04, 0x00, 0x01, 0x96, 0x00, 0x00, 0x00, 0x02,
            0xAA, 0x00, 0x00, 0x00, 0x82, 0x87,
        ];
        let packet = InstructionPacket {
            id: 0xFE,
            instruction: Instruction::SyncWrite {
                address: 116,
                length: 4,
                entries: vec![(1, 150u32.to_le_bytes().to_vec()), (2, 170u32.to_le_bytes().to_vec())],
            },
        };
        assert_eq!(packet.encode().unwrap(), wire.to_vec());
        assert_eq!(decode_instruction(&wire), packet);
    }

    #[test]
    fn ping_example() {
        let wire = [0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x03, 0x00, 0x01, 0x19, 0x4E];
        let packet = InstructionPacket { id: 1, instruction: Instruction::Ping };
        assert_eq!(packet.encode().unwrap(), wire.to_vec());
        assert_eq!(decode_instruction(&wire), packet);
    }

    #[test]
    fn malformed_parameters_are_errors() {
        assert!(matches!(Instruction::decode(code::READ, &[0x84, 0x00]), Err(DxlError::BadParameters { .. })));
        assert!(Instruction::decode(code::SYNC_WRITE, &[0x74, 0, 4, 0, 1, 2]).is_err());
        assert!(matches!(Instruction::decode(0x42, &[]), Err(DxlError::UnknownInstruction(0x42))));
    }
}
