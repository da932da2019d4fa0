//! The controller side of RTDE: a sans-IO session the virtual UR5e runs per TCP connection.
//!
//! Compatibility notes (SDU `ur_rtde`, docs/facts.md#ur_rtde-client-behaviour): every request gets exactly one reply and
//! the session never sends an unsolicited text message during setup (ur_rtde reads one packet
//! per request); name lists may end with a comma; unknown names get `NOT_FOUND` in the reply
//! (the recipe is then invalid, ID 0), never a dropped connection.
//!
//! Checked by hand (not in CI) with the PyPI `ur_rtde` `RTDEReceiveInterface` over TCP: the
//! 58-name default recipe at 500 Hz, `actual_q`, robot mode, runtime state and timestamps read back.
//!
//! Recipe IDs: output and input recipes are numbered separately from 1, as ur_rtde's control
//! interface assumes (its input recipes are 1, 2, ... after one output setup).

use std::collections::HashMap;

use super::RtdeError;
use super::fields::{input_type, is_io_input, output_type};
use super::packet::{ClientPacket, ControllerVersion, MessageLevel, ServerPacket, TextMessage};
use super::recipe::Recipe;
use super::state::{OutputSource, RobotInputs, RobotOutputs};
use super::types::{FieldType, RtdeValue};
use tendril_codec::Decoded;

/// The only protocol version served.
pub const PROTOCOL_VERSION: u16 = 2;

/// What the virtual controller announces and allows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ServerConfig {
    /// Reported by `v`. 5.11 or later makes ur_rtde request its full 58-name default recipe.
    pub controller_version: ControllerVersion,
    /// Highest output frequency accepted, Hz (500 on e-Series).
    pub max_frequency_hz: f64,
}

impl Default for ServerConfig {
    fn default() -> Self {
        Self {
            // PolyScope 5.11.1 (build number is ours).
            controller_version: ControllerVersion { major: 5, minor: 11, bugfix: 1, build: 0 },
            max_frequency_hz: 500.0,
        }
    }
}

/// Robot inputs shared by every connection, with which connection claimed which input.
#[derive(Debug, Clone, Default)]
pub struct SharedInputs {
    /// Current input values (the motion program reads them).
    pub values: RobotInputs,
    /// Input data packages applied so far, over all connections: the cadence at which a client
    /// streams its targets.
    pub packages: u64,
    owners: HashMap<String, u64>,
    writes: HashMap<String, u64>,
    /// The IO fields (digital and analog outputs, speed slider) of each package since the last
    /// [`SharedInputs::take_io_packages`], oldest first, at most [`MAX_IO_PACKAGES`].
    io_packages: Vec<Vec<(String, RtdeValue)>>,
}

/// IO packages kept for the device between its ticks (older ones are dropped).
pub const MAX_IO_PACKAGES: usize = 1024;

impl SharedInputs {
    /// Empty inputs, nothing claimed.
    pub fn new() -> Self {
        Self::default()
    }

    /// How many input data packages wrote `name` so far (what `rtde_set_watchdog` watches).
    pub fn writes_of(&self, name: &str) -> u64 {
        self.writes.get(name).copied().unwrap_or(0)
    }

    /// The IO fields of each package received since the last call, oldest first: a mask and its
    /// value apply once, per package, as the controller applies them.
    pub fn take_io_packages(&mut self) -> Vec<Vec<(String, RtdeValue)>> {
        std::mem::take(&mut self.io_packages)
    }

    /// Applies one input data package, its fields by name: their values, their write counts, and
    /// its IO fields for [`SharedInputs::take_io_packages`].
    pub fn apply_package<'a>(&mut self, fields: impl IntoIterator<Item = (&'a str, RtdeValue)>) {
        let mut io = Vec::new();
        for (name, value) in fields {
            if is_io_input(name) {
                io.push((name.to_string(), value));
            }
            self.values.apply(name, value);
            match self.writes.get_mut(name) {
                Some(n) => *n += 1,
                None => {
                    self.writes.insert(name.to_string(), 1);
                }
            }
        }
        if !io.is_empty() {
            if self.io_packages.len() >= MAX_IO_PACKAGES {
                self.io_packages.remove(0);
            }
            self.io_packages.push(io);
        }
        self.packages += 1;
    }

    /// Frees the inputs claimed by a closed connection.
    pub fn release(&mut self, session: u64) {
        self.owners.retain(|_, owner| *owner != session);
    }
}

