//! What the scene needs to know of an object, read from its model file and nowhere else.
//!
//! An object file (models/objects/*.xml) is a standalone MJCF that keeps one contract: a body
//! `object` whose first joint is a free joint, a geom `object_base` it stands on, a vertical
//! capsule or cylinder `object_grip` the finger wraps, and a site `object_wrap` at the height where
//! the wrap starts. [`ObjectModel::from_mjcf`] compiles the file on its own, checks the contract
//! and reads the mass, the grip radius and the wrap height from the compiled model, so a value is
//! written once, in the file.
//!
//! A produce item is an object file of its own kind, a flex ([`super::produce`]): read here too,
//! its mass and size taken from the flex, its wrap height from its centre.

use super::PhysicsError;
use mujoco_rs::mujoco_c::{_mjtGeomBase, _mjtObjBase, mjtJoint};
use mujoco_rs::prelude::MjModel;

/// An object's model text and the figures the scene places it by.
#[derive(Debug, Clone, PartialEq)]
pub struct ObjectModel {
    /// Where the text came from (a shipped object's name or a file), for messages.
    pub source: String,
    /// The MJCF document.
    pub mjcf: String,
    /// Mass of the body `object` and everything below it \[kg\].
    pub mass_kg: f64,
    /// Radius of `object_grip` \[m\].
    pub grip_radius_m: f64,
    /// Height of the site `object_wrap` above the body origin (the footprint centre) \[m\].
    pub wrap_height_m: f64,
    /// The produce item, when the file is one (its figures above are the flex's: the grip radius
    /// its horizontal semi-axis, the wrap's height above its lowest point).
    pub produce: Option<super::produce::ProduceItem>,
}

impl ObjectModel {
    /// Compiles `mjcf` (from `source`), checks the object contract and reads its figures. A broken
    /// file is a [`PhysicsError::Object`] naming the source and what is wrong.
    ///
    /// Asset files the text names (`<mesh file="...">`) are relative to `dir`, the object file's
    /// folder; they are made absolute here, so the scene that includes the object finds them
    /// wherever it runs.
    pub fn from_mjcf(source: &str, mjcf: &str) -> Result<ObjectModel, PhysicsError> {
        Self::from_mjcf_in(source, mjcf, None)
    }

    /// As [`ObjectModel::from_mjcf`], for a file in `dir`.
    pub fn from_mjcf_in(source: &str, mjcf: &str, dir: Option<&std::path::Path>) -> Result<ObjectModel, PhysicsError> {
        let text = match dir {
            Some(dir) => absolute_files(mjcf, dir),
            None => mjcf.to_string(),
        };
        let mjcf = text.as_str();
        if super::produce::is_produce(mjcf) {
            let item = super::produce::ProduceItem::read(source, mjcf)?;
            return Ok(ObjectModel {
                source: source.to_string(),
                mjcf: mjcf.to_string(),
                mass_kg: item.mass_kg,
                grip_radius_m: item.grip_radius_m(),
                wrap_height_m: item.radii_m[2] + item.wrap_m,
                produce: Some(item),
            });
        }
        let broken = |what: String| PhysicsError::Object { file: source.to_string(), what };
        let m = MjModel::from_xml_string(mjcf).map_err(|e| broken(format!("MuJoCo cannot compile it: {e:?}")))?;
        let find = |kind, kind_name: &str, name: &str| {
            m.name_to_id(kind, name).ok_or_else(|| broken(format!("no {kind_name} named `{name}`")))
        };
        let body = find(_mjtObjBase::mjOBJ_BODY, "body", "object")?;
        let free = m.body_jntnum()[body] >= 1 && m.jnt_type()[m.body_jntadr()[body] as usize] == mjtJoint::mjJNT_FREE;
        if !free {
            return Err(broken("the body `object` needs a free joint (<freejoint/>) to be picked up".into()));
        }
        let mine = |b: usize| b == body;
        let base = find(_mjtObjBase::mjOBJ_GEOM, "geom", "object_base")?;
        let grip = find(_mjtObjBase::mjOBJ_GEOM, "geom", "object_grip")?;
        let wrap = find(_mjtObjBase::mjOBJ_SITE, "site", "object_wrap")?;
        for (what, b) in [
            ("geom `object_base`", m.geom_bodyid()[base]),
            ("geom `object_grip`", m.geom_bodyid()[grip]),
            ("site `object_wrap`", m.site_bodyid()[wrap]),
        ] {
            if !mine(b as usize) {
                return Err(broken(format!("the {what} must belong to the body `object`")));
            }
        }
        if !matches!(m.geom_type()[grip], _mjtGeomBase::mjGEOM_CAPSULE | _mjtGeomBase::mjGEOM_CYLINDER) {
            return Err(broken(format!(
                "the geom `object_grip` must be a capsule or a cylinder (the finger wraps a round grip), not {:?}",
                m.geom_type()[grip]
            )));
        }
        let mass_kg = m.body_subtreemass()[body];
        if !(mass_kg > 0.0 && mass_kg.is_finite()) {
            return Err(broken(format!("the body `object` has no mass ({mass_kg} kg)")));
        }
        Ok(ObjectModel {
            source: source.to_string(),
            mjcf: mjcf.to_string(),
            mass_kg,
            grip_radius_m: m.geom_size()[grip][0],
            wrap_height_m: m.site_pos()[wrap][2],
            produce: None,
        })
    }
}

