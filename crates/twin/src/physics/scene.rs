//! One simulation run of the cell: a compiled, shareable [`SceneModel`] and per-run [`Scene`] state.

use super::census::ContactCensus;
use super::compose::{self, Placement, ProducePart};
use super::config::{ArmMode, Backend};
use super::damage::Toucher;
use super::drive::{Drive, grip_in_hand};
use super::guide::GuidePruning;
use super::produce_run::{self, GeomShape, ProduceIds, ProduceRun};
use super::{Divergence, PadPlace, Physics, PhysicsError, PhysicsReadout, SceneSpec, Snapshot};
use mujoco_rs::mujoco_c::{_mjtObjBase, mjtEnableBit, mjtState, mjtWarning};
use mujoco_rs::prelude::{MjData, MjModel};
use nalgebra::{Isometry3, Vector3};
use std::sync::Arc;
use tendril_config::{Checker, Validate};
use tendril_fbg::array::PerPad;

/// The quaternion (w, x, y, z) of a turn by `yaw_deg` about the vertical.
pub(crate) fn yaw_quaternion(yaw_deg: f64) -> [f64; 4] {
    let half = yaw_deg.to_radians() / 2.0;
    [half.cos(), 0.0, 0.0, half.sin()]
}

/// A compiled scene model and the element ids the readout needs. Build it once and share it (it is
/// `Send + Sync`) between many [`Scene`]s, for example across threads.
#[derive(Debug, Clone)]
pub struct SceneModel {
    model: Arc<MjModel>,
    spec: SceneSpec,
    placement: Placement,
    xml: String,
    ids: Ids,
    /// The model without the guide walls' contacts, stepped while they cannot touch the strip
    /// (`None`: the walls stay in throughout).
    guide_pruning: Option<Arc<GuidePruning>>,
    /// The produce item, when the object is one: as configured, and its flex's calibration.
    produce: Option<Arc<ProducePart>>,
    /// The deepest a contact with the produce item's flex may go \[m\]: `physics.max_penetration_m`,
    /// or deeper where the item's soft contact lets a drop in further
    /// ([`super::plates::Calibration::drop_depth_m`]); set once here, read every step.
    flex_penetration_bound_m: f64,
}

/// Ids of the elements the readout and the backends need (MuJoCo's numbering, which the rapier
/// world keeps: it is built from the same compiled model).
#[derive(Debug, Clone)]
pub(crate) struct Ids {
    /// Geoms of the sensor pad (casing, bump).
    pub(crate) pad_geoms: Vec<usize>,
    /// Geoms of each further pad of a sensor array (`SceneSpec::extra_pads`).
    pub(crate) extra_pad_geoms: Vec<Vec<usize>>,
    /// Geoms of the strip and the pad.
    pub(crate) finger_geoms: Vec<usize>,
    /// The palm beside the guide exit.
    pub(crate) palm_geom: Vec<usize>,
    /// Every geom the arm carries (its links, the hand, palm, strip and pad): what the object can
    /// load the wrist through.
    pub(crate) hand_geoms: Vec<usize>,
    /// The object's geoms (empty without object).
    pub(crate) object_geoms: Vec<usize>,
    pub(crate) object_body: Option<usize>,
    pub(crate) object_grip: Option<usize>,
    pub(crate) object_qpos: Option<usize>,
    pub(crate) hand_body: usize,
    pub(crate) growth_qpos: usize,
    pub(crate) twine_qpos: usize,
    pub(crate) creep_qpos: usize,
    pub(crate) growth_act: usize,
    pub(crate) twine_act: usize,
    /// Joints of the growth and twine outputs, the creep node and the arm.
    pub(crate) growth_joint: usize,
    pub(crate) twine_joint: usize,
    pub(crate) creep_joint: usize,
    pub(crate) arm_joint: [usize; 6],
    pub(crate) arm_qpos: [usize; 6],
    pub(crate) arm_dof: [usize; 6],
    /// Servo actuators of the arm (dynamic mode only).
    pub(crate) arm_act: Option<[usize; 6]>,
    /// Each arm servo's velocity feedforward as a lead \[s\]: (kv + joint damping) / kp, so that a
    /// setpoint moving at speed v is followed without the lag (kv + damping) v / kp a bare PD servo
    /// has (dynamic mode; zero in the kinematic one).
    pub(crate) arm_servo_lead_s: [f64; 6],
    pub(crate) tendon_elastic: usize,
    pub(crate) tendon_maxwell: usize,
    pub(crate) pad_touch_adr: usize,
    /// The produce item's flex (`None` for a rigid object).
    pub(crate) produce: Option<ProduceIds>,
    /// What each geom is to a produce item's damage figures (empty for a rigid object).
    pub(crate) geom_shapes: Vec<Option<GeomShape>>,
}

fn id(model: &MjModel, kind: _mjtObjBase, kind_name: &'static str, name: &str) -> Result<usize, PhysicsError> {
    model.name_to_id(kind, name).ok_or_else(|| PhysicsError::Missing { kind: kind_name, name: name.to_string() })
}

