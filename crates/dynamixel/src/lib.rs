#![doc = include_str!("../README.md")]
#![warn(missing_docs)]

pub mod control_table;
pub mod crc;
pub mod device;
mod error;
pub mod instruction;
pub mod packet;
pub mod stuffing;
pub mod units;

pub use control_table::ControlTable;
pub use device::VirtualBus;
pub use error::{DxlError, MAX_PACKET_LEN};
pub use instruction::{BulkReadEntry, BulkWriteEntry, Instruction, InstructionPacket, StatusErrorCode, StatusPacket};
pub use packet::{BROADCAST_ID, RawPacket, StreamDecoder};
