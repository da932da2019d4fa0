//! Assembles a scene's MJCF from the parts in models/ and the scenario's values.

use super::bump::{self, BumpCalibration, PadShape};
use super::config::{ArmMode, Backend, FingerConfig, Integrator};
use super::follow_camera;
pub use super::header::header;
use super::object::ObjectModel;
use super::plates::{self, Calibration};
use super::produce::ProduceItem;
use super::template::{num, nums, render, section};
use super::{PadPlace, PhysicsError, SceneSpec};
use nalgebra::{Isometry3, Point3, Vector3};
use std::path::Path;
use tendril_ur5e::kinematics as ur5e;

/// The scene's parts as built into the binary: the fallback when no models folder is given.
const BUILT_IN: [(&str, &str); 5] = [
    ("finger.xml", include_str!("../../../../models/finger.xml")),
    ("finger_segment.xml", include_str!("../../../../models/finger_segment.xml")),
    ("sensor_pad.xml", include_str!("../../../../models/sensor_pad.xml")),
    ("ur5e.xml", include_str!("../../../../models/ur5e.xml")),
    ("table.xml", include_str!("../../../../models/table.xml")),
];

/// The text of the part `name`: read from `dir` when given (so an edited `models/finger.xml` takes
/// effect on the next run, no rebuild), else the built-in copy.
fn part(dir: Option<&Path>, name: &str) -> Result<String, PhysicsError> {
    match dir {
        Some(dir) => {
            let file = dir.join(name);
            std::fs::read_to_string(&file)
                .map_err(|e| PhysicsError::Part { file: file.display().to_string(), cause: e.to_string() })
        }
        None => Ok(BUILT_IN.iter().find(|(n, _)| *n == name).map(|(_, text)| text.to_string()).unwrap_or_default()),
    }
}

/// Height of the pad's bump tip above the casing's base \[m\]: 4 mm casing + 1.5 mm bump (sensor_pad.xml).
pub const PAD_HEIGHT_M: f64 = 0.0055;
/// Clearance between the grown, straight strip's bump and the object \[m\], so growing does not push it.
pub const GROW_CLEARANCE_M: f64 = 0.001;
/// Gap between the object and the palm at the start \[m\]: touching (0.2 mm), so the wrap presses it on
/// the palm from the start instead of dragging it there part-way through tightening (which shifted the
/// load off the pad by ~10 %).
pub const PALM_GAP_M: f64 = 0.0002;

/// Tightest radius the strip may curl to \[m\] (each joint's upper limit is segment length / this,
/// so the limit is a curvature, the same at any number of links). A stated choice: 8.75 mm, 2 rad
/// per joint at 8 links as calibrated; tighter than every object's grip (12-14 mm), so it only
/// stops the free tip curling onto itself.
pub const MIN_CURL_RADIUS_M: f64 = 0.00875;
/// Tightest radius the strip may bend backwards to \[m\] (joint lower limit = segment length /
/// this). A stated choice: 58.3 mm, 0.3 rad per joint at 8 links as calibrated; the strip is
/// curled by a tendon on one side and never bends far the other way.
pub const MIN_BACK_RADIUS_M: f64 = 0.0175 / 0.3;

/// The segment template without its `<joint .../>` element: a segment welded to its parent.
fn without_joint(segment: &str) -> String {
    match segment.find("<joint").and_then(|start| segment[start..].find("/>").map(|end| (start, start + end + 2))) {
        Some((start, end)) => format!("{}{}", &segment[..start], &segment[end..]),
        None => segment.to_string(),
    }
}

/// A per-joint value derived from a per-length one, to 12 significant digits: the division and
/// powers leave noise in the last bits (2e-4 came out as 1.9999999999999998e-4), and the grasp is
/// sensitive enough that such a bit moved the crimper's rise time by 0.8 s; rounded, the default
/// 8-link finger gets exactly the per-joint values it was calibrated with.
fn per_joint(x: f64) -> f64 {
    format!("{x:.11e}").parse().unwrap_or(x)
}

/// A model file without its leading comment (whose prose names the template's fields).
fn body_of(text: &str) -> &str {
    text.split_once("-->").map_or(text, |(_, rest)| rest)
}

