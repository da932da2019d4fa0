//! [`Physics`]: one simulation run of the cell, whichever engine steps it.

use super::config::Backend;
use super::error::PhysicsError;
use super::readout::{PhysicsReadout, Snapshot};

/// One simulation run of the cell, whichever engine steps it. The cell ([`crate::sim`]) only
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
    /// [`super::SceneModel`]), recorded for `tendril render`; `None` when the backend has no such state.
    fn snapshot(&self) -> Option<Snapshot> {
        None
    }

    /// The run's MuJoCo data, for a live viewer to show and perturb (`tendril view`); `None` when
    /// the backend has no MuJoCo state.
    fn mujoco_data_mut(
        &mut self,
    ) -> Option<&mut mujoco_rs::prelude::MjData<std::sync::Arc<mujoco_rs::prelude::MjModel>>> {
        None
    }

    /// Counts, from the next step on, the contacts of each geom pair ([`super::ContactCensus`]);
    /// a backend without MuJoCo's contacts counts nothing.
    fn count_contacts(&mut self) {}

    /// The contacts counted so far, if [`Physics::count_contacts`] was asked for and the backend
    /// counts them.
    fn contact_census(&self) -> Option<super::ContactCensus> {
        None
    }

    /// The area of the finger's faces that touch the object now \[m²\] (see
    /// [`super::Scene::contact_area_m2`]); `None` when the backend does not report its contacts.
    fn contact_area_m2(&self) -> Option<f64> {
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
