//! [`SceneSpec`]: what a scene holds and how it is simulated.

use super::config::{FingerConfig, ObjectConfig, PhysicsConfig};
use super::produce_config::ProduceConfig;
use tendril_config::{Checker, Validate};
use tendril_ur5e::kinematics as ur5e;

/// Where a further sensor pad sits on the strip.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PadPlace {
    /// Its centre's distance from the strip's base \[m of arc\].
    pub arc_m: f64,
    /// Height of its bump's tip above the strip's inner face \[m\] (as `finger.pad_protrusion_m`).
    pub protrusion_m: f64,
}

impl PadPlace {
    /// The arcs of `pads` \[m\].
    pub fn arcs(pads: &[PadPlace]) -> Vec<f64> {
        pads.iter().map(|p| p.arc_m).collect()
    }
}

/// What a scene holds and how it is simulated.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneSpec {
    /// MuJoCo options, arm mode and divergence bounds.
    pub physics: PhysicsConfig,
    /// The finger's physical parameters.
    pub finger: FingerConfig,
    /// The object (and with it the table); `None` for a finger-only scene.
    pub object: Option<ObjectConfig>,
    /// Further sensor pads along the strip (a sensor array, `[array]`); empty: the paper's
    /// single pad at `finger.pad_position_m`. Each is a pad like pad 0, named `pad{k}_casing`,
    /// `pad{k}_bump`, `pad{k}_site` (k = 1, 2, ...).
    pub extra_pads: Vec<PadPlace>,
    /// Start joint angles of the arm \[rad\]. The object is placed where the grown finger wraps it in
    /// this pose (see [`super::compose::placement`]).
    pub arm_q0: [f64; 6],
    /// A produce item's overrides, its harvest and its flex's numerics (`[produce]`; read only when
    /// the object is a produce item, [`super::produce`]).
    pub produce: ProduceConfig,
}

impl Default for SceneSpec {
    fn default() -> Self {
        SceneSpec {
            physics: PhysicsConfig::default(),
            finger: FingerConfig::default(),
            object: Some(ObjectConfig::default()),
            extra_pads: Vec::new(),
            arm_q0: ur5e::HOME,
            produce: ProduceConfig::default(),
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
        at.section("produce", &self.produce);
        for (i, q) in self.arm_q0.iter().enumerate() {
            at.finite(&format!("arm_q0[{i}]"), *q);
        }
    }
}