impl SceneModel {
    /// Validates `spec`, assembles the MJCF from models/, compiles it and applies the overrides that
    /// edit the compiled model (object friction, start poses).
    pub fn build(spec: &SceneSpec) -> Result<Arc<SceneModel>, PhysicsError> {
        let mut checker = Checker::default();
        spec.validate(&mut checker);
        if let Some((key, reason)) = checker.into_first_error() {
            return Err(PhysicsError::Config { key, reason });
        }
        let (xml, placement, produce) = compose::scene(spec)?;
        let mut model =
            MjModel::from_xml_string(&xml).map_err(|e| PhysicsError::Compile { message: format!("{e:?}") })?;
        let ids = Self::find_ids(&model, spec, produce.is_some())?;

        // Object: friction override on the grip the finger touches (its base keeps its own friction
        // against the table), start pose on the table.
        if let Some(obj) = &spec.object {
            if let (Some(mu), Some(g)) = (obj.friction, ids.object_grip) {
                model.geom_friction_mut()[g][0] = mu;
            }
            if let (Some(adr), Some(p)) = (ids.object_qpos, placement.object) {
                let [w, x, y, z] = yaw_quaternion(obj.yaw_deg.unwrap_or(0.0));
                model.qpos0_mut()[adr..adr + 7].copy_from_slice(&[p.x, p.y, p.z, w, x, y, z]);
            }
            if let (Some(mass), Some(body)) = (obj.mass_kg, ids.object_body) {
                // Same shape and mass distribution: the inertia scales with the mass.
                let scale = mass / model.body_mass()[body];
                model.body_mass_mut()[body] = mass;
                for v in model.body_inertia_mut()[body].iter_mut() {
                    *v *= scale;
                }
                // The constants MuJoCo derives from masses (subtree masses, the inverse weights its
                // contact softness is scaled by) follow the new mass, as the compiler would set them.
                MjData::new(&mut model).set_const();
            }
        }
        // MuJoCo's energy flag makes every step compute the potential and the kinetic energy; the
        // runaway check reads only the kinetic one, which `Scene::check` computes itself (issue 39,
        // lever 6: the potential energy was 0.3 % of a run's instructions, read by nothing). The
        // energies feed nothing in the dynamics, so the steps are the same.
        model.opt_mut().enableflags &= !(mjtEnableBit::mjENBL_ENERGY as i32);
        if spec.physics.arm_mode == ArmMode::Kinematic {
            // Prescribed motion: the arm must not give way to contact forces within a step.
            for d in ids.arm_dof {
                model.dof_armature_mut()[d] = KINEMATIC_ARM_ARMATURE;
            }
        }
        let guide_pruning = GuidePruning::new(&model).map(Arc::new);
        let bound = spec.physics.max_penetration_m;
        let flex_penetration_bound_m = produce.as_ref().map_or(bound, |p| bound.max(p.calibration.drop_depth_m()));
        let shared = Arc::new(SceneModel {
            model: Arc::new(model),
            spec: spec.clone(),
            placement,
            xml,
            ids,
            guide_pruning,
            produce: produce.map(Arc::new),
            flex_penetration_bound_m,
        });
        if spec.physics.backend == Backend::Rapier {
            // Translate once now, so an element rapier cannot take is an error before any run starts.
            super::rapier::RapierWorld::build(&shared.model, &spec.physics, &shared.ids.arm_joint)?;
        }
        Ok(shared)
    }

