//! The physics of the cell: UR5e, grow-and-twine finger with the FBG sensor pad, one of the paper's
//! objects and the table, assembled from models/ for what a scenario needs and simulated by MuJoCo or
//! rapier behind one [`Physics`] trait.
//!
//! - [`config`]: the `[physics]` (with `[physics.rapier]`), `[finger]` and `[object]` sections.
//! - [`compose`]: MJCF assembly from the model files. MuJoCo compiles it into the [`SceneModel`],
//!   the one description of the scene both backends start from.
//! - [`scene`]: the MuJoCo run ([`Scene`]); [`rapier`]: the rapier world built from the compiled
//!   model and its run ([`rapier::RapierScene`]).
//! - [`drive`]: motor speed limits, the kinematic arm's interpolation and the grip-in-hand
//!   readout, shared by both backends.
//! - [`export`]: the scene as one standalone MJCF with a start keyframe (`tendril scene`).
//! - [`object`]: an object's model file, its contract checked, its mass and grip read from it.
//! - [`ur5e`]: DH kinematics.

pub mod check;
pub mod compose;
pub mod config;
pub mod drive;
pub mod export;
pub mod object;
pub mod rapier;
pub mod scene;
pub mod strip;
pub mod template;
pub mod validation;

/// The arm's kinematics, shared with the control side ([`crate::ur5e`]).
pub use crate::ur5e;
pub use compose::Placement;
pub use config::{
    ArmMode, Backend, Cone, FingerConfig, Integrator, ObjectConfig, ObjectName, PhysicsConfig, RapierConfig, Solver,
};
pub use scene::{PhysicsReadout, Scene, SceneModel};

/// One simulation run of the cell, whichever engine steps it. The cell ([`crate::cell::sim`]) only
/// talks to this.
pub trait Physics: Send {
    /// The engine.
    fn backend(&self) -> Backend;
    /// Simulated time \[s\].
    fn time(&self) -> f64;
    /// Step size \[s\].
    fn timestep(&self) -> f64;
    /// Commands the finger growth (strip length out of the guide) \[m\], clamped to 0..finger.length_m.
    /// The servo's setpoint follows at most at `finger.motor_max_speed_m_s`.
    fn set_growth(&mut self, growth_m: f64) -> Result<(), PhysicsError>;
    /// Commands the twine motor: metres of tendon wound in (the twining/curl input, the PID's output),
    /// clamped to 0..finger.twine_max_m. More twine curls the strip tighter and raises the grip force.
    /// The servo's setpoint follows at most at `finger.motor_max_speed_m_s`.
    fn set_twine(&mut self, twine_m: f64) -> Result<(), PhysicsError>;
    /// Commands the arm joint targets \[rad\]. Dynamic mode: the position servos' setpoints. Kinematic
    /// mode: the arm moves towards them at most at `physics.arm_max_speed_rad_s` per joint, and the hand
    /// follows the flange pose from forward kinematics.
    fn set_arm_target(&mut self, q: [f64; 6]) -> Result<(), PhysicsError>;
    /// Advances one step; a diverging state is a [`PhysicsError::Diverged`] with the time.
    fn step(&mut self) -> Result<(), PhysicsError>;
    /// The readout after the last step.
    fn readout(&self) -> PhysicsReadout;
    /// Applies `force_n` \[N\] (world frame) at the object's centre of mass during the following
    /// steps, until set again (zero to stop): the twin's `[disturbance.push]`. Engines that cannot
    /// refuse with [`PhysicsError::Config`] on `disturbance.push`.
    fn set_object_force(&mut self, force_n: [f64; 3]) -> Result<(), PhysicsError> {
        let _ = force_n;
        Err(PhysicsError::Config {
            key: "disturbance.push".into(),
            reason: format!(
                "the {} backend does not apply pushes; use physics.backend = \"mujoco\"",
                self.backend().name()
            ),
        })
    }

    /// The whole scene's state in MuJoCo's layout (qpos, qvel, ctrl, act of the compiled
    /// [`SceneModel`]), recorded for `tendril render`; `None` when the backend has no such state.
    fn snapshot(&self) -> Option<crate::render::Snapshot> {
        None
    }

    /// The run's MuJoCo data, for a live viewer to show and perturb (`tendril view`); `None` when
    /// the backend has no MuJoCo state.
    fn mujoco_data_mut(
        &mut self,
    ) -> Option<&mut mujoco_rs::prelude::MjData<std::sync::Arc<mujoco_rs::prelude::MjModel>>> {
        None
    }

    /// Steps for `seconds` of simulated time (rounded to whole steps).
    fn run_for(&mut self, seconds: f64) -> Result<(), PhysicsError> {
        let n = (seconds / self.timestep()).round() as usize;
        for _ in 0..n {
            self.step()?;
        }
        Ok(())
    }
}

