//! The small analytic scenes of models/validation/, compiled with a scenario's `[physics]` options
//! (the same header as the cell), for tests/physics_validation.rs and for speed-vs-accuracy charts.

use super::compose::header;
use super::template::{num, render};
use super::{PhysicsConfig, PhysicsError};
use mujoco_rs::prelude::MjModel;

const BOX_ON_PLANE: &str = include_str!("../../../../models/validation/box_on_plane.xml");
const SLOPE: &str = include_str!("../../../../models/validation/slope.xml");
const PINCH: &str = include_str!("../../../../models/validation/pinch.xml");

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
/// actuators `squeeze_l`, `squeeze_r` are the pads' normal forces \[N\].
pub fn pinch(p: &PhysicsConfig, mu: f64) -> Result<MjModel, PhysicsError> {
    compile(PINCH, &[("header", header(p)), ("mu", num(mu))])
}

/// One of these scenes run on either backend (`physics.backend`), with what the analytic checks
/// read: body positions and contact normal forces, by MuJoCo name.
pub struct ValidationRun {
    model: std::sync::Arc<MjModel>,
    engine: Engine,
}

enum Engine {
    Mujoco(Box<mujoco_rs::prelude::MjData<std::sync::Arc<MjModel>>>),
    Rapier(Box<super::rapier::RapierWorld>),
}

impl ValidationRun {
    /// Starts `model` (a model, or one shared by several runs) at its `qpos0` on the backend `p` names.
    pub fn new(model: impl Into<std::sync::Arc<MjModel>>, p: &PhysicsConfig) -> Result<ValidationRun, PhysicsError> {
        let model = model.into();
        let engine = match p.backend {
            super::Backend::Mujoco => {
                let mut d = mujoco_rs::prelude::MjData::new(model.clone());
                d.forward();
                Engine::Mujoco(Box::new(d))
            }
            super::Backend::Rapier => Engine::Rapier(Box::new(super::rapier::RapierWorld::build(&model, p, &[])?)),
        };
        Ok(ValidationRun { model, engine })
    }

    fn id(&self, kind: mujoco_rs::mujoco_c::_mjtObjBase, name: &str) -> Result<usize, PhysicsError> {
        self.model.name_to_id(kind, name).ok_or_else(|| PhysicsError::Missing { kind: "element", name: name.into() })
    }

    /// Sets the named actuator's control.
    pub fn set_ctrl(&mut self, actuator: &str, value: f64) -> Result<(), PhysicsError> {
        let a = self.id(mujoco_rs::mujoco_c::_mjtObjBase::mjOBJ_ACTUATOR, actuator)?;
        match &mut self.engine {
            Engine::Mujoco(d) => d.ctrl_mut()[a] = value,
            Engine::Rapier(w) => w.set_ctrl(a, value),
        }
        Ok(())
    }

    /// Steps for `seconds` (whole steps).
    pub fn run_for(&mut self, seconds: f64) -> Result<(), PhysicsError> {
        let dt = self.model.opt().timestep;
        for _ in 0..(seconds / dt).round() as usize {
            match &mut self.engine {
                Engine::Mujoco(d) => d.step(),
                Engine::Rapier(w) => w.step()?,
            }
        }
        Ok(())
    }

    /// World position of the named body's origin \[m\].
    pub fn body_position(&self, body: &str) -> Result<[f64; 3], PhysicsError> {
        let b = self.id(mujoco_rs::mujoco_c::_mjtObjBase::mjOBJ_BODY, body)?;
        Ok(match &self.engine {
            Engine::Mujoco(d) => d.xpos()[b],
            Engine::Rapier(w) => w.body_pose(b).translation.into(),
        })
    }

    /// Sum of the contact normal forces on the named geom \[N\].
    pub fn normal_force_on(&self, geom: &str) -> Result<f64, PhysicsError> {
        let g = self.id(mujoco_rs::mujoco_c::_mjtObjBase::mjOBJ_GEOM, geom)?;
        Ok(match &self.engine {
            Engine::Mujoco(d) => d
                .contact()
                .iter()
                .enumerate()
                .filter(|(_, c)| c.geom1 as usize == g || c.geom2 as usize == g)
                .map(|(i, _)| d.contact_force(i)[0])
                .sum(),
            Engine::Rapier(w) => {
                let all: Vec<usize> = (0..self.model.ffi().ngeom as usize).collect();
                w.normal_force_between(&[g], &all).0
            }
        })
    }
}