    fn find_ids(m: &MjModel, spec: &SceneSpec, produce: bool) -> Result<Ids, PhysicsError> {
        use _mjtObjBase::*;
        let geom = |n: &str| id(m, mjOBJ_GEOM, "geom", n);
        let joint = |n: &str| id(m, mjOBJ_JOINT, "joint", n);
        let qpos = |n: &str| joint(n).map(|j| m.jnt_qposadr()[j] as usize);
        let act = |n: &str| id(m, mjOBJ_ACTUATOR, "actuator", n);
        let pad_geoms = vec![geom("pad_casing")?, geom("pad_bump")?];
        let mut finger_geoms = pad_geoms.clone();
        let extra_pad_geoms = (1..=spec.extra_pads.len())
            .map(|k| Ok(vec![geom(&format!("pad{k}_casing"))?, geom(&format!("pad{k}_bump"))?]))
            .collect::<Result<Vec<_>, PhysicsError>>()?;
        finger_geoms.extend(extra_pad_geoms.iter().flatten());
        for i in 0..super::strip::layout_with_pads(&spec.finger, &PadPlace::arcs(&spec.extra_pads)).len() {
            finger_geoms.push(geom(&format!("seg{i}"))?);
        }
        let (object_geoms, object_body, object_grip, object_qpos) = if spec.object.is_some() && !produce {
            let body = id(m, mjOBJ_BODY, "body", "object")?;
            let geoms = (0..m.ffi().ngeom as usize).filter(|&g| m.geom_bodyid()[g] as usize == body).collect();
            (geoms, Some(body), Some(geom("object_grip")?), Some(qpos("object")?))
        } else {
            (Vec::new(), None, None, None)
        };
        let hand_body = id(m, mjOBJ_BODY, "body", "hand")?;
        let arm_root = m.body_rootid()[hand_body];
        let hand_geoms =
            (0..m.ffi().ngeom as usize).filter(|&g| m.body_rootid()[m.geom_bodyid()[g] as usize] == arm_root).collect();
        let names = ["shoulder_pan", "shoulder_lift", "elbow", "wrist_1", "wrist_2", "wrist_3"];
        let mut arm_qpos = [0; 6];
        let mut arm_dof = [0; 6];
        let mut arm_joint = [0; 6];
        for k in 0..6 {
            arm_joint[k] = joint(names[k])?;
            arm_qpos[k] = qpos(names[k])?;
            arm_dof[k] = m.jnt_dofadr()[arm_joint[k]] as usize;
        }
        let arm_act = match spec.physics.arm_mode {
            ArmMode::Kinematic => None,
            ArmMode::Dynamic => {
                let mut a = [0; 6];
                for k in 0..6 {
                    a[k] = act(names[k])?;
                }
                Some(a)
            }
        };
        // A position actuator's force is kp (ctrl - q) - kv dq/dt (MuJoCo: gainprm[0] = kp,
        // biasprm[2] = -kv), and the joint's damping adds -d dq/dt.
        let arm_servo_lead_s = match arm_act {
            None => [0.0; 6],
            Some(a) => std::array::from_fn(|k| {
                let (kp, kv) = (m.actuator_gainprm()[a[k]][0], -m.actuator_biasprm()[a[k]][2]);
                if kp > 0.0 { (kv + m.dof_damping()[arm_dof[k]]) / kp } else { 0.0 }
            }),
        };
        let touch = id(m, mjOBJ_SENSOR, "sensor", "pad_touch")?;
        let palm = geom("palm")?;
        let (produce, geom_shapes) = if produce {
            let ngeom = m.ffi().ngeom as usize;
            let bumps: Vec<usize> = std::iter::once(pad_geoms[1]).chain(extra_pad_geoms.iter().map(|p| p[1])).collect();
            let casings: Vec<usize> =
                std::iter::once(pad_geoms[0]).chain(extra_pad_geoms.iter().map(|p| p[0])).collect();
            let shapes = (0..ngeom)
                .map(|g| {
                    let toucher = if bumps.contains(&g) {
                        Toucher::PadBump
                    } else if casings.contains(&g) {
                        Toucher::PadCasing
                    } else if finger_geoms.contains(&g) {
                        Toucher::Strip
                    } else if g == palm {
                        Toucher::Palm
                    } else {
                        Toucher::Other
                    };
                    Some(GeomShape::of(m, g, toucher))
                })
                .collect();
            (Some(ProduceIds::find(m)?), shapes)
        } else {
            (None, Vec::new())
        };
        Ok(Ids {
            pad_geoms,
            extra_pad_geoms,
            finger_geoms,
            palm_geom: vec![palm],
            hand_geoms,
            object_geoms,
            object_body,
            object_grip,
            object_qpos,
            hand_body,
            growth_qpos: qpos("growth")?,
            twine_qpos: qpos("twine")?,
            creep_qpos: qpos("creep")?,
            growth_act: act("growth")?,
            growth_joint: joint("growth")?,
            twine_joint: joint("twine")?,
            creep_joint: joint("creep")?,
            arm_joint,
            twine_act: act("twine")?,
            arm_qpos,
            arm_dof,
            arm_act,
            arm_servo_lead_s,
            tendon_elastic: id(m, mjOBJ_TENDON, "tendon", "tendon_elastic")?,
            tendon_maxwell: id(m, mjOBJ_TENDON, "tendon", "tendon_maxwell")?,
            pad_touch_adr: m.sensor_adr()[touch] as usize,
            produce,
            geom_shapes,
        })
    }

    /// The compiled MuJoCo model.
    pub fn model(&self) -> &Arc<MjModel> {
        &self.model
    }

    /// The same scene with the guide's walls kept in the collision search throughout: the
    /// reference the pruned runs are compared with (tests/guide_pruning.rs).
    pub fn without_guide_pruning(&self) -> Arc<SceneModel> {
        Arc::new(SceneModel { guide_pruning: None, ..self.clone() })
    }

    /// Whether runs on this model leave the guide's walls out of the collision search while they
    /// cannot touch the strip ([`GuidePruning`]).
    pub fn prunes_guide(&self) -> bool {
        self.guide_pruning.is_some()
    }

    /// The spec it was built from.
    pub fn spec(&self) -> &SceneSpec {
        &self.spec
    }

    /// Where the parts start (hand pose, object footprint, table height).
    pub fn placement(&self) -> &Placement {
        &self.placement
    }

    /// Element ids for the backends.
    pub(crate) fn ids(&self) -> &Ids {
        &self.ids
    }

    /// The sensor pad's geoms (casing, bump), in MuJoCo's numbering (for a renderer to colour).
    pub fn pad_geoms(&self) -> &[usize] {
        &self.ids.pad_geoms
    }

    /// The object's grip geom, if the scene has an object (where a camera may look).
    pub fn object_grip_geom(&self) -> Option<usize> {
        self.ids.object_grip
    }

    /// The hand's body (the flange frame).
    pub fn hand_body(&self) -> usize {
        self.ids.hand_body
    }

    /// The assembled MJCF text (for inspection or saving).
    pub fn xml(&self) -> &str {
        &self.xml
    }

    /// The produce item and its flex's calibration, when the object is one.
    pub fn produce(&self) -> Option<&ProducePart> {
        self.produce.as_deref()
    }
}

