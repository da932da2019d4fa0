//! The MuJoCo physics of the cell: UR5e, grow-and-twine finger with the FBG sensor pad, one of the
//! paper's objects and the table, assembled from models/ for what a scenario needs.
//!
//! - [`config`]: the `[physics]`, `[finger]` and `[object]` scenario sections.
//! - [`compose`]: MJCF assembly from the model files.
//! - [`scene`]: [`Scene`] (one simulation run: step, actuator inputs, [`PhysicsReadout`]) on a shared
//!   [`SceneModel`].
//! - [`ur5e`]: DH kinematics.

pub mod check;
pub mod compose;
pub mod config;
pub mod scene;
pub mod template;
pub mod ur5e;
pub mod validation;

pub use compose::Placement;
pub use config::{ArmMode, Cone, FingerConfig, Integrator, ObjectConfig, ObjectName, PhysicsConfig};
pub use scene::{PhysicsReadout, Scene, SceneModel};

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
    /// Start joint angles of the arm [rad]. The object is placed where the grown finger wraps it in
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
    /// An element the scene needs is missing from the model (a bug between models/ and scene.rs).
    #[error("model has no {kind} named `{name}`")]
    Missing {
        /// Element kind.
        kind: &'static str,
        /// Its name.
        name: String,
    },
    /// The simulation diverged.
    #[error("simulation diverged at t = {time_s:.4} s: {cause}")]
    Diverged {
        /// Simulated time of the step that diverged [s].
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
        /// Penetration depth [m].
        depth_m: f64,
        /// First geom.
        geom1: String,
        /// Second geom.
        geom2: String,
    },
    /// Kinetic energy beyond `physics.max_kinetic_energy_j`.
    #[error("kinetic energy {joules:.3e} J beyond the bound")]
    Energy {
        /// Kinetic energy [J].
        joules: f64,
    },
}
