//! [`DxlError`]: why bytes are not a valid frame or packet, and the protocol's limits.

/// Longest packet accepted or produced, in wire bytes. Real devices have smaller receive buffers;
/// the cap bounds how long a corrupt length field can stall the stream decoder.
pub const MAX_PACKET_LEN: usize = 4096;

/// Dynamixel protocol errors.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DxlError {
    /// Bytes before the next header were dropped.
    #[error("skipped {skipped} bytes that are not a packet header")]
    Garbage {
        /// Bytes dropped.
        skipped: usize,
    },
    /// The length field is below 3 or above the cap.
    #[error("packet length field {len} is invalid")]
    BadLength {
        /// The length field.
        len: usize,
    },
    /// The CRC does not match.
    #[error(
        "CRC mismatch in a packet to ID {id} (instruction {instruction:#04x}): computed {expected:#06x}, received {received:#06x}"
    )]
    BadCrc {
        /// CRC of the received bytes.
        expected: u16,
        /// CRC field of the packet.
        received: u16,
        /// The packet's ID field (a device with this ID answers with a CRC error status).
        id: u8,
        /// The packet's instruction field (0x55 for a status packet).
        instruction: u8,
    },
    /// A packet to encode is too long.
    #[error("packet of {len} bytes exceeds the {max}-byte limit")]
    TooLong {
        /// Encoded length.
        len: usize,
        /// Limit.
        max: usize,
    },
    /// The instruction byte is not in Protocol 2.0.
    #[error("unknown instruction {0:#04x}")]
    UnknownInstruction(u8),
    /// The parameters do not fit the instruction.
    #[error("{len} parameter bytes do not fit instruction {instruction:#04x}")]
    BadParameters {
        /// Instruction byte.
        instruction: u8,
        /// Parameter count.
        len: usize,
    },
    /// A status packet where an instruction was expected.
    #[error("expected an instruction packet, got a status packet")]
    NotAnInstruction,
    /// An instruction packet where a status was expected.
    #[error("expected a status packet, got instruction {0:#04x}")]
    NotAStatus(u8),
    /// A status packet without its error byte.
    #[error("status packet has no error byte")]
    MissingErrorByte,
    /// The address range is outside the control table.
    #[error("address {address} length {length} is outside the control table")]
    OutOfTable {
        /// Start address.
        address: u16,
        /// Length.
        length: u16,
    },
    /// Address not writable by the host.
    #[error("address {address} is read-only or unassigned")]
    NotWritable {
        /// First offending address.
        address: u16,
    },
    /// EEPROM write while torque is on.
    #[error("address {address} is in EEPROM, writable only with torque off")]
    EepromLocked {
        /// First offending address.
        address: u16,
    },
    /// A write covers only part of a field (the e-manual's example: 2 bytes to the 4-byte Goal
    /// Position); status error 0x05.
    #[error("the write covers only part of the {size}-byte field at address {address}")]
    DataLength {
        /// Start address of the field.
        address: u16,
        /// Size of the field.
        size: u16,
    },
    /// A value outside the field's range (status error 0x04).
    #[error("{name} {value} is outside its range {min}..={max}")]
    OutOfRange {
        /// The field's name (e-manual).
        name: &'static str,
        /// The value written.
        value: i64,
        /// Lowest value allowed.
        min: i64,
        /// Highest value allowed.
        max: i64,
    },
    /// Invalid or duplicate device ID.
    #[error("device ID {0} is invalid or already on the bus")]
    BadDeviceId(u8),
    /// A physical value has no representation in the field.
    #[error("{quantity} {value} is not representable in the device's units")]
    Unrepresentable {
        /// What was converted.
        quantity: &'static str,
        /// The value.
        value: f64,
    },
}
