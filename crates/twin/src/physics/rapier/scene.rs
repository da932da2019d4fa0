//! The cell's run on rapier: the same [`SceneModel`] as MuJoCo's, stepped by a [`RapierWorld`]
//! built from its compiled model.

use super::world::RapierWorld;
use crate::physics::config::Backend;
use crate::physics::drive::{Drive, grip_in_hand};
use crate::physics::{Physics, PhysicsError, PhysicsReadout, SceneModel, Snapshot};
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};
use rapier3d_f64::prelude::{Pose, Vector};
use std::sync::Arc;
use tendril_fbg::array::PerPad;

/// One rapier simulation run on a shared [`SceneModel`]. Deterministic: the same inputs give the
/// same trajectory (rapier is single-threaded here).
pub struct RapierScene {
    shared: Arc<SceneModel>,
    world: RapierWorld,
    drive: Drive,
    /// Every geom that can touch the object and is neither the object's nor carried by the arm:
    /// the table.
    support_geoms: Vec<usize>,
    /// The object's vertical velocity before the last step \[m/s\], for the load over that step
    /// (`None` before the first step or without an object).
    object_vz_before_m_s: Option<f64>,
}

fn to_na(v: Vector) -> Vector3<f64> {
    Vector3::new(v.x, v.y, v.z)
}

fn isometry(p: &Pose) -> Isometry3<f64> {
    let q = p.rotation;
    Isometry3::from_parts(
        Translation3::new(p.translation.x, p.translation.y, p.translation.z),
        UnitQuaternion::from_quaternion(Quaternion::new(q.w, q.x, q.y, q.z)),
    )
}

impl RapierScene {
    /// A fresh run on `shared` at the start placement, the finger retracted and slack.
    pub fn new(shared: Arc<SceneModel>) -> Result<RapierScene, PhysicsError> {
        let ids = shared.ids();
        let mut world = RapierWorld::build(shared.model(), &shared.spec().physics, &ids.arm_joint)?;
        let q0 = shared.spec().arm_q0;
        for (j, q) in ids.arm_joint.iter().zip(q0) {
            world.place_joint(*j, q);
        }
        let drive = Drive::new(&shared.spec().physics, &shared.spec().finger, q0);
        let ngeom = shared.model().ffi().ngeom as usize;
        let support_geoms =
            (0..ngeom).filter(|g| !ids.hand_geoms.contains(g) && !ids.object_geoms.contains(g)).collect();
        Ok(RapierScene { shared, world, drive, support_geoms, object_vz_before_m_s: None })
    }

    /// The rapier world (read-only), for checks beyond the readout.
    pub fn world(&self) -> &RapierWorld {
        &self.world
    }

    /// The upward force the arm's geoms exerted on the object over the last step \[N\], from its
    /// momentum: m Δv_z / dt = F_arm + F_support + m g_z (`None` before the first step or without
    /// an object). Rapier's contact solve gives impulses whose friction directions are internal to
    /// its solver, so the force is read from what it did to the object instead; the support (the
    /// table) is taken as horizontal, its contacts' force vertical.
    fn load_on_object(&self) -> Option<f64> {
        let (vz_before, b) = (self.object_vz_before_m_s?, self.shared.ids().object_body?);
        let (v, mass) = self.world.body_momentum(b);
        let (support_n, _) = self.world.normal_force_between(&self.support_geoms, &self.shared.ids().object_geoms);
        let dv_dt = (v.z - vz_before) / self.world.timestep();
        Some(mass * (dv_dt - self.world.gravity().z) - support_n)
    }
}

impl Physics for RapierScene {
    fn backend(&self) -> Backend {
        Backend::Rapier
    }

    fn time(&self) -> f64 {
        self.world.time()
    }

    fn timestep(&self) -> f64 {
        self.world.timestep()
    }

    /// Rapier's state in MuJoCo's layout: hinge and slide joints from the multibody, a free joint
    /// from its body's pose (velocity 0: only drawn contact forces use it), controls as commanded,
    /// activations 0.
    fn snapshot(&self) -> Option<Snapshot> {
        use mujoco_rs::mujoco_c::mjtJoint;
        let m = self.shared.model();
        let mut qpos = m.qpos0().to_vec();
        let mut qvel = vec![0.0; m.ffi().nv as usize];
        for j in 0..m.ffi().njnt as usize {
            let (adr, dof) = (m.jnt_qposadr()[j] as usize, m.jnt_dofadr()[j] as usize);
            match m.jnt_type()[j] {
                mjtJoint::mjJNT_HINGE | mjtJoint::mjJNT_SLIDE => {
                    qpos[adr] = self.world.joint_position(j);
                    qvel[dof] = self.world.joint_velocity(j);
                }
                mjtJoint::mjJNT_FREE => {
                    let p = self.world.body_pose(m.jnt_bodyid()[j] as usize);
                    let (t, q) = (p.translation, p.rotation);
                    qpos[adr..adr + 7].copy_from_slice(&[t.x, t.y, t.z, q.w, q.x, q.y, q.z]);
                }
                _ => {}
            }
        }
        Some(Snapshot { qpos, qvel, ctrl: self.world.ctrl.clone(), act: vec![0.0; m.ffi().na as usize] })
    }

