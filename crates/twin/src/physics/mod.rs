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
//! - [`guide`]: the guide's walls left out of the collision search while they cannot touch the
//!   strip; [`census`]: contacts per geom pair over a run (what the collision search finds).
//! - [`export`]: the scene as one standalone MJCF with a start keyframe (`tendril scene`).
//! - [`follow_camera`]: the `follow` camera that turns with the arm's base and aims at the object (for viewers and pictures).
//! - [`object`]: an object's model file, its contract checked, its mass and grip read from it.
//! - [`produce`]: a produce item's model file (a flex), [`plates`] its compression between two
//!   plates and the calibration against [`hertz`], [`bump`] the sensor pad's bump's own contact
//!   with it, [`damage`] the contact pressure on it.
//! - `spec.rs`: what a scene holds ([`SceneSpec`]); `engine.rs`: the [`Physics`] trait; `readout.rs`:
//!   what a run hands out ([`PhysicsReadout`], [`Snapshot`]); `start.rs`: a run on a model
//!   ([`SceneModel::start`]).

pub mod bump;
pub mod census;
pub mod check;
pub mod compose;
pub mod config;
pub mod damage;
pub mod drive;
mod engine;
mod error;
pub mod export;
pub mod follow_camera;
pub mod guide;
mod header;
pub mod hertz;
pub mod object;
pub mod plates;
pub mod produce;
pub mod produce_config;
mod produce_run;
pub mod rapier;
mod readout;
pub mod scene;
mod spec;
mod start;
pub mod strip;
pub mod template;
pub mod validation;

pub use census::{ContactCensus, PairTally};
pub use compose::Placement;
pub use config::{
    ArmMode, Backend, BaseJoint, Cone, FingerConfig, Integrator, ObjectConfig, ObjectName, PhysicsConfig, RapierConfig,
    Solver,
};
pub use engine::Physics;
pub use error::{Divergence, PhysicsError};
pub use produce::ProduceItem;
pub use produce_config::{Dof, ProduceConfig};
pub use readout::{PhysicsReadout, Snapshot};
pub use scene::{Scene, SceneModel};
pub use spec::{PadPlace, SceneSpec};
