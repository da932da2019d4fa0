//! The assembled scene as one self-contained MJCF that MuJoCo's own tools open
//! (`python -m mujoco.viewer --mjcf scene.xml`): every template field filled, and what
//! [`SceneModel::build`] applies to the compiled model written into the text instead (the object's
//! start pose and yaw on the table, grip-friction and mass overrides, the kinematic arm's armature), plus a
//! keyframe `start` holding the start state (arm at its home angles, finger retracted, object
//! standing where the run starts it). A produce item's flex is in the text as the run builds it
//! (its elasticity and calibrated contact included); a harvest's stem is not, since the run
//! applies it as a force of its own (`produce_run`).
//!
//! The export checks itself: the text is compiled again and its model must match the one the runs
//! use in every value the edits touch, so a model file the edits do not recognise is an error, not
//! a silently different scene.

use super::scene::{KINEMATIC_ARM_ARMATURE, yaw_quaternion};
use super::template::{num, nums};
use super::{ArmMode, PhysicsError, Scene, SceneModel};
use mujoco_rs::prelude::MjModel;
use std::sync::Arc;

/// The arm's joints, as named in models/ur5e.xml.
const ARM_JOINTS: [&str; 6] = ["shoulder_pan", "shoulder_lift", "elbow", "wrist_1", "wrist_2", "wrist_3"];

/// The standalone MJCF of `model`'s scene (see the module docs).
pub fn standalone_xml(model: &Arc<SceneModel>) -> Result<String, PhysicsError> {
    let spec = model.spec();
    let mut xml = model.xml().to_string();
    // A produce item's flex is written where it starts, with its mass and friction, by the
    // scene itself (its frame's `pos`); only a rigid object's body needs the edits.
    if model.produce().is_none()
        && let (Some(obj), Some(p)) = (&spec.object, model.placement().object)
    {
        xml = set_attribute(&xml, "<body name=\"object\"", "pos", &nums(&[p.x, p.y, p.z]))?;
        if let Some(yaw) = obj.yaw_deg {
            xml = set_attribute(&xml, "<body name=\"object\"", "quat", &nums(&yaw_quaternion(yaw)))?;
        }
        if obj.mass_kg.is_some() {
            // The scaled mass and inertia as the body's explicit inertial (it wins over the geoms').
            let m = model.model();
            let body = m
                .name_to_id(mujoco_rs::mujoco_c::_mjtObjBase::mjOBJ_BODY, "object")
                .ok_or(PhysicsError::Missing { kind: "body", name: "object".into() })?;
            let inertial = format!(
                "<inertial pos=\"{}\" quat=\"{}\" mass=\"{}\" diaginertia=\"{}\"/>",
                nums(&m.body_ipos()[body]),
                nums(&m.body_iquat()[body]),
                num(m.body_mass()[body]),
                nums(&m.body_inertia()[body])
            );
            let at = xml.find("<body name=\"object\"").and_then(|s| xml[s..].find('>').map(|e| s + e + 1));
            let at = at.ok_or_else(|| PhysicsError::Compile { message: "export: no body `object`".into() })?;
            xml.insert_str(at, &format!("\n      {inertial}"));
        }
        if let Some(mu) = obj.friction {
            let grip =
                ids_grip(model.model()).ok_or(PhysicsError::Missing { kind: "geom", name: "object_grip".into() })?;
            let f = model.model().geom_friction()[grip];
            xml = set_attribute(&xml, "<geom name=\"object_grip\"", "friction", &nums(&[mu, f[1], f[2]]))?;
        }
    }
    if spec.physics.arm_mode == ArmMode::Kinematic {
        for joint in ARM_JOINTS {
            xml = set_attribute(&xml, &format!("<joint name=\"{joint}\""), "armature", &num(KINEMATIC_ARM_ARMATURE))?;
        }
    }
    let start = Scene::new(model.clone());
    let key = format!(
        "  <keyframe>\n    <key name=\"start\" time=\"0\" qpos=\"{}\"/>\n  </keyframe>\n</mujoco>",
        nums(start.data().qpos())
    );
    let xml =
        xml.trim_end().strip_suffix("</mujoco>").map(|head| format!("{head}{key}\n")).ok_or_else(|| {
            PhysicsError::Compile { message: "the assembled scene does not end with </mujoco>".into() }
        })?;
    check_same(model.model(), &xml)?;
    Ok(xml)
}

fn ids_grip(m: &MjModel) -> Option<usize> {
    m.name_to_id(mujoco_rs::mujoco_c::_mjtObjBase::mjOBJ_GEOM, "object_grip")
}

/// Sets `attr="value"` on the first element that starts with `element` (replacing the attribute
/// if the element has it).
fn set_attribute(xml: &str, element: &str, attr: &str, value: &str) -> Result<String, PhysicsError> {
    let missing = || PhysicsError::Compile { message: format!("export: no element `{element} ...>` in the scene") };
    let start = xml.find(element).ok_or_else(missing)?;
    let end = start + xml[start..].find('>').ok_or_else(missing)?;
    let tag = &xml[start..end];
    let needle = format!(" {attr}=\"");
    let new_tag = match tag.find(&needle) {
        Some(a) => {
            let v = a + needle.len();
            let close = v + tag[v..].find('"').ok_or_else(missing)?;
            format!("{}{value}{}", &tag[..v], &tag[close..])
        }
        None => {
            let (body, slash) = tag.strip_suffix('/').map_or((tag, ""), |b| (b, "/"));
            format!("{body} {attr}=\"{value}\"{slash}")
        }
    };
    Ok(format!("{}{new_tag}{}", &xml[..start], &xml[end..]))
}

/// Compiles `xml` and compares it with the model the runs use where the export edited the text.
fn check_same(used: &MjModel, xml: &str) -> Result<(), PhysicsError> {
    let exported = MjModel::from_xml_string(xml)
        .map_err(|e| PhysicsError::Compile { message: format!("the exported scene: {e:?}") })?;
    let differs =
        |what: &str| PhysicsError::Compile { message: format!("the exported scene differs from the run's in {what}") };
    if exported.qpos0() != used.qpos0() {
        return Err(differs("qpos0 (start pose)"));
    }
    if exported.geom_friction() != used.geom_friction() {
        return Err(differs("geom friction"));
    }
    if exported.body_mass() != used.body_mass() || exported.body_inertia() != used.body_inertia() {
        return Err(differs("body mass or inertia"));
    }
    if exported.dof_armature() != used.dof_armature() {
        return Err(differs("joint armature"));
    }
    if exported.ffi().nkey != 1 {
        return Err(differs("keyframes"));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sets_or_adds_an_attribute_on_the_named_element_only() {
        let xml = r#"<a><joint name="x" armature="0.1" damping="2"/><joint name="y"/></a>"#;
        assert_eq!(
            set_attribute(xml, "<joint name=\"x\"", "armature", "1000").unwrap(),
            r#"<a><joint name="x" armature="1000" damping="2"/><joint name="y"/></a>"#
        );
        assert_eq!(
            set_attribute(xml, "<joint name=\"y\"", "armature", "5").unwrap(),
            r#"<a><joint name="x" armature="0.1" damping="2"/><joint name="y" armature="5"/></a>"#
        );
        assert!(set_attribute(xml, "<joint name=\"z\"", "armature", "5").is_err());
    }
}
