//! The two MX-106 servos (growth, twine) over Dynamixel Protocol 2.0 on a serial port.
//!
//! Client decision (the `dynamixel2` 0.9 stuffing bug on `FF FF FF FD`, see the protocol module):
//! we drive the bus with this project's own codec ([`InstructionPacket`], [`StreamDecoder`]) on a
//! `serial2` port directly, so stuffing is the codec's (tested byte for byte against the manual)
//! and no retry is needed. Blocking IO, each reply bounded by a timeout ([`REPLY_TIMEOUT`] unless
//! set otherwise): the cell sets the bus up and puts it in its safe state directly, and while
//! active drives it from an IO thread of its own ([`super::dxl_link`]), one sync read and one sync
//! write per tick.
//!
//! Set-up: torque off, Operating Mode 4 (extended position: the growth pinion turns 1.9 times over
//! the finger's length and the twine spool up to 680°, beyond one turn of mode 3), torque on, goal
//! = present (hold). Angles are relative to the position read at set-up: the finger must be
//! retracted and untwined when the cell is configured (tick 0 of the run = motor angle 0).
//! Safe state on stop: torque stays ON with goal = present position, so the finger holds the
//! object instead of going limp (torque off would drop it).
//! Timing: at 57 600 baud a sync write plus sync read of two motors takes about 6 ms on the wire:
//! the ticks stay on time (the IO thread is not theirs) but use positions three ticks old; real hardware should run the bus at 1 Mbps or more (`hardware.dxl_baud`),
//! and a USB adapter with its latency timer at 1 ms (FTDI's default is 16 ms).

use serial2::SerialPort;
use std::time::{Duration, Instant};
use tendril_dynamixel::control_table::addr;
use tendril_dynamixel::units::{RAD_PER_TICK, rad_to_ticks};
use tendril_dynamixel::{Instruction, InstructionPacket, StatusPacket, StreamDecoder};

/// Longest wait for a status packet, by default: a motor answers within its Return Delay Time
/// (0.5 ms at the factory setting) plus the wire time, so 50 ms only passes on a dead bus.
pub const REPLY_TIMEOUT: Duration = Duration::from_millis(50);
/// MX-106 model number (ping reply).
pub const MX106_MODEL: u16 = 321;
/// Operating Mode value for extended position control.
pub const EXTENDED_POSITION_MODE: u8 = 4;

/// The gripper's two motors on one bus.
pub struct GripperBus {
    port: SerialPort,
    decoder: StreamDecoder,
    /// Growth motor ID.
    pub growth_id: u8,
    /// Twine motor ID.
    pub twine_id: u8,
    offsets: [i32; 2],
    chunk: Vec<u8>,
    reply_timeout: Duration,
}

fn err(cause: impl std::fmt::Display) -> String {
    format!("Dynamixel: {cause}")
}

impl GripperBus {
    /// Opens the port (raw mode, `baud`), pings both motors (must be model 321) and sets them up;
    /// every reply must come within `reply_timeout`.
    pub fn open(
        path: &str,
        baud: u32,
        [growth_id, twine_id]: [u8; 2],
        reply_timeout: Duration,
    ) -> Result<GripperBus, String> {
        let mut port = SerialPort::open(path, baud).map_err(|e| err(format!("{path}: {e}")))?;
        port.set_read_timeout(Duration::from_millis(5)).map_err(err)?;
        let _ = port.discard_buffers();
        let mut bus = GripperBus {
            port,
            decoder: StreamDecoder::new(),
            growth_id,
            twine_id,
            offsets: [0; 2],
            chunk: vec![0; 1024],
            reply_timeout,
        };
        for id in [growth_id, twine_id] {
            let status = bus.transact(id, Instruction::Ping)?;
            let model = status.params.get(..2).map(|b| u16::from_le_bytes([b[0], b[1]]));
            if model != Some(MX106_MODEL) {
                return Err(err(format!("ID {id} is model {model:?}, expected MX-106 ({MX106_MODEL})")));
            }
            bus.write(id, addr::TORQUE_ENABLE, &[0])?;
            bus.write(id, addr::OPERATING_MODE, &[EXTENDED_POSITION_MODE])?;
        }
        let present = bus.present_ticks()?;
        bus.offsets = present;
        for (id, ticks) in [(growth_id, present[0]), (twine_id, present[1])] {
            bus.write(id, addr::GOAL_POSITION, &ticks.to_le_bytes())?;
            bus.write(id, addr::TORQUE_ENABLE, &[1])?;
        }
        Ok(bus)
    }