/// `mjcf` with every relative `file="..."` attribute taken from `dir`.
fn absolute_files(mjcf: &str, dir: &std::path::Path) -> String {
    const ATTR: &str = " file=\"";
    let mut out = String::with_capacity(mjcf.len());
    let mut rest = mjcf;
    while let Some(at) = rest.find(ATTR) {
        let start = at + ATTR.len();
        let Some(len) = rest[start..].find('"') else { break };
        let value = &rest[start..start + len];
        out.push_str(&rest[..start]);
        if std::path::Path::new(value).is_relative() {
            out.push_str(&dir.join(value).display().to_string());
        } else {
            out.push_str(value);
        }
        rest = &rest[start + len..];
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"<mujoco><worldbody><body name="object">
        <freejoint/><site name="object_wrap" pos="0 0 0.08"/>
        <geom name="object_base" type="box" size="0.02 0.02 0.01" pos="0 0 0.01" mass="0.2"/>
        <geom name="object_grip" type="cylinder" size="0.015 0.05" pos="0 0 0.07" mass="0.1"/>
    </body></worldbody></mujoco>"#;

    #[test]
    fn reads_mass_radius_and_wrap_height_from_the_file() {
        let o = ObjectModel::from_mjcf("good.xml", GOOD).unwrap();
        assert!((o.mass_kg - 0.3).abs() < 1e-12);
        assert_eq!(o.grip_radius_m, 0.015);
        assert_eq!(o.wrap_height_m, 0.08);
    }

    #[test]
    fn relative_asset_files_are_taken_from_the_object_folder() {
        let text = r#"<mesh name="a" file="meshes/a.obj"/><mesh name="b" file="/abs/b.stl"/>"#;
        assert_eq!(
            absolute_files(text, std::path::Path::new("/lab/objects")),
            r#"<mesh name="a" file="/lab/objects/meshes/a.obj"/><mesh name="b" file="/abs/b.stl"/>"#
        );
    }

    #[test]
    fn a_broken_contract_names_the_file_and_what_is_missing() {
        let cases = [
            (GOOD.replace("<freejoint/>", ""), "free joint"),
            (GOOD.replace("name=\"object_grip\"", "name=\"handle\""), "object_grip"),
            (GOOD.replace("name=\"object_base\"", "name=\"foot\""), "object_base"),
            (GOOD.replace("name=\"object_wrap\"", "name=\"w\""), "object_wrap"),
            (GOOD.replace("name=\"object\"", "name=\"thing\""), "body named `object`"),
            (
                GOOD.replace("type=\"cylinder\" size=\"0.015 0.05\"", "type=\"box\" size=\"0.015 0.015 0.05\""),
                "capsule or a cylinder",
            ),
            (GOOD.replace("<mujoco>", "<mujoco><oops>"), "cannot compile"),
        ];
        for (text, what) in cases {
            let e = ObjectModel::from_mjcf("mine.xml", &text).unwrap_err().to_string();
            assert!(e.contains("mine.xml") && e.contains(what), "{what}: {e}");
        }
    }
}