/// The geom a contact's other side is and the sign of its force on the flex `flex` (+1: the
/// contact's normal points from that geom to the flex), for a contact between a geom and `flex`.
fn flex_contact(c: &mujoco_rs::mujoco_c::mjContact, flex: usize) -> Option<(usize, f64)> {
    let is = |k: usize| c.flex[k] >= 0 && c.flex[k] as usize == flex;
    if is(1) && c.geom[0] >= 0 {
        Some((c.geom[0] as usize, 1.0))
    } else if is(0) && c.geom[1] >= 0 {
        Some((c.geom[1] as usize, -1.0))
    } else {
        None
    }
}

/// One MuJoCo simulation run on a shared [`SceneModel`]. Deterministic: the same inputs give a
/// bit-identical trajectory.
#[derive(Debug)]
pub struct Scene {
    shared: Arc<SceneModel>,
    data: MjData<Arc<MjModel>>,
    drive: Drive,
    warnings_seen: [i32; 8],
    /// The hand subtree's centre-of-mass Jacobian (3 x nv, row-major), reused every step.
    payload_jacobian: Vec<f64>,
    /// Whether `data` runs on the model without the guide walls' contacts.
    walls_pruned: bool,
    /// The data of the other model (with or without the walls' contacts), kept for the next switch.
    spare_data: Option<MjData<Arc<MjModel>>>,
    /// The integration state at the start of a step on the pruned model, reused every step.
    step_start: Vec<f64>,
    /// Contacts per geom pair, when asked for ([`Physics::count_contacts`]).
    census: Option<ContactCensus>,
    /// The produce item's damage, stem and start shape (`None` for a rigid object).
    produce: Option<ProduceRun>,
    /// The push on a produce item \[N\] (a rigid object's goes straight to its body).
    produce_push_n: [f64; 3],
}

/// Armature of the arm joints in the kinematic mode [kg m^2]: large enough that a few newtons of
/// contact force do not turn a joint within a step (their motion is prescribed anyway).
pub(crate) const KINEMATIC_ARM_ARMATURE: f64 = 1000.0;

/// MuJoCo warnings that mean the run is not trustworthy.
const FATAL_WARNINGS: [(mjtWarning, &str); 6] = [
    (mjtWarning::mjWARN_INERTIA, "bad inertia"),
    (mjtWarning::mjWARN_CONTACTFULL, "contact buffer full"),
    (mjtWarning::mjWARN_CNSTRFULL, "constraint buffer full"),
    (mjtWarning::mjWARN_BADQPOS, "bad qpos (NaN/Inf/huge)"),
    (mjtWarning::mjWARN_BADQVEL, "bad qvel (NaN/Inf/huge)"),
    (mjtWarning::mjWARN_BADQACC, "bad qacc (NaN/Inf/huge): unstable"),
];

impl Scene {
    /// Builds the model for `spec` and a run on it.
    pub fn build(spec: &SceneSpec) -> Result<Scene, PhysicsError> {
        Ok(Scene::new(SceneModel::build(spec)?))
    }

    /// A fresh run on a shared model, at the start placement with the finger retracted and slack.
    pub fn new(shared: Arc<SceneModel>) -> Scene {
        let mut data = MjData::new(shared.model.clone());
        let q0 = shared.spec.arm_q0;
        // Hinge angles count from qpos0 (the model's zero pose), so the start pose is set in the data,
        // not in the model; the object's free joint starts from its qpos0 set in SceneModel::build.
        for (adr, q) in shared.ids.arm_qpos.iter().zip(q0) {
            data.qpos_mut()[*adr] = q;
        }
        if let Some(acts) = shared.ids.arm_act {
            for (a, q) in acts.iter().zip(q0) {
                data.ctrl_mut()[*a] = q;
            }
        }
        data.forward();
        let produce = shared.ids.produce.as_ref().zip(shared.produce.as_ref()).map(|(ids, part)| {
            let harvest = &shared.spec.produce;
            ProduceRun::start(ids, &part.item, &data, harvest.harvest.then_some(harvest.stem_stiffness_n_m))
        });
        let drive = Drive::new(&shared.spec.physics, &shared.spec.finger, q0);
        let payload_jacobian = vec![0.0; 3 * shared.model.ffi().nv as usize];
        Scene {
            shared,
            data,
            drive,
            warnings_seen: [0; 8],
            payload_jacobian,
            walls_pruned: false,
            spare_data: None,
            step_start: Vec::new(),
            census: None,
            produce,
            produce_push_n: [0.0; 3],
        }
    }

    /// The shared model.
    pub fn shared(&self) -> &Arc<SceneModel> {
        &self.shared
    }

    /// Raw MuJoCo data (read-only), for checks beyond the readout.
    pub fn data(&self) -> &MjData<Arc<MjModel>> {
        &self.data
    }