    /// Sends one instruction and returns the device's status (error byte checked).
    fn transact(&mut self, id: u8, instruction: Instruction) -> Result<StatusPacket, String> {
        self.send(&InstructionPacket { id, instruction })?;
        let status = self.receive(id)?;
        match status.error_code() {
            Some(code) if code != 0 => Err(err(format!("ID {id} answered error {code}"))),
            _ => Ok(status),
        }
    }

    fn write(&mut self, id: u8, address: u16, data: &[u8]) -> Result<(), String> {
        self.transact(id, Instruction::Write { address, data: data.to_vec() }).map(|_| ())
    }

    fn send(&mut self, packet: &InstructionPacket) -> Result<(), String> {
        let bytes = packet.encode().map_err(err)?;
        self.port.write_all(&bytes).map_err(err)
    }

    /// The next status packet from `id`, skipping echoes and other devices' replies.
    fn receive(&mut self, id: u8) -> Result<StatusPacket, String> {
        let deadline = Instant::now() + self.reply_timeout;
        loop {
            while let Some(item) = self.decoder.next_packet() {
                if let Ok(raw) = item
                    && let Ok(status) = StatusPacket::from_raw(&raw)
                    && status.id == id
                {
                    return Ok(status);
                }
            }
            if Instant::now() >= deadline {
                return Err(err(format!("ID {id} did not answer within {:?}", self.reply_timeout)));
            }
            match self.port.read(&mut self.chunk) {
                Ok(n) => self.decoder.push(&self.chunk[..n]),
                Err(e) if e.kind() == std::io::ErrorKind::TimedOut || e.kind() == std::io::ErrorKind::WouldBlock => {}
                Err(e) => return Err(err(e)),
            }
        }
    }

    /// Present positions [growth, twine] in raw ticks (one sync read).
    fn present_ticks(&mut self) -> Result<[i32; 2], String> {
        self.send(&InstructionPacket {
            id: tendril_dynamixel::BROADCAST_ID,
            instruction: Instruction::SyncRead {
                address: addr::PRESENT_POSITION,
                length: 4,
                ids: vec![self.growth_id, self.twine_id],
            },
        })?;
        let mut out = [0i32; 2];
        for (slot, id) in out.iter_mut().zip([self.growth_id, self.twine_id]) {
            let status = self.receive(id)?;
            let b = status.params.get(..4).ok_or_else(|| err(format!("ID {id}: short sync read reply")))?;
            *slot = i32::from_le_bytes([b[0], b[1], b[2], b[3]]);
        }
        Ok(out)
    }

    /// Motor angles [growth, twine] in rad from the set-up position.
    pub fn present_rad(&mut self) -> Result<[f64; 2], String> {
        let t = self.present_ticks()?;
        Ok([0, 1].map(|i| f64::from(t[i].wrapping_sub(self.offsets[i])) * RAD_PER_TICK))
    }

    /// Goal angles [growth, twine] in rad from the set-up position (one sync write, no reply).
    pub fn set_goal_rad(&mut self, goal: [f64; 2]) -> Result<(), String> {
        let mut entries = Vec::with_capacity(2);
        for (i, id) in [self.growth_id, self.twine_id].into_iter().enumerate() {
            let ticks = rad_to_ticks(goal[i]).map_err(err)?.saturating_add(self.offsets[i]);
            entries.push((id, ticks.to_le_bytes().to_vec()));
        }
        self.send(&InstructionPacket {
            id: tendril_dynamixel::BROADCAST_ID,
            instruction: Instruction::SyncWrite { address: addr::GOAL_POSITION, length: 4, entries },
        })
    }

    /// Safe state: goal = present position, torque left on (the finger keeps its grip).
    pub fn hold(&mut self) -> Result<(), String> {
        let present = self.present_rad()?;
        self.set_goal_rad(present)
    }
}
