//! The translation of a compiled MuJoCo model into a rapier world ([`RapierWorld::build`]).
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
use super::world::{Actuator, ActuatorKind, FixedTendon, JointKind, JointLink, RapierWorld};
use crate::physics::PhysicsError;
use crate::physics::config::{PhysicsConfig, RapierFriction};
use mujoco_rs::mujoco_c::{_mjtGeomBase, _mjtObjBase, mjtBias, mjtGain, mjtJoint, mjtTrn, mjtWrap};
use mujoco_rs::prelude::MjModel;
use rapier3d_f64::na::Unit;
use rapier3d_f64::prelude::*;

/// A MuJoCo vector as rapier's.
fn vec3(a: [f64; 3]) -> Vector {
    Vector::new(a[0], a[1], a[2])
}

/// A MuJoCo quaternion (w, x, y, z) as rapier's rotation.
fn rot3(q: [f64; 4]) -> Rotation {
    Rotation::from_xyzw(q[1], q[2], q[3], q[0]).normalize()
}

fn pose(p: [f64; 3], q: [f64; 4]) -> Pose {
    Pose::from_parts(vec3(p), rot3(q))
}

/// A rotation taking the x axis onto `axis` (rapier's joints move along or about their frames' x).
fn x_onto(axis: Vector) -> Rotation {
    Rotation::from_rotation_arc(Vector::X, axis.normalize())
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
                    let kinematic = prescribed.contains(&j);
                    carried[b] = kinematic || carried[parent];
                    if m.jnt_limited()[j] && !carried[b] {
                        joint = joint.limits(kind.axis(), m.jnt_range()[j]);
                    }
                    let handle = world.insert_body(dynamic());
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
            generalized: Vec::new(),
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
            // rapier's cylinder runs along y, MuJoCo's along z: a quarter turn about x.
            let along_z = Pose::from_rotation(Rotation::from_rotation_x(std::f64::consts::FRAC_PI_2));
            let (builder, local) = match m.geom_type()[g] {
                _mjtGeomBase::mjGEOM_BOX => (ColliderBuilder::cuboid(s0, s1, s2), local),
                _mjtGeomBase::mjGEOM_SPHERE => (ColliderBuilder::ball(s0), local),
                _mjtGeomBase::mjGEOM_CAPSULE => (ColliderBuilder::capsule_z(s1, s0), local),
                _mjtGeomBase::mjGEOM_CYLINDER => (ColliderBuilder::cylinder(s1, s0), local * along_z),
                _mjtGeomBase::mjGEOM_PLANE => (ColliderBuilder::halfspace(Unit::new_unchecked(Vector::Z)), local),
                // Refused by name: a convex hull of MuJoCo's mesh vertices was tried and let the shipped
                // bottle sink through the table (2.5 cm in 0.2 s); until that is understood, a mesh
                // object runs on MuJoCo only.
                _mjtGeomBase::mjGEOM_MESH => {
                    return Err(unsupported(format!(
                        "mesh geom `{}` (mesh objects run on the mujoco backend only)",
                        self.geom_names[g]
                    )));
                }
                other => return Err(unsupported(format!("{other:?} geom `{}`", self.geom_names[g]))),
            };
            let collider = builder
                .position(local)
                .density(0.0)
                .friction(m.geom_friction()[g][0])
                .user_data(g as u128)
                .active_hooks(ActiveHooks::FILTER_CONTACT_PAIRS | ActiveHooks::MODIFY_SOLVER_CONTACTS);
            let body = self.bodies[m.geom_bodyid()[g] as usize];
            self.colliders[g] = Some(self.world.insert_collider(collider, Some(body)));
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
