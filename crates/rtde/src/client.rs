//! The client side of RTDE: builds requests, matches replies to them, decodes data packages.

use std::collections::{BTreeMap, VecDeque};

use super::RtdeError;
use super::packet::{ClientPacket, ControllerVersion, ServerPacket, TextMessage};
use super::recipe::Recipe;
use super::server::PROTOCOL_VERSION;
use super::types::{FieldType, RtdeValue};
use tendril_codec::Decoded;

/// What a server packet meant.
#[derive(Debug, Clone, PartialEq)]
pub enum ClientEvent {
    /// Answer to the version request.
    ProtocolVersion {
        /// Accepted.
        accepted: bool,
    },
    /// The controller version.
    ControllerVersion(ControllerVersion),
    /// A text message from the controller.
    Message(TextMessage),
    /// An output recipe was accepted.
    OutputRecipe(Recipe),
    /// An input recipe was accepted.
    InputRecipe(Recipe),
    /// Answer to start.
    Started {
        /// Accepted.
        accepted: bool,
    },
    /// Answer to pause.
    Paused {
        /// Accepted.
        accepted: bool,
    },
    /// An output data package, decoded with its recipe.
    Data {
        /// Output recipe ID.
        recipe_id: u8,
        /// Values in recipe order.
        values: Vec<RtdeValue>,
    },
}

/// Client connection state.
#[derive(Debug, Clone, Default)]
pub struct ClientSession {
    pending_outputs: VecDeque<Vec<String>>,
    pending_inputs: VecDeque<Vec<String>>,
    outputs: BTreeMap<u8, Recipe>,
    inputs: BTreeMap<u8, Recipe>,
    protocol_accepted: bool,
    controller_version: Option<ControllerVersion>,
    started: bool,
}

impl ClientSession {
    /// A fresh connection.
    pub fn new() -> Self {
        Self::default()
    }

    /// Whether protocol version 2 was accepted.
    pub fn protocol_accepted(&self) -> bool {
        self.protocol_accepted
    }

    /// The controller version, once received.
    pub fn controller_version(&self) -> Option<ControllerVersion> {
        self.controller_version
    }

    /// Whether the controller accepted start (and no pause since).
    pub fn is_started(&self) -> bool {
        self.started
    }

    /// An accepted output recipe.
    pub fn output_recipe(&self, id: u8) -> Option<&Recipe> {
        self.outputs.get(&id)
    }

    /// An accepted input recipe.
    pub fn input_recipe(&self, id: u8) -> Option<&Recipe> {
        self.inputs.get(&id)
    }

    /// `V` request for version 2.
    pub fn request_protocol_version(&mut self) -> ClientPacket {
        ClientPacket::RequestProtocolVersion { version: PROTOCOL_VERSION }
    }

    /// `v` request.
    pub fn request_controller_version(&mut self) -> ClientPacket {
        ClientPacket::GetControllerVersion
    }

    /// `O` request; the reply becomes [`ClientEvent::OutputRecipe`] or an error naming unknown fields.
    pub fn setup_outputs(&mut self, frequency_hz: f64, names: &[&str]) -> Result<ClientPacket, RtdeError> {
        if !(frequency_hz.is_finite() && frequency_hz > 0.0) {
            return Err(RtdeError::BadFrequency(frequency_hz));
        }
        let names: Vec<String> = names.iter().map(|s| s.to_string()).collect();
        let packet = ClientPacket::SetupOutputs { frequency_hz, names: names.clone() };
        packet.encode()?; // reject names that cannot be sent before queueing the request
        self.pending_outputs.push_back(names);
        Ok(packet)
    }

    /// `I` request; the reply becomes [`ClientEvent::InputRecipe`] or an error naming refused fields.
    pub fn setup_inputs(&mut self, names: &[&str]) -> Result<ClientPacket, RtdeError> {
        let names: Vec<String> = names.iter().map(|s| s.to_string()).collect();
        let packet = ClientPacket::SetupInputs { names: names.clone() };
        packet.encode()?;
        self.pending_inputs.push_back(names);
        Ok(packet)
    }

