//! The sensor pad's bump against a produce item: a contact stiffness of its own, calibrated
//! against Hertz for the bump's radius as the plates' ([`super::plates`]) is for the item's size.
//!
//! Why the bump needs its own: MuJoCo's direct `solref` is a stiffness per contact. The plate
//! calibration sets it so that the many element contacts of a flat plate meet Hertz; the bump, a
//! 1.5 mm sphere, makes one to six contacts with the flex, so the plates' stiffness says nothing
//! about how far the same force sinks the bump. Calibrated on its own, the bump's stiffness comes
//! out 3-10 times lower than the plates' (`docs/studies/produce.md#the-pads-bump-on-soft-produce`).
//!
//! The mechanism: MuJoCo mixes the contact parameters of a geom and a flex (`mj_contactParam`,
//! "Contact parameters" in its documentation;
//! `docs/facts.md#mujoco-mixes-a-geoms-and-a-flexs-contact-parameters`): with equal `priority`
//! two direct `solref`s give the
//! elementwise minimum and the frictions the larger, with different priorities the higher one's
//! `condim`, `solref`, `solimp` and friction are taken whole. `<pair>` cannot name a flex. So in a
//! produce scene the bump geoms get a priority one above the flex's, this calibration's `solref`,
//! the cell's `solimp`, and the flex's own friction and `condim` (so the pair's friction is the
//! item's, as it was). Only produce scenes are edited: a rigid object's scene is unchanged.
//!
//! The calibration: the item alone between two rigid spheres of the bump's radius closing along x
//! at the plates' speed ([`super::plates::PLATE_SPEED_M_S`]), each contact approaching by half the
//! travel, against Hertz's point contact of the effective radius `1/(1/r_bump + κ_item)` and the
//! item's contact modulus (the bump's TPU, tens of MPa, is rigid beside the flesh's 0.05-0.5 MPa).
//! The reference force is where Hertz's bump has sunk half its own height
//! ([`reference_force_n`]): the middle of the range over which the bump alone carries the pad's
//! force, at most [`super::plates::REFERENCE_FORCE_N`].

use super::PhysicsError;
use super::config::PhysicsConfig;
use super::hertz;
use super::plates::{self, PlateSample, REFERENCE_FORCE_N, Squeezed, critical, search_stiffness};
use super::produce::{ProduceItem, attr, with_attr};
use super::template::num;

/// The pad's shape as its model file (`sensor_pad.xml`) gives it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PadShape {
    /// Radius of the bump's sphere \[m\]; it stands that far out of the casing's face (its centre
    /// on the face).
    pub bump_radius_m: f64,
    /// Half-sizes of the casing's box \[m\]: along the strip, out of its face (height), across.
    pub casing_half_m: [f64; 3],
}

impl PadShape {
    /// Reads the `pad_bump` sphere's and the `pad_casing` box's sizes from the pad's model file.
    pub fn read(pad_mjcf: &str) -> Result<PadShape, PhysicsError> {
        let size = |name: &str| -> Result<Vec<f64>, PhysicsError> {
            let key = format!("name=\"{name}\"");
            let at = pad_mjcf
                .find(&key)
                .ok_or_else(|| PhysicsError::Part { file: "sensor_pad.xml".into(), cause: format!("no geom {key}") })?;
            let start = pad_mjcf[..at].rfind('<').unwrap_or(0);
            let end = at + pad_mjcf[at..].find('>').unwrap_or(pad_mjcf.len() - at);
            attr(&pad_mjcf[start..end], "size")
                .map(|s| s.split_whitespace().filter_map(|x| x.parse().ok()).collect())
                .ok_or_else(|| PhysicsError::Part {
                    file: "sensor_pad.xml".into(),
                    cause: format!("geom {key} has no size"),
                })
        };
        let bump = size("pad_bump")?;
        let casing = size("pad_casing")?;
        match (bump.first(), <[f64; 3]>::try_from(casing)) {
            (Some(&r), Ok(c)) if r > 0.0 && c.iter().all(|x| *x > 0.0) => {
                Ok(PadShape { bump_radius_m: r, casing_half_m: c })
            }
            _ => Err(PhysicsError::Part {
                file: "sensor_pad.xml".into(),
                cause: "pad_bump needs a positive radius and pad_casing three positive half-sizes".into(),
            }),
        }
    }
}

/// The bump's calibrated contact with one item, and the test's numbers.
#[derive(Debug, Clone, PartialEq)]
pub struct BumpCalibration {
    /// The bump's contact stiffness in MuJoCo's direct `solref` format \[1/s²\].
    pub contact_stiffness: f64,
    /// Its damping, critical: `2 √stiffness` \[1/s\].
    pub contact_damping: f64,
    /// The force at which it meets Hertz ([`reference_force_n`]) \[N\].
    pub reference_force_n: f64,
    /// Hertz's travel of the two spheres at that force \[m\].
    pub reference_travel_m: f64,
    /// The calibrated spheres' travel at that force \[m\].
    pub calibrated_travel_m: f64,
}