#[derive(Debug, Clone)]
struct OutputRecipe {
    recipe: Recipe,
    sources: Vec<OutputSource>,
    period_s: f64,
    next_due_s: Option<f64>,
}

/// One client connection as the controller sees it.
#[derive(Debug, Clone)]
pub struct ServerSession {
    session: u64,
    config: ServerConfig,
    protocol_version: Option<u16>,
    outputs: Vec<OutputRecipe>,
    inputs: Vec<Recipe>,
    started: bool,
}

impl ServerSession {
    /// A new connection; `session` must be unique among live connections (it owns input claims).
    pub fn new(session: u64, config: ServerConfig) -> Self {
        Self { session, config, protocol_version: None, outputs: Vec::new(), inputs: Vec::new(), started: false }
    }

    /// This connection's ID.
    pub fn id(&self) -> u64 {
        self.session
    }

    /// The negotiated protocol version.
    pub fn protocol_version(&self) -> Option<u16> {
        self.protocol_version
    }

    /// Whether data is streaming.
    pub fn is_started(&self) -> bool {
        self.started
    }

    /// Accepted output recipes with their frequencies (Hz).
    pub fn output_recipes(&self) -> impl Iterator<Item = (&Recipe, f64)> {
        self.outputs.iter().map(|o| (&o.recipe, 1.0 / o.period_s))
    }

    /// Accepted input recipes.
    pub fn input_recipes(&self) -> &[Recipe] {
        &self.inputs
    }

    /// Takes complete packets off the front of `buf` (removing them), handles them and returns
    /// the reply bytes. An error means the stream is unusable: close the connection.
    pub fn feed(&mut self, buf: &mut Vec<u8>, shared: &mut SharedInputs) -> Result<Vec<u8>, RtdeError> {
        let mut out = Vec::new();
        loop {
            match ClientPacket::decode(buf) {
                Decoded::NeedMore => return Ok(out),
                Decoded::Frame { packet, consumed } => {
                    buf.drain(..consumed);
                    for reply in self.handle(packet, shared) {
                        out.extend_from_slice(&reply.encode()?);
                    }
                }
                Decoded::Invalid { error, consumed } => {
                    buf.drain(..consumed);
                    return Err(error);
                }
            }
        }
    }

    /// The replies to one client packet (zero or one).
    pub fn handle(&mut self, packet: ClientPacket, shared: &mut SharedInputs) -> Vec<ServerPacket> {
        match packet {
            ClientPacket::RequestProtocolVersion { version } => {
                let accepted = version == PROTOCOL_VERSION;
                if accepted {
                    self.protocol_version = Some(version);
                }
                vec![ServerPacket::ProtocolVersion { accepted }]
            }
            ClientPacket::GetControllerVersion => vec![ServerPacket::ControllerVersion(self.config.controller_version)],
            ClientPacket::Text(_) => Vec::new(),
            ClientPacket::SetupOutputs { frequency_hz, names } => vec![self.setup_outputs(frequency_hz, names)],
            ClientPacket::SetupInputs { names } => vec![self.setup_inputs(names, shared)],
            ClientPacket::Start => {
                let accepted = self.protocol_version.is_some() && !(self.outputs.is_empty() && self.inputs.is_empty());
                if accepted {
                    self.started = true;
                    self.outputs.iter_mut().for_each(|o| o.next_due_s = None);
                }
                vec![ServerPacket::Start { accepted }]
            }
            ClientPacket::Pause => {
                self.started = false;
                vec![ServerPacket::Pause { accepted: true }]
            }
            ClientPacket::Data { recipe_id, data } => match self.apply_input(recipe_id, &data, shared) {
                Ok(()) => Vec::new(),
                Err(e) => vec![ServerPacket::Text(TextMessage {
                    message: truncate(&e.to_string()),
                    source: "RTDE".into(),
                    level: MessageLevel::Error,
                })],
            },
        }
    }

