//! A rapier world built from a compiled MuJoCo model ([`super::translate`]), stepped like MuJoCo's
//! `MjData`: actuators and tendons as forces, rapier's step, then the divergence checks; and read
//! back by MuJoCo's ids (joint positions, body poses, contact forces between geoms).

use super::contacts::ContactRules;
use crate::physics::{Divergence, PhysicsError};
use rapier3d_f64::na::DVector;
use rapier3d_f64::prelude::*;

#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum JointKind {
    Hinge,
    Slide,
}

impl JointKind {
    pub(super) fn axis(self) -> JointAxis {
        match self {
            JointKind::Hinge => JointAxis::AngX,
            JointKind::Slide => JointAxis::LinX,
        }
    }

    /// Index of the joint's coordinate in rapier's spatial layout (linear 0..3, angular 3..6).
    pub(super) fn coord(self) -> usize {
        match self {
            JointKind::Hinge => 3,
            JointKind::Slide => 0,
        }
    }
}

/// A hinge or slide joint as a multibody link.
#[derive(Debug, Clone)]
pub(super) struct JointLink {
    pub(super) kind: JointKind,
    pub(super) handle: MultibodyJointHandle,
    pub(super) body: RigidBodyHandle,
    pub(super) parent: RigidBodyHandle,
    /// Joint axis in the child body's frame.
    pub(super) axis_local: Vector,
    /// Joint anchor in the child body's frame.
    pub(super) anchor_local: Vector,
    /// MuJoCo's `qpos0` for the joint: rapier's coordinate counts from there.
    pub(super) qpos0: f64,
    /// Passive stiffness and its rest position (rapier's coordinate).
    pub(super) stiffness: f64,
    pub(super) spring_rest: f64,
}

/// A fixed tendon: length = sum of coef x joint position.
#[derive(Debug, Clone)]
pub(super) struct FixedTendon {
    pub(super) terms: Vec<(usize, f64)>,
    pub(super) stiffness: f64,
    /// Spring dead band [lower, upper]: no force inside it.
    pub(super) dead_band: [f64; 2],
    pub(super) damping: f64,
}

#[derive(Debug, Clone, Copy)]
pub(super) enum ActuatorKind {
    /// Position servo: force = kp (ctrl - q) - kv qdot, as the joint's implicit spring and damping.
    Position { kp: f64, kv: f64 },
    /// Force actuator: generalized force = gain x ctrl.
    Motor { gain: f64 },
}

#[derive(Debug, Clone)]
pub(super) struct Actuator {
    pub(super) joint: usize,
    pub(super) kind: ActuatorKind,
    pub(super) ctrl_range: Option<[f64; 2]>,
    pub(super) force_max: f64,
}

/// A rapier world built from a MuJoCo model (one simulation run).
pub struct RapierWorld {
    pub(super) world: PhysicsWorld,
    pub(super) rules: ContactRules,
    /// Rapier body of each MuJoCo body (the world body included).
    pub(super) bodies: Vec<RigidBodyHandle>,
    /// Collider of each MuJoCo geom that collides with anything.
    pub(super) colliders: Vec<Option<ColliderHandle>>,
    /// Each MuJoCo joint: a multibody link, or `None` for a free joint.
    pub(super) joints: Vec<Option<JointLink>>,
    /// Bodies moved only by prescribed joints (left out of the kinetic energy).
    pub(super) driven: Vec<bool>,
    pub(super) tendons: Vec<FixedTendon>,
    pub(super) actuators: Vec<Actuator>,
    pub(super) ctrl: Vec<f64>,
    pub(super) geom_names: Vec<String>,
    pub(super) time_s: f64,
    /// Generalized force per joint for the step being prepared (kept to reuse its allocation).
    pub(super) generalized: Vec<f64>,
    pub(super) max_penetration_m: f64,
    pub(super) max_kinetic_energy_j: f64,
}

impl RapierWorld {
    /// Simulated time \[s\].
    pub fn time(&self) -> f64 {
        self.time_s
    }

    /// Step size \[s\].
    pub fn timestep(&self) -> f64 {
        self.world.integration_parameters.dt
    }

    /// Sets actuator `i`'s control (MuJoCo's `ctrl[i]`).
    pub fn set_ctrl(&mut self, i: usize, value: f64) {
        self.ctrl[i] = value;
    }

    /// Joint `j` as a multibody link (`None`: a free joint or no such joint).
    fn joint_link(&self, j: usize) -> Option<&JointLink> {
        self.joints.get(j)?.as_ref()
    }

    fn link(&self, j: usize) -> Option<(&JointLink, &Multibody, usize)> {
        let link = self.joint_link(j)?;
        let (mb, id) = self.world.multibody_joints.get(link.handle)?;
        Some((link, mb, id))
    }

