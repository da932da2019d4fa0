//! A fresh run on a compiled scene model, with the engine its spec names.

use super::config::Backend;
use super::engine::Physics;
use super::error::PhysicsError;
use super::rapier::RapierScene;
use super::scene::{Scene, SceneModel};

impl SceneModel {
    /// A fresh run on this model with the engine its spec names (`physics.backend`), at the start
    /// placement with the finger retracted and slack.
    pub fn start(self: &std::sync::Arc<Self>) -> Result<Box<dyn Physics>, PhysicsError> {
        Ok(match self.spec().physics.backend {
            Backend::Mujoco => Box::new(Scene::new(self.clone())),
            Backend::Rapier => Box::new(RapierScene::new(self.clone())?),
        })
    }
}