    fn set_growth(&mut self, growth_m: f64) -> Result<(), PhysicsError> {
        self.drive.set_growth(growth_m)
    }

    fn set_twine(&mut self, twine_m: f64) -> Result<(), PhysicsError> {
        self.drive.set_twine(twine_m)
    }

    fn set_arm_target(&mut self, q: [f64; 6]) -> Result<(), PhysicsError> {
        self.drive.set_arm_target(q, self.world.time())
    }

    fn step(&mut self) -> Result<(), PhysicsError> {
        let ids = self.shared.ids();
        let dt = self.world.timestep();
        let set = self.drive.advance(self.world.time(), dt);
        self.world.set_ctrl(ids.growth_act, set.motors[0]);
        self.world.set_ctrl(ids.twine_act, set.motors[1]);
        // Prescribed arm: the velocity that takes each joint to its next angle in this step.
        for (k, j) in ids.arm_joint.iter().enumerate() {
            let v = (set.arm_q[k] - self.world.joint_position(*j)) / dt;
            self.world.set_joint_velocity(*j, v);
        }
        self.object_vz_before_m_s = ids.object_body.map(|b| self.world.body_momentum(b).0.z);
        self.world.step()
    }

    fn readout(&self) -> PhysicsReadout {
        let ids = self.shared.ids();
        let w = &self.world;
        let (pad_force_n, _) = w.normal_force_between(&ids.pad_geoms, &ids.object_geoms);
        let mut extra_pad_forces_n = PerPad::filled(ids.extra_pad_geoms.len(), 0.0);
        for (f, geoms) in extra_pad_forces_n.as_mut_slice().iter_mut().zip(&ids.extra_pad_geoms) {
            *f = w.normal_force_between(geoms, &ids.object_geoms).0;
        }
        let (grip_force_n, grip_contacts) = w.normal_force_between(&ids.finger_geoms, &ids.object_geoms);
        let (palm_force_n, _) = w.normal_force_between(&ids.palm_geom, &ids.object_geoms);
        let hand_pose = w.body_pose(ids.hand_body);
        let hand = isometry(&hand_pose);
        let mut r = PhysicsReadout {
            time_s: w.time(),
            pad_force_n,
            extra_pad_forces_n,
            grip_force_n,
            palm_force_n,
            grip_contacts,
            touching: grip_contacts > 0,
            hand_pos_m: hand.translation.vector.into(),
            growth_m: w.joint_position(ids.growth_joint),
            twine_m: w.joint_position(ids.twine_joint),
            twine_setpoint_m: self.drive.twine_setpoint_m(),
            creep_m: w.joint_position(ids.creep_joint),
            tendon_tension_n: w.tendon_tension(ids.tendon_elastic).max(0.0)
                + w.tendon_tension(ids.tendon_maxwell).max(0.0),
            arm_q: ids.arm_joint.map(|j| w.joint_position(j)),
            tool_load_n: Some(self.load_on_object().unwrap_or(0.0)),
            ..PhysicsReadout::default()
        };
        if let (Some(body), Some(grip)) = (ids.object_body, ids.object_grip) {
            let object = isometry(&w.body_pose(body));
            r.object_pos_m = object.translation.vector.into();
            let q = object.rotation.quaternion();
            r.object_quat = [q.w, q.i, q.j, q.k];
            let p = w.geom_position(grip).unwrap_or(Vector::ZERO);
            let (v_grip, _) = w.point_velocity(body, p);
            let (v_hand, w_hand) = w.point_velocity(ids.hand_body, hand_pose.translation);
            let in_hand = grip_in_hand(&hand, to_na(v_hand), to_na(w_hand), to_na(p), to_na(v_grip));
            r.object_vel_m_s = to_na(v_grip).into();
            r.slip_speed_m_s = in_hand.slip_speed_m_s;
            r.object_in_hand_m = in_hand.position_m;
        }
        r
    }
}