impl BumpCalibration {
    /// The calibrated contact with `physics`' impedance, as [`bump_attrs`] takes it.
    pub fn contact(&self, physics: &PhysicsConfig) -> ([f64; 2], [f64; 3]) {
        ([self.contact_stiffness, self.contact_damping], physics.contact_solimp)
    }
}

/// Hertz's effective radius of the bump on the item, pressed along x \[m\]:
/// `1 / (1/r_bump + κ_item)`.
pub fn radius_m(item: &ProduceItem, pad: &PadShape) -> f64 {
    1.0 / (1.0 / pad.bump_radius_m + item.curvatures([1.0, 0.0, 0.0])[0])
}

/// The force at which Hertz's bump has sunk half its height into the item \[N\]
/// (`F = (4/3) E* √R d^{3/2}`, `d = r_bump / 2`), at most [`REFERENCE_FORCE_N`]: the middle of
/// the range where the bump alone carries the pad's force (beyond its height the casing touches).
/// For the cherry tomato 0.63 N; for the soft basil bunch 0.06 N.
pub fn reference_force_n(item: &ProduceItem, pad: &PadShape) -> f64 {
    let depth = pad.bump_radius_m / 2.0;
    let f = hertz::plates_force_n(radius_m(item, pad), plates::plate_modulus_pa(item), 2.0 * depth);
    f.min(REFERENCE_FORCE_N)
}

/// The attributes a bump geom gets in a produce scene (see the module's doc for why each):
/// `priority` one above the flex's, `contact` (direct `solref` \[1/s²\], \[1/s\]; `solimp`), and
/// the flex's friction and `condim` when its file sets them.
pub fn bump_attrs(item: &ProduceItem, contact: ([f64; 2], [f64; 3])) -> Vec<(&'static str, String)> {
    let priority: i32 = item.contact_attr("priority").and_then(|p| p.parse().ok()).unwrap_or(0);
    let ([k, b], imp) = contact;
    let mut attrs = vec![
        ("priority", (priority + 1).to_string()),
        ("solref", format!("{} {}", num(-k), num(-b))),
        ("solimp", format!("{} {} {} 0.5 2", num(imp[0]), num(imp[1]), num(imp[2]))),
    ];
    for copied in ["friction", "condim"] {
        if let Some(v) = item.contact_attr(copied) {
            attrs.push((copied, v));
        }
    }
    attrs
}

/// `mjcf` with every bump geom (a `<geom name="...bump"`, the pad's and a sensor array's) given
/// `attrs` ([`bump_attrs`]).
pub fn with_bump_contact(mjcf: &str, attrs: &[(&str, String)]) -> String {
    let mut out = String::with_capacity(mjcf.len() + 256);
    let mut rest = mjcf;
    while let Some(at) = rest.find("<geom") {
        let end = at + rest[at..].find('>').unwrap_or(rest.len() - at);
        let tag = &rest[at..end];
        out.push_str(&rest[..at]);
        if attr(tag, "name").is_some_and(|n| n.starts_with("pad") && n.ends_with("_bump")) {
            out.push_str(&attrs.iter().fold(tag.to_string(), |t, (k, v)| with_attr(&t, k, v)));
        } else {
            out.push_str(tag);
        }
        rest = &rest[end..];
    }
    out.push_str(rest);
    out
}

/// A bump-sized sphere with `attrs`, its tip at its body's origin facing the item from `sign`.
fn sphere(pad: &PadShape, sign: f64, attrs: &[(&str, String)]) -> String {
    let name = if sign > 0.0 { "pad_bump" } else { "pad_bump_minus" };
    let tag = format!(
        r#"<geom name="{name}" type="sphere" size="{r}" pos="{x} 0 0" contype="8" conaffinity="0""#,
        r = num(pad.bump_radius_m),
        x = num(sign * pad.bump_radius_m),
    );
    format!("{}/>", attrs.iter().fold(tag, |t, (k, v)| with_attr(&t, k, v)))
}

/// The item squeezed between two bump spheres of contact stiffness `stiffness` (its flex with the
/// plate calibration's `plate_contact`) until they push it with `max_force_n`.
pub fn spheres(
    item: &ProduceItem,
    physics: &PhysicsConfig,
    pad: &PadShape,
    plate_contact: ([f64; 2], [f64; 3]),
    stiffness: f64,
    max_force_n: f64,
) -> Result<Vec<PlateSample>, PhysicsError> {
    let attrs = bump_attrs(item, ([stiffness, critical(stiffness)], physics.contact_solimp));
    let xml = plates::squeeze_scene(item, physics, plate_contact, &|sign| sphere(pad, sign, &attrs));
    let samples = plates::squeeze(item, physics, &xml, &[&["pad_bump"]], max_force_n)?;
    Ok(samples.into_iter().map(|s| PlateSample { travel_m: s.travel_m, force_n: s.forces_n[0] }).collect())
}