impl SceneModel {
    /// A fresh run on this model with the engine its spec names (`physics.backend`), at the start
    /// placement with the finger retracted and slack.
    pub fn start(self: &std::sync::Arc<Self>) -> Result<Box<dyn Physics>, PhysicsError> {
        Ok(match self.spec().physics.backend {
            Backend::Mujoco => Box::new(Scene::new(self.clone())),
            Backend::Rapier => Box::new(rapier::RapierScene::new(self.clone())?),
        })
    }
}

use crate::scenario::{Checker, Validate};

/// What a scene holds and how it is simulated.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneSpec {
    /// MuJoCo options, arm mode and divergence bounds.
    pub physics: PhysicsConfig,
    /// The finger's physical parameters.
    pub finger: FingerConfig,
    /// The object (and with it the table); `None` for a finger-only scene.
    pub object: Option<ObjectConfig>,
    /// Start joint angles of the arm \[rad\]. The object is placed where the grown finger wraps it in
    /// this pose (see [`compose::placement`]).
    pub arm_q0: [f64; 6],
}

impl Default for SceneSpec {
    fn default() -> Self {
        SceneSpec {
            physics: PhysicsConfig::default(),
            finger: FingerConfig::default(),
            object: Some(ObjectConfig::default()),
            arm_q0: ur5e::HOME,
        }
    }
}

impl Validate for SceneSpec {
    fn validate(&self, at: &mut Checker) {
        at.section("physics", &self.physics);
        at.section("finger", &self.finger);
        if let Some(o) = &self.object {
            at.section("object", o);
        }
        for (i, q) in self.arm_q0.iter().enumerate() {
            at.finite(&format!("arm_q0[{i}]"), *q);
        }
    }
}

/// Why the physics stopped or could not start.
#[derive(Debug, thiserror::Error)]
pub enum PhysicsError {
    /// A model template has a placeholder nobody filled (a bug between models/ and compose.rs).
    #[error("model template: placeholder {placeholder} has no value")]
    Template {
        /// The placeholder, e.g. `${k_bend}`.
        placeholder: String,
    },
    /// MuJoCo refused the assembled model.
    #[error("MuJoCo could not compile the scene: {message}")]
    Compile {
        /// MuJoCo's message.
        message: String,
    },
    /// The configuration is out of range.
    #[error("invalid scene configuration: key `{key}`: {reason}")]
    Config {
        /// Dotted key at fault.
        key: String,
        /// What is wrong.
        reason: String,
    },
    /// An actuator or arm input is not a finite number.
    #[error("input {what} is not finite: {value}")]
    BadInput {
        /// Which input.
        what: &'static str,
        /// The value given.
        value: f64,
    },
    /// A part of the scene (models/finger.xml, ...) could not be read from the models folder.
    #[error("{file}: cannot read this part of the scene: {cause}")]
    Part {
        /// The part's file.
        file: String,
        /// Why.
        cause: String,
    },
    /// An object's model file breaks the object contract (see [`object`]).
    #[error("object model {file}: {what}")]
    Object {
        /// The shipped object's name or the file.
        file: String,
        /// What is wrong or missing.
        what: String,
    },
    /// An element the scene needs is missing from the model (a bug between models/ and scene.rs).
    #[error("model has no {kind} named `{name}`")]
    Missing {
        /// Element kind.
        kind: &'static str,
        /// Its name.
        name: String,
    },
    /// The scene holds an element the backend cannot simulate (a model the rapier translation does
    /// not cover).
    #[error("the {backend} backend cannot simulate {what}")]
    Unsupported {
        /// The backend.
        backend: &'static str,
        /// The element and why.
        what: String,
    },
    /// The simulation diverged.
    #[error("simulation diverged at t = {time_s:.4} s: {cause}")]
    Diverged {
        /// Simulated time of the step that diverged \[s\].
        time_s: f64,
        /// What was detected.
        cause: Divergence,
    },
}

/// The symptom that stopped a diverging simulation.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Divergence {
    /// A state value became NaN or infinite.
    #[error("non-finite {what}")]
    NonFinite {
        /// Which state array.
        what: &'static str,
    },
    /// MuJoCo raised a warning (it resets the state on bad accelerations, which would hide the blow-up).
    #[error("MuJoCo warning: {warning}")]
    Warning {
        /// The warning's name.
        warning: &'static str,
    },
    /// A contact is deeper than `physics.max_penetration_m`.
    #[error("contact {depth_m:.4} m deep between `{geom1}` and `{geom2}`")]
    Penetration {
        /// Penetration depth \[m\].
        depth_m: f64,
        /// First geom.
        geom1: String,
        /// Second geom.
        geom2: String,
    },
    /// Kinetic energy beyond `physics.max_kinetic_energy_j`.
    #[error("kinetic energy {joules:.3e} J beyond the bound")]
    Energy {
        /// Kinetic energy \[J\].
        joules: f64,
    },
}