/// The finger part (hand, motors, strip, pad) with its tendons, actuators and sensor, as a full MJCF
/// document whose hand body goes into the arm's flange.
/// With `extra_pads`, further sensor pads (a sensor array) sit on the strip, each a copy of
/// `sensor_pad.xml` whose names carry its number (`pad1_casing`, ...).
pub fn finger(f: &FingerConfig, extra_pads: &[PadPlace], models: Option<&Path>) -> Result<String, PhysicsError> {
    let (finger_text, segment_text, pad_text) =
        (part(models, "finger.xml")?, part(models, "finger_segment.xml")?, part(models, "sensor_pad.xml")?);
    let pieces = super::strip::layout_with_pads(f, &PadPlace::arcs(extra_pads));
    let r = f.thickness_m / 2.0;
    let pad_at = |centre: f64, protrusion_m: f64| -> Result<(usize, String), PhysicsError> {
        let seg = super::strip::pad_piece(&pieces, centre);
        // How far the pad sits lower than standing on the strip's face (<= 0: recessed into the sleeve).
        let sink = protrusion_m - PAD_HEIGHT_M;
        let xml = render(
            body_of(&pad_text),
            &[
                ("x", num(centre - pieces[seg].start_m)),
                ("r", num(r)),
                ("casing_y", num(r + 0.002 + sink)),
                ("bump_y", num(r + 0.004 + sink)),
                ("site_y", num(r + 0.005 + sink)),
            ],
        )?;
        Ok((seg, xml))
    };
    let mut pads = vec![pad_at(f.pad_position_m, f.pad_protrusion_m)?];
    for (k, p) in extra_pads.iter().enumerate() {
        let (seg, xml) = pad_at(p.arc_m, p.protrusion_m)?;
        pads.push((seg, xml.replace("name=\"pad_", &format!("name=\"pad{}_", k + 1))));
    }
    let pads_on = |i: usize| pads.iter().filter(|(seg, _)| *seg == i).map(|(_, xml)| xml.as_str()).collect::<String>();
    let segment_body = body_of(&segment_text);
    let rigid_body = without_joint(segment_body);
    // A joint between two rigid pieces stands for no strip: the pieces are welded.
    let bends = |p: &super::strip::Piece| p.joint_span_m > 0.0;
    let mut chain = String::new();
    for (i, piece) in pieces.iter().enumerate().rev() {
        let previous = if i == 0 { 0.0 } else { pieces[i - 1].length_m };
        let span = piece.joint_span_m;
        let l = piece.length_m;
        chain = render(
            if bends(piece) { segment_body } else { &rigid_body },
            &[
                ("i", i.to_string()),
                ("x", num(previous)),
                // Helix: each segment one step towards the flange (-z in the hand frame).
                ("z", num(-f.helix_slope * previous)),
                ("k_bend", num(per_joint(f.bending_stiffness_n_m2 / span))),
                ("d_bend", num(per_joint(f.bending_damping_n_m2_s / span))),
                ("a_bend", num(per_joint(f.bending_armature_kg_m3 / span))),
                ("min_curl", num(-per_joint(span / MIN_BACK_RADIUS_M))),
                ("max_curl", num(per_joint(span / MIN_CURL_RADIUS_M))),
                ("half_len", num(l / 2.0)),
                ("half_width", num(f.width_m / 2.0)),
                ("radius", num(r)),
                ("mass", num(f.density_kg_m3 * l * f.width_m * f.thickness_m)),
                ("pad", pads_on(i)),
                ("child", chain),
            ],
        )?;
    }
    let curl_terms: String = (0..pieces.len())
        .filter(|&i| bends(&pieces[i]))
        .map(|i| {
            let arm = f.moment_arm_m * (-f.tendon_tension_decay_per_m * pieces[i].start_m).exp();
            format!("<joint joint=\"curl{i}\" coef=\"{}\"/>\n      ", num(per_joint(arm)))
        })
        .collect();
    let k = f.tendon_stiffness_n_m;
    let k_elastic = f.relaxed_fraction * k;
    let k_maxwell = (1.0 - f.relaxed_fraction) * k;
    // The dashpot's node needs some inertia; 1e-3 kg keeps its own time constant (m / c) far below tau.
    let creep_damping = f.relaxation_time_s * k_maxwell.max(1e-9);
    render(
        body_of(&finger_text),
        &[
            ("exit_z", num(f.exit_z_m)),
            ("length", num(f.length_m)),
            ("moment_arm", num(f.moment_arm_m)),
            ("segments", chain),
            ("motor_armature", num(f.motor_armature_kg)),
            ("twine_range", nums(&[0.0, f.twine_max_m])),
            ("growth_range", nums(&[0.0, f.length_m])),
            ("creep_damping", num(creep_damping)),
            ("creep_armature", num(1e-3)),
            ("root_x", num(-f.length_m)),
            ("half_length", num(f.length_m / 2.0)),
            ("guide_x", num(-f.length_m / 2.0)),
            ("guide_half_width", num(f.width_m / 2.0 + 0.002 + f.helix_slope * f.length_m)),
            ("wall_y", num(r + 0.0012)),
            ("k_elastic", num(k_elastic)),
            ("k_maxwell", num(k_maxwell)),
            ("curl_terms", curl_terms),
            ("motor_kp", num(f.motor_kp_n_m)),
            ("motor_kv", num(f.motor_kv_n_s_m)),
        ],
    )
}

