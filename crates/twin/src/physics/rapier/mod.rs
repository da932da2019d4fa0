//! The second physics backend: rapier3d (f64), built from the same compiled MuJoCo model.
//!
//! One source of truth for the scene: models/ is assembled and compiled by MuJoCo
//! ([`super::SceneModel`]), and [`RapierWorld::build`] translates the compiled model (bodies,
//! joints, geoms, masses, inertias, friction, tendons, actuators) into a rapier world. Nothing
//! about the cell is described twice.
//!
//! Settings (`[physics.rapier]`, [`super::RapierConfig`]) follow what was measured for rapier 0.36
//! on this kind of machine (docs/facts.md#rapier-multibody-chain): the finger is a reduced-coordinate
//! multibody (impulse joints let a 12-link chain drift and drop the object), f64 throughout.
//!
//! - [`translate`]: the compiled MuJoCo model -> a rapier world ([`RapierWorld::build`]).
//! - [`world`]: stepping it and reading it back by MuJoCo ids ([`RapierWorld`]).
//! - [`contacts`]: MuJoCo's collision filter and friction mix as rapier hooks.
//! - [`scene`]: the cell's run on it ([`RapierScene`]).

pub mod contacts;
pub mod scene;
pub mod translate;
pub mod world;

pub use scene::RapierScene;
pub use world::RapierWorld;