    /// The servoed arm's payload compensation, as a UR's controller has for its configured payload:
    /// the joint torques that carry the weight of the hand and everything on it (the finger, the
    /// pad; not a held object), from the subtree's centre-of-mass Jacobian at the last computed
    /// pose. Without it the position servos sagged under that weight (1.5 mrad at the shoulder,
    /// about 1.2 mm at the hand), where a UR holds its pose to a fraction of that.
    fn compensate_payload(&mut self) {
        let ids = &self.shared.ids;
        let model = &self.shared.model;
        let nv = model.ffi().nv as usize;
        let mass = model.body_subtreemass()[ids.hand_body];
        let gravity = model.opt().gravity;
        self.data.jac_subtree_com_into(ids.hand_body, &mut self.payload_jacobian);
        for d in ids.arm_dof {
            let along_gravity: f64 = (0..3).map(|i| self.payload_jacobian[i * nv + d] * gravity[i]).sum();
            self.data.qfrc_applied_mut()[d] = -mass * along_gravity;
        }
    }

    /// Moves the run onto the model with (`pruned` false) or without the guide walls' contacts,
    /// carrying over everything a step starts from (MuJoCo's integration state: time, positions,
    /// velocities, activations, the solver's warm start, controls, applied forces), or the
    /// integration state `state` when given: the next step then computes what it would have on
    /// the other model, but for the walls' contacts. The data of the model left is kept for the
    /// next switch.
    fn switch_guide(&mut self, pruned: bool, state: Option<&[f64]>) {
        let model = match (&self.shared.guide_pruning, pruned) {
            (Some(p), true) => p.model().clone(),
            _ => self.shared.model.clone(),
        };
        let mut data = self.spare_data.take().unwrap_or_else(|| MjData::new(model));
        let integration = mjtState::mjSTATE_INTEGRATION as u32;
        match state {
            Some(state) => data.set_state(state, integration),
            None => data.copy_state_from_data(&self.data, integration),
        }
        .expect("the pruned model has the same layout");
        self.spare_data = Some(std::mem::replace(&mut self.data, data));
        // Warnings are counted per data.
        self.warnings_seen = [0; 8];
        for (k, (w, _)) in FATAL_WARNINGS.iter().enumerate() {
            self.warnings_seen[k] = self.data.warning()[*w as usize].number;
        }
        self.walls_pruned = pruned;
    }

    /// Takes one MuJoCo step, on the model without the guide walls' contacts when they cannot
    /// touch anything ([`GuidePruning`]): a step taken there is checked with the positions its
    /// collision search used, and taken again on the full model, from the state it started at,
    /// if the walls might have touched. The contacts, and so the trajectory, are the full model's.
    fn mj_step(&mut self) {
        let Some(pruning) = self.shared.guide_pruning.clone() else {
            self.data.step();
            return;
        };
        // The step's positions: a switch of model carries them over, so this holds on either.
        let first_link_clear = pruning.first_link_clear(self.data.qpos());
        // Positions of the last step's start: a guess, checked below.
        if !self.walls_pruned && pruning.walls_idle(&self.data, first_link_clear) {
            self.switch_guide(true, None);
        }
        if !self.walls_pruned {
            self.data.step();
            return;
        }
        let integration = mjtState::mjSTATE_INTEGRATION as u32;
        self.step_start.resize(self.data.model().state_size(integration), 0.0);
        self.data.read_state_into(integration, &mut self.step_start);
        self.data.step();
        if !pruning.walls_idle(&self.data, first_link_clear) {
            let start = std::mem::take(&mut self.step_start);
            self.switch_guide(false, Some(&start));
            self.step_start = start;
            self.data.step();
        }
    }

    fn check(&mut self, time_s: f64) -> Result<(), PhysicsError> {
        let diverged = |cause| Err(PhysicsError::Diverged { time_s, cause });
        // Warnings first: on a bad acceleration MuJoCo resets the state, so the NaN is gone by now.
        let warnings = self.data.warning();
        for (k, (w, name)) in FATAL_WARNINGS.iter().enumerate() {
            let count = warnings[*w as usize].number;
            if count > self.warnings_seen[k] {
                self.warnings_seen[k] = count;
                return diverged(Divergence::Warning { warning: name });
            }
        }
        for (what, values) in [("qpos", self.data.qpos()), ("qvel", self.data.qvel()), ("qacc", self.data.qacc())] {
            if values.iter().any(|v| !v.is_finite()) {
                return diverged(Divergence::NonFinite { what });
            }
        }
        let bound = self.shared.spec.physics.max_penetration_m;
        if let (Some(run), Some(ids)) = (&self.produce, &self.shared.ids.produce)
            && let Some(cause) = run.inverted(ids, &self.data)
        {
            return diverged(cause);
        }
        for c in self.data.contact() {
            let allowed = if c.flex.iter().any(|&f| f >= 0) { self.shared.flex_penetration_bound_m } else { bound };
            if c.dist < -allowed {
                // A flex's side of a contact has no geom (-1): it is named by its flex.
                let name = |k: usize| match (c.geom[k], c.flex[k]) {
                    (g, _) if g >= 0 => {
                        self.shared.model.id_to_name(_mjtObjBase::mjOBJ_GEOM, g as usize).unwrap_or("?").to_string()
                    }
                    (_, f) if f >= 0 => self
                        .shared
                        .model
                        .id_to_name(_mjtObjBase::mjOBJ_FLEX, f as usize)
                        .map_or_else(|| "a flex".to_string(), |n| format!("{n} (flex)")),
                    _ => "?".to_string(),
                };
                return diverged(Divergence::Penetration { depth_m: -c.dist, geom1: name(0), geom2: name(1) });
            }
        }
        // Kinetic energy of what is simulated (½ qvel' M qvel, M from the step's start), the
        // kinematic arm's armature term taken out: that is prescribed motion.
        self.data.energy_vel();
        let mut kinetic = self.data.energy()[1];
        if self.shared.ids.arm_act.is_none() {
            for d in self.shared.ids.arm_dof {
                kinetic -= 0.5 * KINEMATIC_ARM_ARMATURE * self.data.qvel()[d].powi(2);
            }
        }
        if !kinetic.is_finite() || kinetic > self.shared.spec.physics.max_kinetic_energy_j {
            return diverged(Divergence::Energy { joules: kinetic });
        }
        Ok(())
    }