    fn setup_outputs(&mut self, frequency_hz: f64, names: Vec<String>) -> ServerPacket {
        let types: Vec<FieldType> =
            names.iter().map(|n| output_type(n).map_or(FieldType::NotFound, FieldType::Known)).collect();
        let frequency_ok =
            frequency_hz.is_finite() && frequency_hz > 0.0 && frequency_hz <= self.config.max_frequency_hz;
        let valid = self.protocol_version.is_some()
            && !self.started
            && frequency_ok
            && !names.is_empty()
            && types.iter().all(|t| matches!(t, FieldType::Known(_)))
            && self.outputs.len() < usize::from(u8::MAX);
        if !valid {
            return ServerPacket::SetupOutputs { recipe_id: 0, types };
        }
        let id = self.outputs.len() as u8 + 1;
        let known: Vec<_> =
            types.iter().filter_map(|t| if let FieldType::Known(t) = t { Some(*t) } else { None }).collect();
        let sources = names.iter().zip(&known).map(|(n, &t)| OutputSource::resolve(n, t)).collect();
        self.outputs.push(OutputRecipe {
            recipe: Recipe { id, names, types: known },
            sources,
            period_s: 1.0 / frequency_hz,
            next_due_s: None,
        });
        ServerPacket::SetupOutputs { recipe_id: id, types }
    }

    fn setup_inputs(&mut self, names: Vec<String>, shared: &mut SharedInputs) -> ServerPacket {
        let types: Vec<FieldType> = names
            .iter()
            .map(|n| match input_type(n) {
                None => FieldType::NotFound,
                Some(_) if shared.owners.get(n).is_some_and(|&o| o != self.session) => FieldType::InUse,
                Some(t) => FieldType::Known(t),
            })
            .collect();
        let valid = self.protocol_version.is_some()
            && !self.started
            && !names.is_empty()
            && types.iter().all(|t| matches!(t, FieldType::Known(_)))
            && self.inputs.len() < usize::from(u8::MAX);
        if !valid {
            return ServerPacket::SetupInputs { recipe_id: 0, types };
        }
        for n in &names {
            shared.owners.insert(n.clone(), self.session);
        }
        let id = self.inputs.len() as u8 + 1;
        let known = types.iter().filter_map(|t| if let FieldType::Known(t) = t { Some(*t) } else { None }).collect();
        self.inputs.push(Recipe { id, names, types: known });
        ServerPacket::SetupInputs { recipe_id: id, types }
    }

    fn apply_input(&mut self, recipe_id: u8, data: &[u8], shared: &mut SharedInputs) -> Result<(), RtdeError> {
        let recipe =
            self.inputs.get(usize::from(recipe_id).wrapping_sub(1)).ok_or(RtdeError::UnknownRecipe(recipe_id))?;
        let values = recipe.decode(data)?;
        // Applied whether or not the session was started: SDU ur_rtde's RTDEIOInterface sets up
        // its input recipes and sends data packages without ever sending START, and works on real
        // controllers, so they take inputs from a session that has not started.
        shared.apply_package(recipe.names.iter().map(String::as_str).zip(values));
        Ok(())
    }

    /// Data packages due at time `now_s` (s, any monotonic clock), one per output recipe whose
    /// period has elapsed. Empty unless started. A recipe that fell behind by more than one
    /// period restarts its schedule instead of bursting.
    pub fn poll_outputs(&mut self, now_s: f64, outputs: &RobotOutputs, shared: &SharedInputs) -> Vec<ServerPacket> {
        if !self.started {
            return Vec::new();
        }
        let mut packets = Vec::new();
        for o in &mut self.outputs {
            let due = o.next_due_s.unwrap_or(now_s);
            if now_s + 1e-9 < due {
                continue;
            }
            let next = due + o.period_s;
            o.next_due_s = Some(if next <= now_s { now_s + o.period_s } else { next });
            packets.push(encode_outputs(o, outputs, &shared.values));
        }
        packets
    }

    /// The data package of output recipe `recipe_id` for the given state, regardless of schedule.
    pub fn data_package(
        &self,
        recipe_id: u8,
        outputs: &RobotOutputs,
        shared: &SharedInputs,
    ) -> Result<ServerPacket, RtdeError> {
        let o = self.outputs.get(usize::from(recipe_id).wrapping_sub(1)).ok_or(RtdeError::UnknownRecipe(recipe_id))?;
        Ok(encode_outputs(o, outputs, &shared.values))
    }
}

fn encode_outputs(o: &OutputRecipe, outputs: &RobotOutputs, inputs: &RobotInputs) -> ServerPacket {
    let mut data = Vec::with_capacity(o.recipe.data_len());
    for source in &o.sources {
        source.value(outputs, inputs).encode_into(&mut data);
    }
    ServerPacket::Data { recipe_id: o.recipe.id, data }
}

/// Text messages carry at most 255 bytes.
fn truncate(s: &str) -> String {
    let mut end = s.len().min(255);
    while !s.is_char_boundary(end) {
        end -= 1;
    }
    s[..end].to_string()
}