/// How far below a harvested item the bench stands \[m\]: 0.25 m, clear of the item and the
/// finger while the arm pulls the item down off its plant (a stated choice of the harvest's
/// layout: the item hangs from its plant, nothing under it).
pub const HARVEST_BENCH_DROP_M: f64 = 0.25;

/// A produce item in a scene: the item as the scenario configures it, and its flex's calibration.
#[derive(Debug, Clone, PartialEq)]
pub struct ProducePart {
    /// The item, `[produce]` and `[object]` overrides applied.
    pub item: ProduceItem,
    /// The contact stiffness that meets Hertz in the plate test ([`plates::calibrate`]).
    pub calibration: Calibration,
    /// The pad's bump's own contact with the item, meeting Hertz for the bump's radius
    /// ([`bump::calibrate`]).
    pub bump: BumpCalibration,
}

/// Where the scene's parts stand at the start, in the world frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Placement {
    /// Tool-flange (= hand frame) pose at the start arm configuration.
    pub hand: Isometry3<f64>,
    /// Object footprint centre (its body origin) \[m\]; `None` when the scene has no object.
    pub object: Option<Vector3<f64>>,
    /// Height of the table plane \[m\].
    pub table_z: f64,
}

/// Computes the start placement: the hand from forward kinematics of the start joint angles; the
/// object (unless its position is given; its grip radius and wrap height from its model) against the palm ([`PALM_GAP_M`]) and so far beside the strip
/// that the growing strip's pad passes it with [`GROW_CLEARANCE_M`] to spare; the table under
/// the object so that the strip's plane crosses the middle of the grip.
pub fn placement(spec: &SceneSpec, object: Option<&ObjectModel>) -> Placement {
    let hand = ur5e::forward(&spec.arm_q0);
    let f = &spec.finger;
    let (Some(obj), Some(model)) = (&spec.object, object) else {
        return Placement { hand, object: None, table_z: 0.0 };
    };
    let radius = model.grip_radius_m;
    let y = f.thickness_m / 2.0 + f.pad_protrusion_m + GROW_CLEARANCE_M + radius;
    let wrap = hand * Point3::new(radius + PALM_GAP_M, y, f.exit_z_m);
    let base_z = wrap.z - model.wrap_height_m;
    let (x, y) = match obj.position_m {
        Some([x, y]) => (x, y),
        None => (wrap.x, wrap.y),
    };
    let harvest = model.produce.is_some() && spec.produce.harvest;
    let table_z = if harvest { base_z - HARVEST_BENCH_DROP_M } else { base_z };
    Placement { hand, object: Some(Vector3::new(x, y, base_z)), table_z }
}

/// The produce item of `spec` as its scenario configures it, calibrated: refused on the rapier
/// backend (it has no flex) and with an integrator that does not integrate a flex's elasticity.
fn produce_part(spec: &SceneSpec, raw: &ProduceItem, pad: &PadShape) -> Result<ProducePart, PhysicsError> {
    if spec.physics.backend == Backend::Rapier {
        return Err(PhysicsError::Unsupported {
            backend: "rapier",
            what: format!("the produce item {} (a MuJoCo flex); use physics.backend = \"mujoco\"", raw.source),
        });
    }
    if matches!(spec.physics.integrator, Integrator::Implicit | Integrator::Implicitfast) {
        return Err(PhysicsError::Config {
            key: "physics.integrator".into(),
            reason: "a produce item's flex needs \"discrete\" (or \"euler\"): MuJoCo 3.17 integrates flex \
                     elasticity implicitly only in the discrete integrator"
                .into(),
        });
    }
    let object = spec.object.as_ref();
    let item = raw.configured(&spec.produce, object.and_then(|o| o.mass_kg), object.and_then(|o| o.friction))?;
    let calibration = plates::calibrate(&item, &spec.physics)?;
    let bump = bump::calibrate(&item, &spec.physics, pad, calibration.contact(&spec.physics))?;
    Ok(ProducePart { item, calibration, bump })
}