    /// Normal force \[N\] summed over contacts between a geom in `a` and a geom in `b`, and their count.
    pub fn normal_force_between(&self, a: &[usize], b: &[usize]) -> (f64, usize) {
        let mut sum = 0.0;
        let mut n = 0;
        for (i, c) in self.data.contact().iter().enumerate() {
            let (g1, g2) = (c.geom1 as usize, c.geom2 as usize);
            let hit = (a.contains(&g1) && b.contains(&g2)) || (a.contains(&g2) && b.contains(&g1));
            if hit && c.efc_address >= 0 {
                sum += self.data.contact_force(i)[0];
                n += 1;
            }
        }
        (sum, n)
    }

    /// Normal force \[N\] summed over contacts between a geom in `a` and the flex `flex`, and
    /// their count.
    fn normal_force_on_flex(&self, a: &[usize], flex: usize) -> (f64, usize) {
        let mut sum = 0.0;
        let mut n = 0;
        for (i, c) in self.data.contact().iter().enumerate() {
            if flex_contact(c, flex).is_some_and(|(g, _)| a.contains(&g)) && c.efc_address >= 0 {
                sum += self.data.contact_force(i)[0];
                n += 1;
            }
        }
        (sum, n)
    }

    /// The upward (world +z) component of the contact forces geoms `a` exert on the flex `flex` \[N\].
    fn vertical_force_on_flex(&self, a: &[usize], flex: usize) -> f64 {
        let mut up = 0.0;
        for (i, c) in self.data.contact().iter().enumerate() {
            let Some((g, sign)) = flex_contact(c, flex) else { continue };
            if a.contains(&g) && c.efc_address >= 0 {
                let f = self.data.contact_force(i);
                up += sign * (f[0] * c.frame[2] + f[1] * c.frame[5] + f[2] * c.frame[8]);
            }
        }
        up
    }

    /// The upward (world +z) component of the contact forces geoms `a` exert on geoms `b` \[N\].
    pub fn vertical_force_on(&self, a: &[usize], b: &[usize]) -> f64 {
        let mut up = 0.0;
        for (i, c) in self.data.contact().iter().enumerate() {
            let (g1, g2) = (c.geom1 as usize, c.geom2 as usize);
            // MuJoCo's contact frame: rows normal, tangent 1, tangent 2; the normal points from
            // geom1 to geom2, and the force in that frame is the one geom1 exerts on geom2.
            let sign = if a.contains(&g1) && b.contains(&g2) {
                1.0
            } else if a.contains(&g2) && b.contains(&g1) {
                -1.0
            } else {
                continue;
            };
            if c.efc_address >= 0 {
                let f = self.data.contact_force(i);
                let z = f[0] * c.frame[2] + f[1] * c.frame[5] + f[2] * c.frame[8];
                up += sign * z;
            }
        }
        up
    }

    /// The pad's normal force as MuJoCo's `touch` sensor on `pad_site` reports it \[N\].
    pub fn pad_touch_sensor_n(&self) -> f64 {
        self.data.sensordata()[self.shared.ids.pad_touch_adr]
    }

    /// Tension of the tendon path \[N\]: both standard-linear-solid branches (zero when slack).
    pub fn tendon_tension_n(&self) -> f64 {
        let ids = &self.shared.ids;
        let m = &self.shared.model;
        let len = self.data.ten_length();
        let k = m.tendon_stiffness();
        // Length below the dead band's lower end (0) stretches the tendon.
        (-len[ids.tendon_elastic]).max(0.0) * k[ids.tendon_elastic]
            + (-len[ids.tendon_maxwell]).max(0.0) * k[ids.tendon_maxwell]
    }

    /// Geom ids of the sensor pad (casing, bump).
    pub fn pad_geoms(&self) -> &[usize] {
        &self.shared.ids.pad_geoms
    }

    /// Geom ids of the object.
    pub fn object_geoms(&self) -> &[usize] {
        &self.shared.ids.object_geoms
    }