/// The bump's contact stiffness whose two-sphere test meets Hertz's travel at
/// [`reference_force_n`], with the item's flex carrying the plate calibration's contact
/// (`plate_contact`, which the spheres' higher priority overrides).
pub fn calibrate(
    item: &ProduceItem,
    physics: &PhysicsConfig,
    pad: &PadShape,
    plate_contact: ([f64; 2], [f64; 3]),
) -> Result<BumpCalibration, PhysicsError> {
    let force = reference_force_n(item, pad);
    let target = hertz::plates_travel_m(radius_m(item, pad), plates::plate_modulus_pa(item), force);
    let travel_with = |stiffness: f64| -> Result<f64, PhysicsError> {
        let samples = spheres(item, physics, pad, plate_contact, stiffness, 1.5 * force)?;
        plates::travel_at(&samples, force).ok_or_else(|| PhysicsError::Object {
            file: item.source.clone(),
            what: format!(
                "cannot calibrate the pad's bump: two {:.1} mm spheres never pushed it with {force:.3} N \
                 (contact stiffness {stiffness:.3e} /s²): they sank through its surface",
                pad.bump_radius_m * 1e3
            ),
        })
    };
    let too_soft = |travel: f64| PhysicsError::Object {
        file: item.source.clone(),
        what: format!(
            "cannot calibrate the pad's bump: pressed by {force:.3} N between two {:.1} mm spheres, its flex \
             alone travels {:.3} mm, more than Hertz's {:.3} mm",
            pad.bump_radius_m * 1e3,
            travel * 1e3,
            target * 1e3
        ),
    };
    let (k, t) = search_stiffness(target, travel_with, too_soft)?;
    Ok(BumpCalibration {
        contact_stiffness: k,
        contact_damping: critical(k),
        reference_force_n: force,
        reference_travel_m: target,
        calibrated_travel_m: t,
    })
}

/// One step of the pad pressing the item onto a plate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PadSample {
    /// The pad's and the plate's travel since the pad first touched \[m\].
    pub travel_m: f64,
    /// The pad's normal force on the item, casing and bump \[N\].
    pub force_n: f64,
    /// The bump's share of it \[N\].
    pub bump_force_n: f64,
}

/// The sensor pad (its casing with the bump, square to the item) pressing the item against a flat
/// plate, the bump with `bump_contact` ([`bump_attrs`]) and the flex with `plate_contact`, until
/// the pad pushes with `max_force_n`: where the pad's force goes, bump or casing.
pub fn pad_press(
    item: &ProduceItem,
    physics: &PhysicsConfig,
    pad: &PadShape,
    plate_contact: ([f64; 2], [f64; 3]),
    bump_contact: ([f64; 2], [f64; 3]),
    max_force_n: f64,
) -> Result<Vec<PadSample>, PhysicsError> {
    let attrs = bump_attrs(item, bump_contact);
    let h = 2.0 * item.radii_m.iter().cloned().fold(0.0, f64::max);
    let [along, height, across] = pad.casing_half_m;
    let presser = |sign: f64| {
        if sign > 0.0 {
            format!(
                r#"{bump}<geom name="pad_casing" type="box" size="{height} {along} {across}" pos="{x} 0 0" contype="8" conaffinity="0"/>"#,
                bump = sphere(pad, sign, &attrs),
                height = num(height),
                along = num(along),
                across = num(across),
                x = num(pad.bump_radius_m + height),
            )
        } else {
            format!(
                r#"<geom name="plate_minus" type="box" size="0.001 {h} {h}" pos="-0.001 0 0" contype="2" conaffinity="0"/>"#,
                h = num(h)
            )
        }
    };
    let xml = plates::squeeze_scene(item, physics, plate_contact, &presser);
    let samples = plates::squeeze(item, physics, &xml, &[&["pad_casing", "pad_bump"], &["pad_bump"]], max_force_n)?;
    Ok(samples
        .into_iter()
        .map(|Squeezed { travel_m, forces_n }| PadSample { travel_m, force_n: forces_n[0], bump_force_n: forces_n[1] })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    const PAD: &str = include_str!("../../../../models/sensor_pad.xml");

    #[test]
    fn reads_the_pad_shape_from_its_file() {
        let pad = PadShape::read(PAD).unwrap();
        assert_eq!(pad, PadShape { bump_radius_m: 0.0015, casing_half_m: [0.006, 0.002, 0.006] });
        assert!(PadShape::read(&PAD.replace("name=\"pad_bump\"", "name=\"knob\"")).is_err());
    }

    #[test]
    fn only_bump_geoms_get_the_contact() {
        let doc =
            r#"<geom name="pad_casing" size="1"/><geom name="pad_bump" size="2"/><geom name="pad1_bump" size="3"/>"#;
        let out = with_bump_contact(doc, &[("priority", "2".into())]);
        assert_eq!(
            out,
            r#"<geom name="pad_casing" size="1"/><geom name="pad_bump" size="2" priority="2"/><geom name="pad1_bump" size="3" priority="2"/>"#
        );
    }
}