    /// Position of hinge or slide joint `j` (MuJoCo's `qpos`) [rad or m]; 0 for other joints.
    pub fn joint_position(&self, j: usize) -> f64 {
        self.link(j)
            .and_then(|(link, mb, id)| Some(link.qpos0 + mb.link(id)?.joint.coords()[link.kind.coord()]))
            .unwrap_or(0.0)
    }

    /// Velocity of hinge or slide joint `j` [rad/s or m/s]; 0 for other joints.
    pub fn joint_velocity(&self, j: usize) -> f64 {
        self.link(j).and_then(|(_, mb, id)| Some(mb.joint_velocity(mb.link(id)?)[0])).unwrap_or(0.0)
    }

    /// Sets the velocity of prescribed joint `j` for the next step.
    pub fn set_joint_velocity(&mut self, j: usize, v: f64) {
        let Some(handle) = self.joint_link(j).map(|l| l.handle) else { return };
        if let Some((mb, id)) = self.world.multibody_joints.get_mut(handle)
            && let Some(a) = mb.link(id).map(|l| l.assembly_id())
        {
            mb.generalized_velocity_mut()[a] = v;
        }
    }

    /// Moves prescribed joint `j` to position `q` at once (start poses), with everything it carries.
    pub fn place_joint(&mut self, j: usize, q: f64) {
        let current = self.joint_position(j);
        let Some(handle) = self.joint_link(j).map(|l| l.handle) else { return };
        let bodies = &mut self.world.bodies;
        if let Some((mb, id)) = self.world.multibody_joints.get_mut(handle)
            && let Some(a) = mb.link(id).map(|l| l.assembly_id())
        {
            let mut disp = DVector::zeros(mb.ndofs());
            disp[a] = q - current;
            mb.apply_displacements(disp.as_slice());
            mb.forward_kinematics(bodies, false);
            mb.update_rigid_bodies(bodies, true);
        }
    }

    /// World pose of MuJoCo body `b`.
    pub fn body_pose(&self, b: usize) -> Pose {
        *self.world.bodies[self.bodies[b]].position()
    }

    /// Velocity of body `b`'s centre of mass \[m/s\] and its mass \[kg\].
    pub fn body_momentum(&self, b: usize) -> (Vector, f64) {
        let rb = &self.world.bodies[self.bodies[b]];
        (rb.linvel(), rb.mass())
    }

    /// Gravity \[m/s²\].
    pub fn gravity(&self) -> Vector {
        self.world.gravity
    }

    /// Velocity of the point `p` (world frame) attached to body `b` [m/s], and the body's angular
    /// velocity [rad/s].
    pub fn point_velocity(&self, b: usize, p: Vector) -> (Vector, Vector) {
        let rb = &self.world.bodies[self.bodies[b]];
        (rb.velocity_at_point(p), rb.angvel())
    }

    /// World position of geom `g`'s centre (geoms without a collider: their body's origin).
    pub fn geom_position(&self, g: usize) -> Option<Vector> {
        Some(self.world.colliders.get(self.colliders.get(g).copied()??)?.position().translation)
    }

    /// Normal force \[N\] summed over contacts between a geom in `a` and a geom in `b`, and the
    /// number of contact points carrying force.
    pub fn normal_force_between(&self, a: &[usize], b: &[usize]) -> (f64, usize) {
        let dt = self.timestep();
        let mut sum = 0.0;
        let mut n = 0;
        for &ga in a {
            for &gb in b {
                let (Some(Some(ca)), Some(Some(cb))) = (self.colliders.get(ga), self.colliders.get(gb)) else {
                    continue;
                };
                let Some(pair) = self.world.narrow_phase.contact_pair(*ca, *cb) else { continue };
                for manifold in pair.solver_manifolds() {
                    for point in &manifold.points {
                        if point.data.impulse > 0.0 {
                            sum += point.data.impulse / dt;
                            n += 1;
                        }
                    }
                }
            }
        }
        (sum, n)
    }

    /// Tension of tendon `t` \[N\]: MuJoCo's tendon force, positive when the tendon is shorter than
    /// its dead band (wound in) and pulls.
    pub fn tendon_tension(&self, t: usize) -> f64 {
        self.tendon_force(&self.tendons[t])
    }

    fn tendon_force(&self, t: &FixedTendon) -> f64 {
        let (mut length, mut rate) = (0.0, 0.0);
        for &(j, coef) in &t.terms {
            length += coef * self.joint_position(j);
            rate += coef * self.joint_velocity(j);
        }
        let [lo, hi] = t.dead_band;
        let stretch = if length < lo {
            length - lo
        } else if length > hi {
            length - hi
        } else {
            0.0
        };
        -t.stiffness * stretch - t.damping * rate
    }