    /// `S` request.
    pub fn start(&mut self) -> ClientPacket {
        ClientPacket::Start
    }

    /// `P` request.
    pub fn pause(&mut self) -> ClientPacket {
        ClientPacket::Pause
    }

    /// A `U` package for input recipe `recipe_id` (values in recipe order, types checked).
    pub fn input_data(&self, recipe_id: u8, values: &[RtdeValue]) -> Result<ClientPacket, RtdeError> {
        let recipe = self.inputs.get(&recipe_id).ok_or(RtdeError::UnknownRecipe(recipe_id))?;
        Ok(ClientPacket::Data { recipe_id, data: recipe.encode(values)? })
    }

    /// Takes complete packets off the front of `buf` (removing them) and interprets them.
    /// Stops at the first error (the rest of `buf` is kept).
    pub fn feed(&mut self, buf: &mut Vec<u8>) -> Result<Vec<ClientEvent>, RtdeError> {
        let mut events = Vec::new();
        loop {
            match ServerPacket::decode(buf) {
                Decoded::NeedMore => return Ok(events),
                Decoded::Frame { packet, consumed } => {
                    buf.drain(..consumed);
                    events.push(self.handle(packet)?);
                }
                Decoded::Invalid { error, consumed } => {
                    buf.drain(..consumed);
                    return Err(error);
                }
            }
        }
    }

    /// Interprets one server packet.
    pub fn handle(&mut self, packet: ServerPacket) -> Result<ClientEvent, RtdeError> {
        Ok(match packet {
            ServerPacket::ProtocolVersion { accepted } => {
                self.protocol_accepted = accepted;
                ClientEvent::ProtocolVersion { accepted }
            }
            ServerPacket::ControllerVersion(v) => {
                self.controller_version = Some(v);
                ClientEvent::ControllerVersion(v)
            }
            ServerPacket::Text(t) => ClientEvent::Message(t),
            ServerPacket::SetupOutputs { recipe_id, types } => {
                let names = self.pending_outputs.pop_front().ok_or(RtdeError::UnexpectedReply('O'))?;
                let recipe = accept(recipe_id, names, types)?;
                self.outputs.insert(recipe_id, recipe.clone());
                ClientEvent::OutputRecipe(recipe)
            }
            ServerPacket::SetupInputs { recipe_id, types } => {
                let names = self.pending_inputs.pop_front().ok_or(RtdeError::UnexpectedReply('I'))?;
                let recipe = accept(recipe_id, names, types)?;
                self.inputs.insert(recipe_id, recipe.clone());
                ClientEvent::InputRecipe(recipe)
            }
            ServerPacket::Start { accepted } => {
                self.started = accepted;
                ClientEvent::Started { accepted }
            }
            ServerPacket::Pause { accepted } => {
                if accepted {
                    self.started = false;
                }
                ClientEvent::Paused { accepted }
            }
            ServerPacket::Data { recipe_id, data } => {
                let recipe = self.outputs.get(&recipe_id).ok_or(RtdeError::UnknownRecipe(recipe_id))?;
                ClientEvent::Data { recipe_id, values: recipe.decode(&data)? }
            }
        })
    }
}

/// Turns a setup reply into a recipe, or an error naming the refused fields.
fn accept(recipe_id: u8, names: Vec<String>, types: Vec<FieldType>) -> Result<Recipe, RtdeError> {
    if types.len() != names.len() {
        return Err(RtdeError::TypeCount { expected: names.len(), got: types.len() });
    }
    let refused = |kind: FieldType| -> Vec<String> {
        names.iter().zip(&types).filter(|(_, t)| **t == kind).map(|(n, _)| n.clone()).collect()
    };
    let (not_found, in_use) = (refused(FieldType::NotFound), refused(FieldType::InUse));
    if !not_found.is_empty() || !in_use.is_empty() || recipe_id == 0 {
        return Err(RtdeError::RecipeRejected { not_found, in_use });
    }
    let types = types.into_iter().filter_map(|t| if let FieldType::Known(t) = t { Some(t) } else { None }).collect();
    Ok(Recipe { id: recipe_id, names, types })
}
