//! The MX-106 (Protocol 2.0, model number 321) control table.
//!
//! Source: ROBOTIS e-manual "MX-106(2.0)" (emanual.robotis.com/docs/en/dxl/mx/mx-106-2/): the
//! addresses, sizes, access and initial values of both tables (EEPROM and RAM) are the manual's;
//! where the manual gives "-" (measured or set by the device) the initial values marked `guess`
//! are ours. Indirect addresses (168 and up) are not modelled: reads or writes there get an Access
//! error.
//!
//! Writes are checked as the device checks them (e-manual, Protocol 2.0 "Status Packet"): a byte
//! of a read-only or undefined address, or of EEPROM while torque is on, is an Access error
//! (0x07); a write that covers only part of a field is a Data Length error (0x05); a value outside
//! the field's range is a Data Range error (0x04). The ranges checked are [`ControlTable::range`]'s,
//! from the field descriptions of the same manual; fields it does not list accept any value.

use super::DxlError;

/// Who may write a field.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Access {
    /// Read-only for the host (the device updates it).
    Read,
    /// Readable and writable; in EEPROM (address < 64) only while torque is off.
    ReadWrite,
}

/// One control-table field.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Field {
    /// Name as in the e-manual.
    pub name: &'static str,
    /// Address.
    pub address: u16,
    /// Size in bytes (1, 2 or 4), little-endian.
    pub size: u16,
    /// Host access.
    pub access: Access,
    /// Factory default (for signed fields, the two's complement bit pattern).
    pub default: u32,
}

const fn f(name: &'static str, address: u16, size: u16, access: Access, default: u32) -> Field {
    Field { name, address, size, access, default }
}

use Access::{Read as R, ReadWrite as RW};

/// Model number of the MX-106 under Protocol 2.0.
pub const MX106_MODEL_NUMBER: u16 = 321;
/// First RAM address: below it is EEPROM, writable only with torque off.
pub const RAM_START: u16 = 64;
/// Size of the modelled table (addresses 0..=146).
pub const TABLE_LEN: usize = 147;

/// Addresses the drivers use (docs/facts.md#mx-106-control-table).
pub mod addr {
    /// Model Number (2 bytes, 321).
    pub const MODEL_NUMBER: u16 = 0;
    /// Firmware Version (1).
    pub const FIRMWARE_VERSION: u16 = 6;
    /// ID (1).
    pub const ID: u16 = 7;
    /// Baud Rate (1).
    pub const BAUD_RATE: u16 = 8;
    /// Operating Mode (1): 0 current, 1 velocity, 3 position, 4 extended position, 5 current-based position, 16 PWM.
    pub const OPERATING_MODE: u16 = 11;
    /// Moving Threshold (4, 0.229 rpm units): above it, Moving reads 1.
    pub const MOVING_THRESHOLD: u16 = 24;
    /// PWM Limit (2).
    pub const PWM_LIMIT: u16 = 36;
    /// Current Limit (2, 3.36 mA units).
    pub const CURRENT_LIMIT: u16 = 38;
    /// Velocity Limit (4, 0.229 rpm units).
    pub const VELOCITY_LIMIT: u16 = 44;
    /// Max Position Limit (4, ticks; position mode only).
    pub const MAX_POSITION_LIMIT: u16 = 48;
    /// Min Position Limit (4, ticks; position mode only).
    pub const MIN_POSITION_LIMIT: u16 = 52;
    /// Torque Enable (1).
    pub const TORQUE_ENABLE: u16 = 64;
    /// Status Return Level (1): 0 ping only, 1 ping and read, 2 all.
    pub const STATUS_RETURN_LEVEL: u16 = 68;
    /// Registered Instruction (1).
    pub const REGISTERED_INSTRUCTION: u16 = 69;
    /// Hardware Error Status (1).
    pub const HARDWARE_ERROR_STATUS: u16 = 70;
    /// Goal PWM (2, signed).
    pub const GOAL_PWM: u16 = 100;
    /// Goal Current (2, 3.36 mA units).
    pub const GOAL_CURRENT: u16 = 102;
    /// Goal Velocity (4, 0.229 rpm units).
    pub const GOAL_VELOCITY: u16 = 104;
    /// Profile Acceleration (4).
    pub const PROFILE_ACCELERATION: u16 = 108;
    /// Profile Velocity (4).
    pub const PROFILE_VELOCITY: u16 = 112;
    /// Goal Position (4, 4096 ticks/rev).
    pub const GOAL_POSITION: u16 = 116;
    /// Realtime Tick (2, ms, wraps at 32 767).
    pub const REALTIME_TICK: u16 = 120;
    /// Moving (1).
    pub const MOVING: u16 = 122;
    /// Present Current (2, signed).
    pub const PRESENT_CURRENT: u16 = 126;
    /// Present Velocity (4, signed).
    pub const PRESENT_VELOCITY: u16 = 128;
    /// Present Position (4, signed).
    pub const PRESENT_POSITION: u16 = 132;
    /// Present Input Voltage (2, 0.1 V).
    pub const PRESENT_INPUT_VOLTAGE: u16 = 144;
    /// Present Temperature (1, °C).
    pub const PRESENT_TEMPERATURE: u16 = 146;
}