    /// Advances one step: actuators and tendons, then rapier's step, then the divergence checks.
    pub fn step(&mut self) -> Result<(), PhysicsError> {
        let mut generalized = std::mem::take(&mut self.generalized);
        generalized.clear();
        generalized.resize(self.joints.len(), 0.0);
        for t in &self.tendons {
            let f = self.tendon_force(t);
            for &(j, coef) in &t.terms {
                generalized[j] += coef * f;
            }
        }
        for i in 0..self.actuators.len() {
            let a = &self.actuators[i];
            let ctrl = match a.ctrl_range {
                Some([lo, hi]) => self.ctrl[i].clamp(lo, hi),
                None => self.ctrl[i],
            };
            match a.kind {
                ActuatorKind::Motor { gain } => generalized[a.joint] += (gain * ctrl).clamp(-a.force_max, a.force_max),
                ActuatorKind::Position { kp, .. } => {
                    let (joint, force_max) = (a.joint, a.force_max);
                    self.set_servo(joint, ctrl, kp, force_max)
                }
            }
        }
        for &handle in &self.bodies {
            if let Some(rb) = self.world.bodies.get_mut(handle)
                && rb.is_dynamic()
            {
                rb.reset_forces(false);
                rb.reset_torques(false);
            }
        }
        for (j, f) in generalized.iter().enumerate() {
            if *f != 0.0 {
                self.apply_generalized(j, *f);
            }
        }
        self.generalized = generalized;
        self.world.step_with_events(&self.rules, &());
        self.time_s += self.timestep();
        self.check()
    }

    /// Points joint `j`'s implicit spring at the servo's `target` (its stiffness `kp` added to the
    /// joint's own); a target further than `force_max / kp` away is brought within it, so the
    /// servo pushes with at most `force_max`.
    fn set_servo(&mut self, j: usize, target: f64, kp: f64, force_max: f64) {
        let q = self.joint_position(j);
        let Some(link) = self.joint_link(j) else { return };
        let reach = force_max / kp;
        let target = target.clamp(q - reach, q + reach) - link.qpos0;
        let k = link.stiffness + kp;
        let rest = (link.stiffness * link.spring_rest + kp * target) / k;
        let coord = link.kind.coord();
        if let Some((mb, id)) = self.world.multibody_joints.get_mut(link.handle)
            && let Some(l) = mb.link_mut(id)
        {
            l.joint.set_spring(coord, k, rest);
        }
    }

    /// Applies generalized force `f` on joint `j` as a wrench pair: on the child body and, opposite,
    /// on the parent at the same point, so no other joint feels it.
    fn apply_generalized(&mut self, j: usize, f: f64) {
        // `joint_link` written out: it would borrow all of `self`, and the bodies are changed below.
        let Some(link) = self.joints.get(j).and_then(Option::as_ref) else { return };
        let child = *self.world.bodies[link.body].position();
        let axis = child.rotation * link.axis_local;
        let anchor = child * link.anchor_local;
        for (body, sign) in [(link.body, 1.0), (link.parent, -1.0)] {
            if let Some(rb) = self.world.bodies.get_mut(body)
                && rb.is_dynamic()
            {
                match link.kind {
                    JointKind::Hinge => rb.add_torque(axis * (sign * f), false),
                    JointKind::Slide => rb.add_force_at_point(axis * (sign * f), anchor, false),
                }
            }
        }
    }

    fn check(&self) -> Result<(), PhysicsError> {
        let time_s = self.time_s;
        let diverged = |cause| Err(PhysicsError::Diverged { time_s, cause });
        let mut kinetic = 0.0;
        for (b, handle) in self.bodies.iter().enumerate() {
            let rb = &self.world.bodies[*handle];
            if !rb.translation().is_finite() || !rb.linvel().is_finite() || !rb.angvel().is_finite() {
                return diverged(Divergence::NonFinite { what: "body pose or velocity" });
            }
            if rb.is_dynamic() && !self.driven[b] {
                kinetic += rb.kinetic_energy();
            }
        }
        for pair in self.world.narrow_phase.contact_pairs() {
            for manifold in pair.manifolds() {
                for point in &manifold.points {
                    if point.dist < -self.max_penetration_m {
                        let geom = |c: ColliderHandle| {
                            let g = self.world.colliders.get(c).map_or(usize::MAX, |c| c.user_data as usize);
                            self.geom_names.get(g).cloned().unwrap_or_else(|| "?".into())
                        };
                        return diverged(Divergence::Penetration {
                            depth_m: -point.dist,
                            geom1: geom(pair.collider1),
                            geom2: geom(pair.collider2),
                        });
                    }
                }
            }
        }
        if !kinetic.is_finite() || kinetic > self.max_kinetic_energy_j {
            return diverged(Divergence::Energy { joules: kinetic });
        }
        Ok(())
    }
}
