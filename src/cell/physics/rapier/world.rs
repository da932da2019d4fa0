//! A rapier world built from a compiled MuJoCo model, and stepped like MuJoCo's `MjData`.
//!
//! Translation (MuJoCo element -> rapier):
//! - body with a hinge or slide joint -> link of a reduced-coordinate multibody (revolute or
//!   prismatic about the joint's axis through its anchor), with the joint's stiffness (implicit
//!   spring about `qpos_spring`), damping, armature, friction loss and range; MuJoCo's ordering
//!   puts parents first, so every chain becomes one multibody rooted at a fixed body;
//! - body without joints -> welded to its parent (a fixed multibody joint), or fixed when the
//!   parent is fixed; body with a free joint -> free rigid body at its `qpos0`;
//! - mass, centre of mass, principal inertia and its frame from the compiled model (geoms carry
//!   no density); `gravcomp` -> gravity scale;
//! - box, sphere, capsule, cylinder and plane geoms that collide with anything -> colliders,
//!   filtered and given friction by MuJoCo's rules ([`ContactRules`]);
//! - fixed tendons (joint wraps) with stiffness, dead band and damping -> generalized forces,
//!   explicit, applied as equal and opposite wrenches on the joint's two bodies;
//! - `position` actuators on joints -> the joint's implicit spring pulled towards the control
//!   (kp) plus implicit damping (kv), the control clamped to its range and the servo force to its
//!   force range; `motor` actuators -> generalized forces.
//!
//! Joints named as prescribed become kinematic multibody joints whose velocity the caller sets
//! each step (the kinematic arm). rapier 0.36 panics (an LU size mismatch) when a multibody with
//! kinematic joints also has joint motors or limits, so servos are springs (above) and joints
//! carried by a prescribed joint keep no range: the finger's servos and its bending springs keep
//! them far inside it (the curl range is 2 rad per joint; a wrap needs about 1.4). Anything else
//! (ball joints, several joints in one body, meshes, other actuators or tendons) is refused with
//! [`PhysicsError::Unsupported`].

use super::contacts::ContactRules;
use crate::cell::physics::config::{PhysicsConfig, RapierFriction};
use crate::cell::physics::{Divergence, PhysicsError};
use mujoco_rs::mujoco_c::{_mjtGeomBase, _mjtObjBase, mjtBias, mjtGain, mjtJoint, mjtTrn, mjtWrap};
use mujoco_rs::prelude::MjModel;
use rapier3d_f64::na::{DVector, Unit};
use rapier3d_f64::prelude::*;

/// A MuJoCo vector as rapier's.
pub fn vec3(a: [f64; 3]) -> Vector {
    Vector::new(a[0], a[1], a[2])
}

/// A MuJoCo quaternion (w, x, y, z) as rapier's rotation.
pub fn rot3(q: [f64; 4]) -> Rotation {
    Rotation::from_xyzw(q[1], q[2], q[3], q[0]).normalize()
}

fn pose(p: [f64; 3], q: [f64; 4]) -> Pose {
    Pose::from_parts(vec3(p), rot3(q))
}