/// The modelled fields, in address order.
pub const FIELDS: &[Field] = &[
    f("Model Number", 0, 2, R, MX106_MODEL_NUMBER as u32),
    f("Model Information", 2, 4, R, 0),
    // guess: a recent MX(2.0) firmware (42 and later have the Clear instruction, the lower
    // Velocity Limit and ignore a broadcast Factory Reset 0xFF; the virtual bus follows those).
    f("Firmware Version", 6, 1, R, 45),
    f("ID", 7, 1, RW, 1),
    f("Baud Rate", 8, 1, RW, 1), // 1 = 57600 bps
    f("Return Delay Time", 9, 1, RW, 250),
    f("Drive Mode", 10, 1, RW, 0),
    f("Operating Mode", 11, 1, RW, 3),
    f("Secondary(Shadow) ID", 12, 1, RW, 255),
    f("Protocol Type", 13, 1, RW, 2),
    f("Homing Offset", 20, 4, RW, 0),
    f("Moving Threshold", 24, 4, RW, 10),
    f("Temperature Limit", 31, 1, RW, 80),
    f("Max Voltage Limit", 32, 2, RW, 160),
    f("Min Voltage Limit", 34, 2, RW, 95),
    f("PWM Limit", 36, 2, RW, 885),
    f("Current Limit", 38, 2, RW, 2047),
    f("Acceleration Limit", 40, 4, RW, 32767),
    f("Velocity Limit", 44, 4, RW, 360), // the manual's table (0.229 rpm units: 82.4 rpm)
    f("Max Position Limit", 48, 4, RW, 4095),
    f("Min Position Limit", 52, 4, RW, 0),
    f("Shutdown", 63, 1, RW, 52),
    f("Torque Enable", 64, 1, RW, 0),
    f("LED", 65, 1, RW, 0),
    f("Status Return Level", 68, 1, RW, 2),
    f("Registered Instruction", 69, 1, R, 0),
    f("Hardware Error Status", 70, 1, R, 0),
    f("Velocity I Gain", 76, 2, RW, 1920),
    f("Velocity P Gain", 78, 2, RW, 100),
    f("Position D Gain", 80, 2, RW, 0),
    f("Position I Gain", 82, 2, RW, 0),
    f("Position P Gain", 84, 2, RW, 850),
    f("Feedforward 2nd Gain", 88, 2, RW, 0),
    f("Feedforward 1st Gain", 90, 2, RW, 0),
    f("Bus Watchdog", 98, 1, RW, 0),
    f("Goal PWM", 100, 2, RW, 885),
    f("Goal Current", 102, 2, RW, 2047),
    f("Goal Velocity", 104, 4, RW, 0),
    f("Profile Acceleration", 108, 4, RW, 0),
    f("Profile Velocity", 112, 4, RW, 0),
    f("Goal Position", 116, 4, RW, 2048), // guess: mid-range, where Present Position starts
    f("Realtime Tick", 120, 2, R, 0),
    f("Moving", 122, 1, R, 0),
    f("Moving Status", 123, 1, R, 0),
    f("Present PWM", 124, 2, R, 0),
    f("Present Current", 126, 2, R, 0),
    f("Present Velocity", 128, 4, R, 0),
    f("Present Position", 132, 4, R, 2048), // guess: the twin overwrites it
    f("Velocity Trajectory", 136, 4, R, 0),
    f("Position Trajectory", 140, 4, R, 0),
    f("Present Input Voltage", 144, 2, R, 120), // guess: 12.0 V supply
    f("Present Temperature", 146, 1, R, 30),    // guess: 30 °C
];

