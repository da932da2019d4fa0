//! The small analytic scenes of models/validation/, compiled with a scenario's `[physics]` options
//! (the same header as the cell), for tests/physics_validation.rs and for speed-vs-accuracy charts.

use super::compose::header;
use super::template::{num, render};
use super::{PhysicsConfig, PhysicsError};
use mujoco_rs::prelude::MjModel;

const BOX_ON_PLANE: &str = include_str!("../../../models/validation/box_on_plane.xml");
const SLOPE: &str = include_str!("../../../models/validation/slope.xml");
const PINCH: &str = include_str!("../../../models/validation/pinch.xml");

fn compile(text: &str, values: &[(&str, String)]) -> Result<MjModel, PhysicsError> {
    let body = text.split_once("-->").map_or(text, |(_, rest)| rest);
    let xml = render(body, values)?;
    MjModel::from_xml_string(&xml).map_err(|e| PhysicsError::Compile { message: format!("{e:?}") })
}

/// A 1 kg, 0.1 m box resting on a plane (body `box`, geom `box`, geom `floor`).
pub fn box_on_plane(p: &PhysicsConfig) -> Result<MjModel, PhysicsError> {
    compile(BOX_ON_PLANE, &[("header", header(p))])
}

/// A 0.5 kg box on a plane tilted by `angle_rad` about y, friction 0.5 (body `box`, body `ramp`).
pub fn slope(p: &PhysicsConfig, angle_rad: f64) -> Result<MjModel, PhysicsError> {
    let normal = [angle_rad.sin(), 0.0, angle_rad.cos()];
    let pos = super::template::nums(&normal.map(|n| 0.025 * n));
    compile(SLOPE, &[("header", header(p)), ("angle_rad", num(angle_rad)), ("box_pos", pos)])
}

/// Two pads on a carriage (slide joint `lift`) squeezing a 0.35 kg box with friction `mu` on every geom;
/// actuators `squeeze_l`, `squeeze_r` are the pads' normal forces [N].
pub fn pinch(p: &PhysicsConfig, mu: f64) -> Result<MjModel, PhysicsError> {
    compile(PINCH, &[("header", header(p)), ("mu", num(mu))])
}