    /// The area of the finger's faces that touch the object now \[m²\]: each box of the finger
    /// (a strip link, a pad's casing) in contact with the object counts with its largest face
    /// (its length by the strip's width), once however many points touch. The area the wrap lies
    /// on, at the links' resolution; a pad's bump counts through its casing. A produce item's
    /// side of a contact is its flex.
    pub fn contact_area_m2(&self) -> f64 {
        let ids = &self.shared.ids;
        let m = &self.shared.model;
        let mut touching: Vec<usize> = Vec::new();
        for c in self.data.contact() {
            let finger = match &ids.produce {
                Some(p) => flex_contact(c, p.flex).map(|(g, _)| g),
                None => {
                    let (g1, g2) = (c.geom1 as usize, c.geom2 as usize);
                    if ids.object_geoms.contains(&g2) { Some(g1) } else { ids.object_geoms.contains(&g1).then_some(g2) }
                }
            };
            if let Some(finger) = finger.filter(|f| c.efc_address >= 0 && ids.finger_geoms.contains(f)) {
                // The bump touches for its casing: one face per pad.
                let face = if ids.pad_geoms.contains(&finger) { ids.pad_geoms[0] } else { finger };
                if !touching.contains(&face) {
                    touching.push(face);
                }
            }
        }
        touching
            .into_iter()
            .filter(|&g| m.geom_type()[g] == mujoco_rs::mujoco_c::_mjtGeomBase::mjGEOM_BOX)
            .map(|g| {
                let mut half = m.geom_size()[g];
                half.sort_by(f64::total_cmp);
                4.0 * half[1] * half[2]
            })
            .sum()
    }
}

impl Physics for Scene {
    fn backend(&self) -> Backend {
        Backend::Mujoco
    }

    fn time(&self) -> f64 {
        self.data.time()
    }

    fn timestep(&self) -> f64 {
        self.shared.spec.physics.timestep_s
    }

    fn snapshot(&self) -> Option<Snapshot> {
        let d = &self.data;
        Some(Snapshot {
            qpos: d.qpos().to_vec(),
            qvel: d.qvel().to_vec(),
            ctrl: d.ctrl().to_vec(),
            act: d.act().to_vec(),
        })
    }

    fn mujoco_data_mut(&mut self) -> Option<&mut MjData<Arc<MjModel>>> {
        Some(&mut self.data)
    }

    fn set_growth(&mut self, growth_m: f64) -> Result<(), PhysicsError> {
        self.drive.set_growth(growth_m)
    }

    fn set_twine(&mut self, twine_m: f64) -> Result<(), PhysicsError> {
        self.drive.set_twine(twine_m)
    }

    fn set_arm_target(&mut self, q: [f64; 6]) -> Result<(), PhysicsError> {
        self.drive.set_arm_target(q, self.data.time())?;
        Ok(())
    }

    fn step(&mut self) -> Result<(), PhysicsError> {
        let t0 = self.data.time();
        let dt = self.shared.spec.physics.timestep_s;
        let before = self.drive.arm_q();
        let set = self.drive.advance(t0, dt);
        let ids = &self.shared.ids;
        self.data.ctrl_mut()[ids.growth_act] = set.motors[0];
        self.data.ctrl_mut()[ids.twine_act] = set.motors[1];
        match ids.arm_act {
            // Prescribed motion: the joint velocity that takes the actual angles to the next commanded
            // ones in this step (so nothing drifts). Writing qpos directly instead doubled the step time.
            None => {
                for k in 0..6 {
                    let actual = self.data.qpos()[ids.arm_qpos[k]];
                    self.data.qvel_mut()[ids.arm_dof[k]] = (set.arm_q[k] - actual) / dt;
                }
            }
            // The servos track the same interpolated setpoints, with the step's velocity fed forward
            // as a UR's joint controller does. Holding each tick's target as the servos' setpoint
            // instead made them chase a staircase (at the paper's 45 °/s, steps of 7.9 mrad every
            // 10 ms) and lag (kv + damping) / kp = 0.1 s behind a moving setpoint.
            Some(acts) => {
                for k in 0..6 {
                    let speed = (set.arm_q[k] - before[k]) / dt;
                    self.data.ctrl_mut()[acts[k]] = set.arm_q[k] + ids.arm_servo_lead_s[k] * speed;
                }
                self.compensate_payload();
            }
        }
        if let (Some(run), Some(ids)) = (self.produce.as_mut(), &self.shared.ids.produce) {
            run.apply_forces(ids, &mut self.data, t0, self.produce_push_n);
        }
        // After the inputs are set (the payload compensation reads this data's last kinematics),
        // so that a switch of model carries them over with the state.
        self.mj_step();
        if let Some(census) = self.census.as_mut() {
            census.record(&self.data, t0 + dt);
        }
        if let (Some(run), Some(ids), Some(part)) =
            (self.produce.as_mut(), &self.shared.ids.produce, &self.shared.produce)
        {
            run.record_damage(ids, &part.item, &self.shared.ids.geom_shapes, &self.data, dt);
        }
        self.check(t0 + dt)
    }

    fn count_contacts(&mut self) {
        self.census.get_or_insert_with(ContactCensus::default);
    }

    fn contact_census(&self) -> Option<ContactCensus> {
        self.census.clone()
    }

    fn contact_area_m2(&self) -> Option<f64> {
        Some(Scene::contact_area_m2(self))
    }