/// Operating Mode values the MX-106(2.0) has: current, velocity, position, extended position,
/// current-based position, PWM.
pub const OPERATING_MODES: [u8; 6] = [0, 1, 3, 4, 5, 16];
/// Operating Mode 3, position control within one turn.
pub const POSITION_MODE: u8 = 3;

/// The field that contains `address`, if any.
pub fn field_at(address: u16) -> Option<&'static Field> {
    FIELDS.iter().find(|f| address >= f.address && address < f.address + f.size)
}

/// The control table of one MX-106.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ControlTable {
    bytes: [u8; TABLE_LEN],
}

impl Default for ControlTable {
    fn default() -> Self {
        Self::with_id(1)
    }
}

impl ControlTable {
    /// Factory defaults with the given ID.
    pub fn with_id(id: u8) -> Self {
        let mut bytes = [0u8; TABLE_LEN];
        for field in FIELDS {
            let at = usize::from(field.address);
            let size = usize::from(field.size);
            bytes[at..at + size].copy_from_slice(&field.default.to_le_bytes()[..size]);
        }
        bytes[usize::from(addr::ID)] = id;
        Self { bytes }
    }

    /// The ID stored at address 7.
    pub fn id(&self) -> u8 {
        self.bytes[usize::from(addr::ID)]
    }

    /// Whether torque is on (address 64).
    pub fn torque_enabled(&self) -> bool {
        self.bytes[usize::from(addr::TORQUE_ENABLE)] != 0
    }

    /// Operating Mode (address 11).
    pub fn operating_mode(&self) -> u8 {
        self.bytes[usize::from(addr::OPERATING_MODE)]
    }

    /// Status Return Level (address 68).
    pub fn status_return_level(&self) -> u8 {
        self.bytes[usize::from(addr::STATUS_RETURN_LEVEL)]
    }

    /// Goal Position in ticks.
    pub fn goal_position(&self) -> i32 {
        self.u32_at(addr::GOAL_POSITION) as i32
    }

    /// Goal Velocity in 0.229 rpm units.
    pub fn goal_velocity(&self) -> i32 {
        self.u32_at(addr::GOAL_VELOCITY) as i32
    }

    /// Goal Current in 3.36 mA units.
    pub fn goal_current(&self) -> i16 {
        self.u16_at(addr::GOAL_CURRENT) as i16
    }

    /// Sets Present Position (ticks), as the device would from its encoder.
    pub fn set_present_position(&mut self, ticks: i32) {
        self.put(addr::PRESENT_POSITION, &ticks.to_le_bytes());
    }

    /// Sets Present Velocity (0.229 rpm units).
    pub fn set_present_velocity(&mut self, units: i32) {
        self.put(addr::PRESENT_VELOCITY, &units.to_le_bytes());
    }

    /// Sets Present Current (3.36 mA units).
    pub fn set_present_current(&mut self, units: i16) {
        self.put(addr::PRESENT_CURRENT, &units.to_le_bytes());
    }

    /// Sets Present Temperature (°C).
    pub fn set_present_temperature(&mut self, celsius: u8) {
        self.put(addr::PRESENT_TEMPERATURE, &[celsius]);
    }

    /// Sets Moving (0 or 1).
    pub fn set_moving(&mut self, moving: bool) {
        self.put(addr::MOVING, &[u8::from(moving)]);
    }

    /// Present Position in ticks.
    pub fn present_position(&self) -> i32 {
        self.u32_at(addr::PRESENT_POSITION) as i32
    }