/// The full scene MJCF for `spec`, where its parts start, and its produce item if it has one.
pub fn scene(spec: &SceneSpec) -> Result<(String, Placement, Option<ProducePart>), PhysicsError> {
    let models = spec.physics.models_dir.as_deref();
    let object = spec.object.as_ref().map(|o| o.model()).transpose()?;
    let place = placement(spec, object.as_ref());
    let mut worldbody = String::new();
    let mut actuator = String::new();
    let mut tendon = String::new();
    let mut sensor = String::new();
    // The object's assets (meshes), with their files already made absolute by ObjectModel.
    let mut asset = object.as_ref().map_or("", |o| section(&o.mjcf, "asset")).to_string();
    // How the scene looks (sky, the table's pattern, the headlight): table.xml's <asset> and
    // <visual>, which only pictures use.
    let mut visual = String::new();

    let mut produce = None;
    if spec.object.is_some() {
        let table = part(models, "table.xml")?.replace("pos=\"0 0 0\"", &format!("pos=\"0 0 {}\"", num(place.table_z)));
        worldbody.push_str(section(&table, "worldbody"));
        asset.push_str(section(&table, "asset"));
        visual.push_str(section(&table, "visual"));
        match (object.as_ref().and_then(|o| o.produce.as_ref()), place.object) {
            (Some(raw), Some(foot)) => {
                let pad = PadShape::read(&part(models, "sensor_pad.xml")?)?;
                let p = produce_part(spec, raw, &pad)?;
                // The item's centre stands its height above its footprint, in a static frame its
                // flex's nodes slide in.
                let centre = [foot.x, foot.y, foot.z + p.item.radii_m[2]];
                worldbody.push_str(&format!(
                    "\n    <body name=\"produce_frame\" pos=\"{}\">{}</body>\n",
                    nums(&centre),
                    section(&p.item.document(p.calibration.contact(&spec.physics)), "worldbody")
                ));
                produce = Some(p);
            }
            _ => worldbody.push_str(section(object.as_ref().map_or("", |o| o.mjcf.as_str()), "worldbody")),
        }
    }
    // The hand rides on the arm's flange in both modes; the kinematic mode prescribes the joints'
    // motion (Scene::step) instead of driving them with servos, so it has no arm actuators.
    let mut finger_doc = finger(&spec.finger, &spec.extra_pads, models)?;
    if let Some(p) = &produce {
        // The pads' bumps meet the item with their own calibrated contact (bump.rs says why a
        // higher priority on the geom is how); a rigid object's scene is left as it was.
        finger_doc = bump::with_bump_contact(&finger_doc, &bump::bump_attrs(&p.item, p.bump.contact(&spec.physics)));
    }
    // The `follow` camera (follow_camera.rs): aimed at a rigid object's body, or through the hand
    // at a produce item (its flex has no body of its own); none without an object.
    let camera = match (object.as_ref(), place.object) {
        (Some(o), Some(foot)) => {
            let target = if produce.is_some() { "hand" } else { "object" };
            follow_camera::element([foot.x, foot.y, foot.z + o.wrap_height_m], spec.arm_q0[0], target)
        }
        _ => String::new(),
    };
    let arm = render(
        &part(models, "ur5e.xml")?,
        &[("hand", section(&finger_doc, "worldbody").to_string()), ("camera", camera)],
    )?;
    worldbody.push_str(section(&arm, "worldbody"));
    if spec.physics.arm_mode == ArmMode::Dynamic {
        actuator.push_str(section(&arm, "actuator"));
    }
    actuator.push_str(section(&finger_doc, "actuator"));
    tendon.push_str(section(&finger_doc, "tendon"));
    sensor.push_str(section(&finger_doc, "sensor"));

    let xml = format!(
        "<mujoco model=\"tendril_cell\">\n  {header}\n  <visual>{visual}</visual>\n  <asset>{asset}</asset>\n  <worldbody>{worldbody}</worldbody>\n  \
         <tendon>{tendon}</tendon>\n  <actuator>{actuator}</actuator>\n  \
         <sensor>{sensor}</sensor>\n</mujoco>\n",
        header = header(&spec.physics),
    );
    Ok((xml, place, produce))
}