    fn set_object_force(&mut self, force_n: [f64; 3]) -> Result<(), PhysicsError> {
        if self.produce.is_some() {
            if let Some(bad) = force_n.iter().find(|f| !f.is_finite()) {
                return Err(PhysicsError::BadInput { what: "object push force", value: *bad });
            }
            // Shared by the flex's nodes in proportion to their mass (Scene::step applies it).
            self.produce_push_n = force_n;
            return Ok(());
        }
        let Some(body) = self.shared.ids.object_body else {
            return Err(PhysicsError::Config {
                key: "disturbance.push".into(),
                reason: "the scene has no object to push".into(),
            });
        };
        if let Some(bad) = force_n.iter().find(|f| !f.is_finite()) {
            return Err(PhysicsError::BadInput { what: "object push force", value: *bad });
        }
        // xfrc_applied: a Cartesian force and torque at the body's centre of mass, world frame.
        self.data.xfrc_applied_mut()[body] = [force_n[0], force_n[1], force_n[2], 0.0, 0.0, 0.0];
        Ok(())
    }

    fn readout(&self) -> PhysicsReadout {
        let ids = &self.shared.ids;
        let qpos = self.data.qpos();
        // A geom set's normal force on the object (a rigid body's geoms, or a produce item's flex).
        let on_object = |a: &[usize]| match &ids.produce {
            Some(p) => self.normal_force_on_flex(a, p.flex),
            None => self.normal_force_between(a, &ids.object_geoms),
        };
        let (pad_force_n, _) = on_object(&ids.pad_geoms);
        let mut extra_pad_forces_n = PerPad::filled(ids.extra_pad_geoms.len(), 0.0);
        for (f, geoms) in extra_pad_forces_n.as_mut_slice().iter_mut().zip(&ids.extra_pad_geoms) {
            *f = on_object(geoms).0;
        }
        let (grip_force_n, grip_contacts) = on_object(&ids.finger_geoms);
        let (palm_force_n, _) = on_object(&ids.palm_geom);
        let tool_load_n = Some(match &ids.produce {
            Some(p) => self.vertical_force_on_flex(&ids.hand_geoms, p.flex),
            None => self.vertical_force_on(&ids.hand_geoms, &ids.object_geoms),
        });
        let hand_p = Vector3::from(self.data.xpos()[ids.hand_body]);
        let hq = self.data.xquat()[ids.hand_body];
        let hand_rot = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(hq[0], hq[1], hq[2], hq[3]));
        let hand = Isometry3::from_parts(hand_p.into(), hand_rot);
        let mut r = PhysicsReadout {
            time_s: self.data.time(),
            pad_force_n,
            extra_pad_forces_n,
            grip_force_n,
            palm_force_n,
            grip_contacts,
            touching: grip_contacts > 0,
            tool_load_n,
            hand_pos_m: hand_p.into(),
            growth_m: qpos[ids.growth_qpos],
            twine_m: qpos[ids.twine_qpos],
            twine_setpoint_m: self.drive.twine_setpoint_m(),
            creep_m: qpos[ids.creep_qpos],
            tendon_tension_n: self.tendon_tension_n(),
            arm_q: match ids.arm_act {
                Some(_) => ids.arm_qpos.map(|a| qpos[a]),
                None => self.drive.arm_q(),
            },
            ..PhysicsReadout::default()
        };
        if let (Some(p), Some(run), Some(part)) = (&ids.produce, &self.produce, &self.shared.produce) {
            let centre = produce_run::centroid(p, &self.data);
            let v = produce_run::velocity(p, &self.data);
            let vh = self.data.object_velocity(_mjtObjBase::mjOBJ_BODY, ids.hand_body, false);
            let w_hand = Vector3::new(vh[0], vh[1], vh[2]);
            let v_obj = Vector3::from(v);
            let in_hand = grip_in_hand(&hand, Vector3::new(vh[3], vh[4], vh[5]), w_hand, Vector3::from(centre), v_obj);
            // The footprint centre, as a rigid object's body origin: the item's centre less its height.
            r.object_pos_m = [centre[0], centre[1], centre[2] - part.item.radii_m[2]];
            r.object_quat = [1.0, 0.0, 0.0, 0.0];
            r.object_vel_m_s = v;
            r.slip_speed_m_s = in_hand.slip_speed_m_s;
            r.object_in_hand_m = in_hand.position_m;
            let bump_force_n = self.normal_force_on_flex(&ids.pad_geoms[1..2], p.flex).0;
            r.produce = Some(produce_run::ProduceReadout { bump_force_n, ..run.readout() });
        }
        if let (Some(body), Some(grip)) = (ids.object_body, ids.object_grip) {
            r.object_pos_m = self.data.xpos()[body];
            r.object_quat = self.data.xquat()[body];
            let p = Vector3::from(self.data.geom_xpos()[grip]);
            let vo = self.data.object_velocity(_mjtObjBase::mjOBJ_GEOM, grip, false);
            let vh = self.data.object_velocity(_mjtObjBase::mjOBJ_BODY, ids.hand_body, false);
            let v_obj = Vector3::new(vo[3], vo[4], vo[5]);
            let w_hand = Vector3::new(vh[0], vh[1], vh[2]);
            let in_hand = grip_in_hand(&hand, Vector3::new(vh[3], vh[4], vh[5]), w_hand, p, v_obj);
            r.object_vel_m_s = v_obj.into();
            r.slip_speed_m_s = in_hand.slip_speed_m_s;
            r.object_in_hand_m = in_hand.position_m;
        }
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_can_move_to_other_threads_and_share_the_model() {
        fn send<T: Send>() {}
        fn send_sync<T: Send + Sync>() {}
        send::<Scene>();
        send_sync::<SceneModel>();
    }
}