    /// Reads `length` bytes at `address` as the host would (gaps between fields read as 0).
    pub fn read(&self, address: u16, length: u16) -> Result<&[u8], DxlError> {
        let (start, end) = self.span(address, length)?;
        Ok(&self.bytes[start..end])
    }

    /// Writes `data` at `address` as the host would: every byte must belong to a writable field
    /// (EEPROM only while torque is off), every field touched must be written whole, and every
    /// value must be in its [`ControlTable::range`]. Nothing is written unless all of it is valid.
    pub fn write(&mut self, address: u16, data: &[u8]) -> Result<(), DxlError> {
        let length = u16::try_from(data.len()).map_err(|_| DxlError::OutOfTable { address, length: u16::MAX })?;
        let (start, end) = self.span(address, length)?;
        for offset in 0..length {
            let at = address + offset;
            match field_at(at) {
                Some(field) if field.access == Access::ReadWrite => {
                    if at < RAM_START && self.torque_enabled() {
                        return Err(DxlError::EepromLocked { address: at });
                    }
                }
                _ => return Err(DxlError::NotWritable { address: at }),
            }
        }
        let touched: Vec<&'static Field> =
            FIELDS.iter().filter(|f| usize::from(f.address) < end && usize::from(f.address + f.size) > start).collect();
        if let Some(f) =
            touched.iter().find(|f| usize::from(f.address) < start || usize::from(f.address + f.size) > end)
        {
            return Err(DxlError::DataLength { address: f.address, size: f.size });
        }
        // Ranges may depend on other fields written in the same packet (a limit and its goal).
        let mut candidate = self.clone();
        candidate.bytes[start..end].copy_from_slice(data);
        for field in touched {
            candidate.check_range(field)?;
        }
        *self = candidate;
        Ok(())
    }

    /// The values `field` accepts in this table's state (its operating mode and limits), as the
    /// e-manual's field descriptions give them; `None` when any value is accepted.
    ///
    /// Operating Mode accepts only 0, 1, 3, 4, 5 and 16 within this range ([`OPERATING_MODES`]).
    pub fn range(&self, field: &Field) -> Option<(i64, i64)> {
        let limit = |address| i64::from(self.u32_at(address));
        let limit16 = |address| i64::from(self.u16_at(address));
        Some(match field.address {
            addr::ID => (0, 252),
            addr::BAUD_RATE => (0, 7),
            addr::OPERATING_MODE => (0, 16),
            13 => (1, 2),                        // Protocol Type
            20 => (-1_044_479, 1_044_479),       // Homing Offset
            addr::MOVING_THRESHOLD => (0, 1023), // Moving Threshold
            31 => (0, 100),                      // Temperature Limit
            32 | 34 => (95, 160),                // Max/Min Voltage Limit
            addr::PWM_LIMIT => (0, 885),
            addr::CURRENT_LIMIT => (0, 2047),
            40 => (0, 32767), // Acceleration Limit
            addr::VELOCITY_LIMIT => (0, 1023),
            addr::MAX_POSITION_LIMIT | addr::MIN_POSITION_LIMIT => (0, 4095),
            addr::TORQUE_ENABLE | 65 => (0, 1), // Torque Enable, LED
            addr::STATUS_RETURN_LEVEL => (0, 2),
            76..=90 => (0, 16383), // the PID and feedforward gains
            98 => (0, 127),        // Bus Watchdog (1..127 × 20 ms; 0 off)
            addr::GOAL_PWM => (-limit16(addr::PWM_LIMIT), limit16(addr::PWM_LIMIT)),
            addr::GOAL_CURRENT => (-limit16(addr::CURRENT_LIMIT), limit16(addr::CURRENT_LIMIT)),
            addr::GOAL_VELOCITY => (-limit(addr::VELOCITY_LIMIT), limit(addr::VELOCITY_LIMIT)),
            addr::PROFILE_ACCELERATION | addr::PROFILE_VELOCITY => (0, 32767),
            addr::GOAL_POSITION => match self.operating_mode() {
                // Position mode: one turn, within the position limits.
                POSITION_MODE => (limit(addr::MIN_POSITION_LIMIT), limit(addr::MAX_POSITION_LIMIT)),
                // Extended and current-based position: ±256 turns.
                _ => (-1_048_575, 1_048_575),
            },
            _ => return None,
        })
    }