/// A rotation taking the x axis onto `axis` (rapier's joints move along or about their frames' x).
fn x_onto(axis: Vector) -> Rotation {
    Rotation::from_rotation_arc(Vector::X, axis.normalize())
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum JointKind {
    Hinge,
    Slide,
}

impl JointKind {
    fn axis(self) -> JointAxis {
        match self {
            JointKind::Hinge => JointAxis::AngX,
            JointKind::Slide => JointAxis::LinX,
        }
    }

    /// Index of the joint's coordinate in rapier's spatial layout (linear 0..3, angular 3..6).
    fn coord(self) -> usize {
        match self {
            JointKind::Hinge => 3,
            JointKind::Slide => 0,
        }
    }
}

/// A hinge or slide joint as a multibody link.
#[derive(Debug, Clone)]
struct JointLink {
    kind: JointKind,
    handle: MultibodyJointHandle,
    body: RigidBodyHandle,
    parent: RigidBodyHandle,
    /// Joint axis in the child body's frame.
    axis_local: Vector,
    /// Joint anchor in the child body's frame.
    anchor_local: Vector,
    /// MuJoCo's `qpos0` for the joint: rapier's coordinate counts from there.
    qpos0: f64,
    /// Passive stiffness and its rest position (rapier's coordinate).
    stiffness: f64,
    spring_rest: f64,
}

/// A fixed tendon: length = sum of coef x joint position.
#[derive(Debug, Clone)]
struct FixedTendon {
    terms: Vec<(usize, f64)>,
    stiffness: f64,
    /// Spring dead band [lower, upper]: no force inside it.
    dead_band: [f64; 2],
    damping: f64,
}

#[derive(Debug, Clone, Copy)]
enum ActuatorKind {
    /// Position servo: force = kp (ctrl - q) - kv qdot, as a joint motor.
    Position { kp: f64, kv: f64 },
    /// Force actuator: generalized force = gain x ctrl.
    Motor { gain: f64 },
}

#[derive(Debug, Clone)]
struct Actuator {
    joint: usize,
    kind: ActuatorKind,
    ctrl_range: Option<[f64; 2]>,
    force_max: f64,
}

/// A rapier world built from a MuJoCo model (one simulation run).
pub struct RapierWorld {
    world: PhysicsWorld,
    rules: ContactRules,
    /// Rapier body of each MuJoCo body (the world body included).
    bodies: Vec<RigidBodyHandle>,
    /// Collider of each MuJoCo geom that collides with anything.
    colliders: Vec<Option<ColliderHandle>>,
    /// Each MuJoCo joint: a multibody link, or `None` for a free joint.
    joints: Vec<Option<JointLink>>,
    /// Bodies moved only by prescribed joints (left out of the kinetic energy).
    driven: Vec<bool>,
    tendons: Vec<FixedTendon>,
    actuators: Vec<Actuator>,
    ctrl: Vec<f64>,
    geom_names: Vec<String>,
    time_s: f64,
    max_penetration_m: f64,
    max_kinetic_energy_j: f64,
}

fn unsupported(what: String) -> PhysicsError {
    PhysicsError::Unsupported { backend: "rapier", what }
}

impl RapierWorld {
    /// Builds the world for model `m` with the options of `physics`. Joints listed in `prescribed`
    /// are kinematic: they move only as [`RapierWorld::set_joint_velocity`] says.
    pub fn build(m: &MjModel, physics: &PhysicsConfig, prescribed: &[usize]) -> Result<RapierWorld, PhysicsError> {
        let nbody = m.ffi().nbody as usize;
        let njnt = m.ffi().njnt as usize;
        let ngeom = m.ffi().ngeom as usize;
        let name = |kind, id| m.id_to_name(kind, id).unwrap_or("?").to_string();
        let mut world = PhysicsWorld::new();
        world.gravity = vec3(m.opt().gravity);
        set_parameters(&mut world.integration_parameters, physics);

        // Bodies, in MuJoCo's order (parents first), with their world poses at qpos0.
        let mut bodies = Vec::with_capacity(nbody);
        let mut world_pose = Vec::with_capacity(nbody);
        let mut fixed = vec![false; nbody];
        let mut driven = vec![false; nbody];
        // Moved by a prescribed joint somewhere up the chain.
        let mut carried = vec![false; nbody];
        let mut joints: Vec<Option<JointLink>> = vec![None; njnt];
        bodies.push(world.insert_body(RigidBodyBuilder::fixed()));
        world_pose.push(Pose::IDENTITY);
        fixed[0] = true;
        for b in 1..nbody {
            let parent = m.body_parentid()[b] as usize;
            let relative = pose(m.body_pos()[b], m.body_quat()[b]);
            let here = world_pose[parent] * relative;
            let mass = MassProperties::with_principal_inertia_frame(
                vec3(m.body_ipos()[b]),
                m.body_mass()[b],
                vec3(m.body_inertia()[b]),
                rot3(m.body_iquat()[b]),
            );
            let dynamic = || {
                RigidBodyBuilder::dynamic()
                    .pose(here)
                    .additional_mass_properties(mass)
                    .gravity_scale(1.0 - m.body_gravcomp()[b])
                    .can_sleep(false)
            };
            let njoints = m.body_jntnum()[b];
            if njoints > 1 {
                return Err(unsupported(format!("body `{}` has {njoints} joints", name(_mjtObjBase::mjOBJ_BODY, b))));
            }
            if njoints == 0 {
                if fixed[parent] {
                    bodies.push(world.insert_body(RigidBodyBuilder::fixed().pose(here)));
                    fixed[b] = true;
                } else {
                    let handle = world.insert_body(dynamic());
                    let weld = GenericJointBuilder::new(JointAxesMask::LOCKED_FIXED_AXES)
                        .local_frame1(relative)
                        .contacts_enabled(true)
                        .build();
                    world.multibody_joints.insert(bodies[parent], handle, weld, true);
                    bodies.push(handle);
                    driven[b] = driven[parent];
                    carried[b] = carried[parent];
                }
                world_pose.push(here);
                continue;
            }
            let j = m.body_jntadr()[b] as usize;
            let qadr = m.jnt_qposadr()[j] as usize;
            match m.jnt_type()[j] {
                mjtJoint::mjJNT_FREE => {
                    if parent != 0 {
                        return Err(unsupported(format!(
                            "free joint `{}` below another body",
                            name(_mjtObjBase::mjOBJ_JOINT, j)
                        )));
                    }
                    let q = &m.qpos0()[qadr..qadr + 7];
                    let start = pose([q[0], q[1], q[2]], [q[3], q[4], q[5], q[6]]);
                    bodies.push(world.insert_body(dynamic().pose(start)));
                    world_pose.push(start);
                }
                kind @ (mjtJoint::mjJNT_HINGE | mjtJoint::mjJNT_SLIDE) => {
                    let kind = if kind == mjtJoint::mjJNT_HINGE { JointKind::Hinge } else { JointKind::Slide };
                    let axis_local = vec3(m.jnt_axis()[j]);
                    let anchor_local = vec3(m.jnt_pos()[j]);
                    let qpos0 = m.qpos0()[qadr];
                    if qpos0 != 0.0 {
                        return Err(unsupported(format!(
                            "joint `{}` with a non-zero reference (ref)",
                            name(_mjtObjBase::mjOBJ_JOINT, j)
                        )));
                    }
                    let frame2 = Pose::from_parts(anchor_local, x_onto(axis_local));
                    let mut joint = GenericJointBuilder::new(match kind {
                        JointKind::Hinge => JointAxesMask::LOCKED_REVOLUTE_AXES,
                        JointKind::Slide => JointAxesMask::LOCKED_PRISMATIC_AXES,
                    })
                    .local_frame1(relative * frame2)
                    .local_frame2(frame2)
                    .contacts_enabled(true);
                    if m.jnt_limited()[j] && !carried[parent] && !prescribed.contains(&j) {
                        joint = joint.limits(kind.axis(), m.jnt_range()[j]);
                    }
                    let handle = world.insert_body(dynamic());
                    let kinematic = prescribed.contains(&j);
                    carried[b] = kinematic || carried[parent];
                    let inserted = if kinematic {
                        world.multibody_joints.insert_kinematic(bodies[parent], handle, joint.build(), true)
                    } else {
                        world.multibody_joints.insert(bodies[parent], handle, joint.build(), true)
                    };
                    let Some(joint_handle) = inserted else {
                        return Err(unsupported(format!(
                            "joint `{}` closes a loop",
                            name(_mjtObjBase::mjOBJ_JOINT, j)
                        )));
                    };
                    joints[j] = Some(JointLink {
                        kind,
                        handle: joint_handle,
                        body: handle,
                        parent: bodies[parent],
                        axis_local,
                        anchor_local,
                        qpos0,
                        stiffness: m.jnt_stiffness()[j],
                        spring_rest: m.qpos_spring()[qadr] - qpos0,
                    });
                    driven[b] = kinematic && (fixed[parent] || driven[parent]);
                    bodies.push(handle);
                    world_pose.push(here);
                }
                other => {
                    return Err(unsupported(format!("{other:?} joint `{}`", name(_mjtObjBase::mjOBJ_JOINT, j))));
                }
            }
        }

        let mut rapier = RapierWorld {
            world,
            rules: ContactRules::from_model(m),
            bodies,
            colliders: vec![None; ngeom],
            joints,
            driven,
            tendons: Vec::new(),
            actuators: Vec::new(),
            ctrl: vec![0.0; m.ffi().nu as usize],
            geom_names: (0..ngeom).map(|g| name(_mjtObjBase::mjOBJ_GEOM, g)).collect(),
            time_s: 0.0,
            max_penetration_m: physics.max_penetration_m,
            max_kinetic_energy_j: physics.max_kinetic_energy_j,
        };
        rapier.tendons = tendons(m)?;
        rapier.actuators = actuators(m)?;
        for mb in rapier.multibody_indices() {
            if let Some(mb) = rapier.world.multibody_joints.get_multibody_mut(mb) {
                // A new multibody takes its root as free; forward kinematics finds it fixed and drops
                // its six root coordinates, which shifts every dof index: settle that first.
                mb.forward_kinematics(&rapier.world.bodies, false);
                // The strip's segments touch the guide walls on the hand: same multibody.
                mb.set_self_contacts_enabled(true);
            }
        }
        rapier.add_joint_dynamics(m);
        rapier.add_colliders(m)?;
        Ok(rapier)
    }

    fn multibody_indices(&self) -> Vec<MultibodyIndex> {
        let mut out: Vec<MultibodyIndex> = Vec::new();
        for link in self.joints.iter().flatten() {
            if let Some(id) = self.world.multibody_joints.rigid_body_link(link.body)
                && !out.contains(&id.multibody)
            {
                out.push(id.multibody);
            }
        }
        out
    }

    /// Damping (with the servos' kv), armature, friction loss and springs of every hinge and slide.
    fn add_joint_dynamics(&mut self, m: &MjModel) {
        let actuators = &self.actuators;
        for (j, link) in self.joints.iter().enumerate() {
            let Some(link) = link else { continue };
            let dof = m.jnt_dofadr()[j] as usize;
            let Some((mb, id)) = self.world.multibody_joints.get_mut(link.handle) else { continue };
            let a = mb.link(id).map_or(0, |l| l.assembly_id());
            if mb.link(id).is_some_and(|l| l.joint.kinematic) {
                // Prescribed: no dynamics of its own.
                mb.damping_mut()[a] = 0.0;
                continue;
            }
            let servo_kv: f64 = actuators
                .iter()
                .filter(|s| s.joint == j)
                .map(|s| match s.kind {
                    ActuatorKind::Position { kv, .. } => kv,
                    ActuatorKind::Motor { .. } => 0.0,
                })
                .sum();
            mb.damping_mut()[a] = m.dof_damping()[dof] + servo_kv;
            mb.armature_mut()[a] = m.dof_armature()[dof];
            mb.frictions_mut()[a] = m.dof_frictionloss()[dof];
            if let Some(l) = mb.link_mut(id) {
                l.joint.set_spring(link.kind.coord(), link.stiffness, link.spring_rest);
            }
        }
    }

    fn add_colliders(&mut self, m: &MjModel) -> Result<(), PhysicsError> {
        for g in 0..m.ffi().ngeom as usize {
            if m.geom_contype()[g] == 0 && m.geom_conaffinity()[g] == 0 {
                continue;
            }
            let [s0, s1, s2] = m.geom_size()[g];
            let local = pose(m.geom_pos()[g], m.geom_quat()[g]);
            let builder = match m.geom_type()[g] {
                _mjtGeomBase::mjGEOM_BOX => ColliderBuilder::cuboid(s0, s1, s2),
                _mjtGeomBase::mjGEOM_SPHERE => ColliderBuilder::ball(s0),
                _mjtGeomBase::mjGEOM_CAPSULE => ColliderBuilder::capsule_z(s1, s0),
                // rapier's cylinder runs along y, MuJoCo's along z.
                _mjtGeomBase::mjGEOM_CYLINDER => ColliderBuilder::cylinder(s1, s0)
                    .position(local * Pose::from_rotation(Rotation::from_rotation_x(std::f64::consts::FRAC_PI_2))),
                _mjtGeomBase::mjGEOM_PLANE => ColliderBuilder::halfspace(Unit::new_unchecked(Vector::Z)),
                other => return Err(unsupported(format!("{other:?} geom `{}`", self.geom_names[g]))),
            };
            let builder = match m.geom_type()[g] {
                _mjtGeomBase::mjGEOM_CYLINDER => builder,
                _ => builder.position(local),
            };
            let collider = builder
                .density(0.0)
                .friction(m.geom_friction()[g][0])
                .user_data(g as u128)
                .active_hooks(ActiveHooks::FILTER_CONTACT_PAIRS | ActiveHooks::MODIFY_SOLVER_CONTACTS);
            let body = self.bodies[m.geom_bodyid()[g] as usize];
            self.colliders[g] = Some(self.world.insert_collider(collider, Some(body)));
        }
        Ok(())
    }

    /// Simulated time [s].
    pub fn time(&self) -> f64 {
        self.time_s
    }

    /// Step size [s].
    pub fn timestep(&self) -> f64 {
        self.world.integration_parameters.dt
    }

    /// Sets actuator `i`'s control (MuJoCo's `ctrl[i]`).
    pub fn set_ctrl(&mut self, i: usize, value: f64) {
        self.ctrl[i] = value;
    }

    fn link(&self, j: usize) -> Option<(&JointLink, &Multibody, usize)> {
        let link = self.joints.get(j)?.as_ref()?;
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
        let Some(link) = self.joints.get(j).and_then(|l| l.as_ref()) else { return };
        if let Some((mb, id)) = self.world.multibody_joints.get_mut(link.handle)
            && let Some(a) = mb.link(id).map(|l| l.assembly_id())
        {
            mb.generalized_velocity_mut()[a] = v;
        }
    }

    /// Moves prescribed joint `j` to position `q` at once (start poses), with everything it carries.
    pub fn place_joint(&mut self, j: usize, q: f64) {
        let current = self.joint_position(j);
        let Some(link) = self.joints.get(j).and_then(|l| l.as_ref()) else { return };
        let bodies = &mut self.world.bodies;
        if let Some((mb, id)) = self.world.multibody_joints.get_mut(link.handle)
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

    /// Normal force [N] summed over contacts between a geom in `a` and a geom in `b`, and the
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

    /// Tension of tendon `t` [N]: MuJoCo's tendon force, positive when the tendon is shorter than
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
        let mut generalized = vec![0.0; self.joints.len()];
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
        self.world.step_with_events(&self.rules, &());
        self.time_s += self.timestep();
        self.check()
    }

    /// Points joint `j`'s implicit spring at the servo's `target` (its stiffness `kp` added to the
    /// joint's own); a target further than `force_max / kp` away is brought within it, so the
    /// servo pushes with at most `force_max`.
    fn set_servo(&mut self, j: usize, target: f64, kp: f64, force_max: f64) {
        let q = self.joint_position(j);
        let Some(link) = self.joints.get(j).and_then(|l| l.as_ref()) else { return };
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
        let Some(link) = self.joints.get(j).and_then(|l| l.as_ref()).cloned() else { return };
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

fn set_parameters(p: &mut IntegrationParameters, physics: &PhysicsConfig) {
    let r = &physics.rapier;
    p.dt = physics.timestep_s;
    p.num_solver_iterations = r.solver_iterations as usize;
    p.num_internal_pgs_iterations = r.pgs_iterations as usize;
    p.num_internal_stabilization_iterations = r.stabilization_iterations as usize;
    p.friction_model = match r.friction_model {
        RapierFriction::Simplified => FrictionModel::Simplified,
        RapierFriction::Coulomb => FrictionModel::Coulomb,
    };
    p.contact_softness = SpringCoefficients::new(r.contact_frequency_hz, r.contact_damping_ratio);
    p.static_contact_softness = p.contact_softness;
    p.length_unit = r.length_unit_m;
    // Read contact forces per manifold; the scene's primitives give one manifold per pair anyway.
    p.contact_clustering = false;
    // Recycling keeps contacts of pairs that moved less than 0.05 length units: the finger's
    // contacts change within a millimetre.
    p.contact_recycling = false;
}

fn tendons(m: &MjModel) -> Result<Vec<FixedTendon>, PhysicsError> {
    let mut out = Vec::new();
    for t in 0..m.ffi().ntendon as usize {
        let adr = m.tendon_adr()[t] as usize;
        let num = m.tendon_num()[t] as usize;
        let mut terms = Vec::with_capacity(num);
        for w in adr..adr + num {
            if m.wrap_type()[w] != mjtWrap::mjWRAP_JOINT {
                let name = m.id_to_name(_mjtObjBase::mjOBJ_TENDON, t).unwrap_or("?");
                return Err(unsupported(format!("spatial tendon `{name}` (only fixed tendons)")));
            }
            terms.push((m.wrap_objid()[w] as usize, m.wrap_prm()[w]));
        }
        out.push(FixedTendon {
            terms,
            stiffness: m.tendon_stiffness()[t],
            dead_band: m.tendon_lengthspring()[t],
            damping: m.tendon_damping()[t],
        });
    }
    Ok(out)
}

fn actuators(m: &MjModel) -> Result<Vec<Actuator>, PhysicsError> {
    let mut out = Vec::new();
    for a in 0..m.ffi().nu as usize {
        let name = || m.id_to_name(_mjtObjBase::mjOBJ_ACTUATOR, a).unwrap_or("?").to_string();
        if m.actuator_trntype()[a] != mjtTrn::mjTRN_JOINT || m.actuator_gaintype()[a] != mjtGain::mjGAIN_FIXED {
            return Err(unsupported(format!("actuator `{}` (only joint motors and position servos)", name())));
        }
        let gear = m.actuator_gear()[a][0];
        let gain = m.actuator_gainprm()[a][0];
        let bias = m.actuator_biasprm()[a];
        let kind = match m.actuator_biastype()[a] {
            mjtBias::mjBIAS_NONE => ActuatorKind::Motor { gain: gain * gear },
            mjtBias::mjBIAS_AFFINE if bias[1] == -gain && gear == 1.0 => {
                ActuatorKind::Position { kp: gain, kv: -bias[2] }
            }
            _ => return Err(unsupported(format!("actuator `{}` (only joint motors and position servos)", name()))),
        };
        let [flo, fhi] = m.actuator_forcerange()[a];
        out.push(Actuator {
            joint: m.actuator_trnid()[a][0] as usize,
            kind,
            ctrl_range: m.actuator_ctrllimited()[a].then(|| m.actuator_ctrlrange()[a]),
            force_max: if m.actuator_forcelimited()[a] { flo.abs().max(fhi.abs()) } else { f64::MAX },
        });
    }
    Ok(out)
}