    /// The value of `field` (sign-extended where the field is signed).
    pub fn value(&self, field: &Field) -> i64 {
        let signed = matches!(
            field.address,
            20 | addr::GOAL_PWM | addr::GOAL_CURRENT | addr::GOAL_VELOCITY | addr::GOAL_POSITION | 124..=143
        );
        match (field.size, signed) {
            (1, _) => i64::from(self.bytes[usize::from(field.address)]),
            (2, false) => i64::from(self.u16_at(field.address)),
            (2, true) => i64::from(self.u16_at(field.address) as i16),
            (_, false) => i64::from(self.u32_at(field.address)),
            (_, true) => i64::from(self.u32_at(field.address) as i32),
        }
    }

    fn check_range(&self, field: &'static Field) -> Result<(), DxlError> {
        let value = self.value(field);
        let out = |(min, max)| DxlError::OutOfRange { name: field.name, value, min, max };
        if let Some((min, max)) = self.range(field)
            && !(min..=max).contains(&value)
        {
            return Err(out((min, max)));
        }
        if field.address == addr::OPERATING_MODE && !OPERATING_MODES.contains(&(value as u8)) {
            return Err(out((0, 16)));
        }
        Ok(())
    }

    /// Device-side write, with no access check (the device updating its own Present values).
    pub fn put(&mut self, address: u16, data: &[u8]) {
        let start = usize::from(address).min(TABLE_LEN);
        let end = (start + data.len()).min(TABLE_LEN);
        self.bytes[start..end].copy_from_slice(&data[..end - start]);
    }

    /// Little-endian u16 at `address` (0 outside the table).
    pub fn u16_at(&self, address: u16) -> u16 {
        let a = usize::from(address);
        if a + 2 > TABLE_LEN {
            return 0;
        }
        u16::from_le_bytes([self.bytes[a], self.bytes[a + 1]])
    }

    /// Little-endian u32 at `address` (0 outside the table).
    pub fn u32_at(&self, address: u16) -> u32 {
        let a = usize::from(address);
        if a + 4 > TABLE_LEN {
            return 0;
        }
        u32::from_le_bytes([self.bytes[a], self.bytes[a + 1], self.bytes[a + 2], self.bytes[a + 3]])
    }

    fn span(&self, address: u16, length: u16) -> Result<(usize, usize), DxlError> {
        let start = usize::from(address);
        let end = start + usize::from(length);
        if length == 0 || end > TABLE_LEN {
            return Err(DxlError::OutOfTable { address, length });
        }
        Ok((start, end))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_carry_model_number_and_id() {
        let table = ControlTable::with_id(2);
        assert_eq!(table.u16_at(addr::MODEL_NUMBER), 321);
        assert_eq!(table.id(), 2);
        assert_eq!(table.operating_mode(), 3);
        assert!(!table.torque_enabled());
    }

    #[test]
    fn fields_are_ordered_and_disjoint_and_inside_the_table() {
        for pair in FIELDS.windows(2) {
            assert!(pair[0].address + pair[0].size <= pair[1].address, "{} overlaps {}", pair[0].name, pair[1].name);
        }
        let last = FIELDS.last().unwrap();
        assert_eq!(usize::from(last.address + last.size), TABLE_LEN);
    }

    #[test]
    fn eeprom_locked_while_torque_on_and_read_only_rejected() {
        let mut table = ControlTable::with_id(1);
        table.write(addr::OPERATING_MODE, &[1]).unwrap();
        table.write(addr::TORQUE_ENABLE, &[1]).unwrap();
        assert!(matches!(table.write(addr::OPERATING_MODE, &[3]), Err(DxlError::EepromLocked { .. })));
        assert!(matches!(table.write(addr::PRESENT_POSITION, &[0; 4]), Err(DxlError::NotWritable { .. })));
        assert!(matches!(table.read(146, 2), Err(DxlError::OutOfTable { .. })));
        assert_eq!(table.operating_mode(), 1);
    }
}
