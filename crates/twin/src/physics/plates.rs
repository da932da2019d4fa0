//! A produce item squeezed between two flat plates: its force against the plates' travel, and
//! the contact stiffness that makes it Hertz's.
//!
//! The item alone, gravity off, between two rigid plates across x (the direction the finger
//! squeezes it); the plates close at [`PLATE_SPEED_M_S`] each, slow enough that the item is
//! squeezed quasi-statically, and the force on one plate is recorded against their total travel
//! since first contact. This is the ASAE S368 compression test, whose analysis is Hertz's
//! ([`super::hertz::plates_force_n`]).
//!
//! The flex's interpolated degrees of freedom (24 trilinear, 81 quadratic) cannot form a
//! contact's local dent: with the item's own modulus the flex flattens as a whole, several times
//! stiffer than Hertz's local indentation at a newton, its force linear in the travel. What gives
//! way at a contact is MuJoCo's soft contact, and it is as soft as the nodes are light (a 12 g
//! item's contacts at the cell's 5 ms time constant give half of Hertz's force for a cherry
//! tomato). [`calibrate`] sets the item's contact stiffness (MuJoCo's direct `solref`, critically
//! damped) so that the plates meet Hertz's force at [`REFERENCE_FORCE_N`]; the flex keeps the
//! published modulus, and the contact's impedance the cell's `physics.contact_solimp`, whose
//! rise over its width stiffens the contact with depth as Hertz's does. How close the whole curve
//! comes to Hertz's over the grip's range is the figure `docs/studies/produce.md` shows.

use super::PhysicsError;
use super::config::PhysicsConfig;
use super::header::header;
use super::hertz;
use super::produce::{FLEX_NAME, ProduceItem};
use super::template::{num, section};
use mujoco_rs::mujoco_c::_mjtObjBase;
use mujoco_rs::prelude::{MjData, MjModel};

/// Each plate's speed \[m/s\]: 2 mm/s, so that the travel over the squeezed item's slowest
/// period (about 10 ms for a cherry tomato) is 20 µm, a quasi-static test.
pub const PLATE_SPEED_M_S: f64 = 0.002;

/// The force at which the calibration meets Hertz \[N\]: 1 N, the middle (geometric mean) of
/// the 0.1-10 N that one contact of the finger puts on an item (a strip link carries a few tenths
/// of a newton, the pad up to the sensor's 4.69 N range).
pub const REFERENCE_FORCE_N: f64 = 1.0;

/// Gap between each plate and the item at the start \[m\].
const START_GAP_M: f64 = 2e-4;

/// One sample of a compression: total travel of the plates since first contact and force on one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlateSample {
    /// Both plates' travel since they first touched the item \[m\].
    pub travel_m: f64,
    /// Normal force on one plate \[N\].
    pub force_n: f64,
}

/// The contact stiffness that reproduces Hertz at the reference force, and the test's numbers.
#[derive(Debug, Clone, PartialEq)]
pub struct Calibration {
    /// The contact's stiffness in MuJoCo's direct `solref` format \[1/s²\] (an acceleration per
    /// metre of penetration, which MuJoCo scales by the bodies' effective mass).
    pub contact_stiffness: f64,
    /// Its damping, critical: `2 √stiffness` \[1/s\].
    pub contact_damping: f64,
    /// Hertz's travel at [`REFERENCE_FORCE_N`] \[m\].
    pub reference_travel_m: f64,
    /// The travel the calibrated item needs for the reference force \[m\].
    pub calibrated_travel_m: f64,
}

/// The fastest a dropped item meets the table \[m/s\]: ~1.5 m/s, a 12 cm fall, the speed
/// `physics.max_penetration_m`'s bound is stated for.
pub const DROP_SPEED_M_S: f64 = 1.5;

impl Calibration {
    /// The calibrated contact as [`ProduceItem::document`] takes it, with `physics`' impedance.
    pub fn contact(&self, physics: &PhysicsConfig) -> ([f64; 2], [f64; 3]) {
        ([self.contact_stiffness, self.contact_damping], physics.contact_solimp)
    }

    /// The deepest this contact lets a dropped item in \[m\]: `v / √stiffness` at
    /// [`DROP_SPEED_M_S`], an undamped contact's peak (critical damping stops it at 1/e of that).
    /// The divergence check allows the item's contacts this deep where it is more than
    /// `physics.max_penetration_m`: a soft item's calibrated contact is far softer than the cell's
    /// time constant (the basil bunch's 150 /s² has a natural period of 0.5 s), and its fall onto
    /// the table is not a blow-up (the bunch dropped from 47 mm went 40-50 mm in and came to rest
    /// 1.5 mm in).
    pub fn drop_depth_m(&self) -> f64 {
        DROP_SPEED_M_S / self.contact_stiffness.sqrt()
    }
}

/// Critical damping of a direct-format contact of `stiffness` \[1/s\] (MuJoCo: a damping ratio
/// of 1 is `2 √stiffness`).
pub(crate) fn critical(stiffness: f64) -> f64 {
    2.0 * stiffness.sqrt()
}

/// Hertz's effective radius of the item against a plate across x \[m\].
pub fn plate_radius_m(item: &ProduceItem) -> f64 {
    1.0 / item.curvatures([1.0, 0.0, 0.0])[0]
}

/// Hertz's contact modulus of the item against a rigid plate \[Pa\].
pub fn plate_modulus_pa(item: &ProduceItem) -> f64 {
    let p = &item.properties;
    hertz::contact_modulus_pa(p.modulus_pa, p.poisson, f64::INFINITY, 0.0)
}

/// A rigid body closing on the item along x: its MJCF, surface at the body's origin, facing the
/// item from the side `sign` (+1: from +x).
pub(crate) type Presser<'a> = &'a dyn Fn(f64) -> String;

/// The squeeze's MJCF: the item (its document with `contact` on its flex) between two mocap
/// bodies `plate_plus` and `plate_minus` holding `presser(+1)` and `presser(−1)`, in `physics`'
/// options.
pub(crate) fn squeeze_scene(
    item: &ProduceItem,
    physics: &PhysicsConfig,
    contact: ([f64; 2], [f64; 3]),
    presser: Presser,
) -> String {
    let x = item.radii_m[0] + START_GAP_M;
    let body = |name: &str, sign: f64| {
        format!(
            r#"<body name="{name}" mocap="true" pos="{px} 0 0">{geoms}</body>"#,
            px = num(sign * x),
            geoms = presser(sign)
        )
    };
    format!(
        "<mujoco model=\"plates\">\n  {header}\n  <worldbody>\n    {top}\n    {bottom}\n    {item}\n  </worldbody>\n</mujoco>\n",
        header = header(physics),
        top = body("plate_plus", 1.0),
        bottom = body("plate_minus", -1.0),
        item = section(&item.document(contact), "worldbody"),
    )
}

/// A flat rigid plate, larger than the item, as [`squeeze_scene`] takes it.
fn plate(item: &ProduceItem, sign: f64) -> String {
    let h = 2.0 * item.radii_m.iter().cloned().fold(0.0, f64::max);
    let name = if sign > 0.0 { "plate_plus" } else { "plate_minus" };
    format!(
        r#"<geom name="{name}" type="box" size="0.001 {h} {h}" pos="{gx} 0 0" contype="2" conaffinity="0"/>"#,
        gx = num(sign * 0.001),
        h = num(h),
    )
}

/// One step of a squeeze: the bodies' travel since first contact and the normal force on the item
/// of each group of the `plate_plus` body's geoms.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Squeezed {
    /// Both bodies' travel since the first group first touched the item \[m\].
    pub travel_m: f64,
    /// Normal force of each group's geoms on the item \[N\].
    pub forces_n: Vec<f64>,
}

/// Closes the bodies of `xml` ([`squeeze_scene`]) on the item at [`PLATE_SPEED_M_S`] each until
/// the geoms of `groups[0]` push it with `max_force_n` or the bodies have travelled the item's
/// radius; returns a sample per step from first contact on. Gravity is off: the item floats
/// between the two.
pub(crate) fn squeeze(
    item: &ProduceItem,
    physics: &PhysicsConfig,
    xml: &str,
    groups: &[&[&str]],
    max_force_n: f64,
) -> Result<Vec<Squeezed>, PhysicsError> {
    let mut model = MjModel::from_xml_string(xml).map_err(|e| PhysicsError::Object {
        file: item.source.clone(),
        what: format!("MuJoCo cannot compile the plate test: {e:?}"),
    })?;
    model.opt_mut().gravity = [0.0; 3];
    let geom = |name: &str| model.name_to_id(_mjtObjBase::mjOBJ_GEOM, name).expect("the squeeze scene names it");
    let groups: Vec<Vec<usize>> = groups.iter().map(|g| g.iter().map(|n| geom(n)).collect()).collect();
    let flex = model.name_to_id(_mjtObjBase::mjOBJ_FLEX, FLEX_NAME).expect("read checked the flex");
    let mocap = |m: &MjModel, body: &str| {
        let b = m.name_to_id(_mjtObjBase::mjOBJ_BODY, body).expect("the plate scene names it");
        m.body_mocapid()[b] as usize
    };
    let (m_plus, m_minus) = (mocap(&model, "plate_plus"), mocap(&model, "plate_minus"));
    let x0 = item.radii_m[0] + START_GAP_M;
    let dt = physics.timestep_s;
    let mut data = MjData::new(&model);
    let mut samples = Vec::new();
    let mut touched_at: Option<f64> = None;
    let steps = ((item.radii_m[0] + START_GAP_M) / (PLATE_SPEED_M_S * dt)).ceil() as usize;
    for _ in 0..steps {
        let s = PLATE_SPEED_M_S * (data.time() + dt);
        data.mocap_pos_mut()[m_plus][0] = x0 - s;
        data.mocap_pos_mut()[m_minus][0] = -(x0 - s);
        data.step();
        let mut forces = vec![0.0; groups.len()];
        for (i, c) in data.contact().iter().enumerate() {
            if c.efc_address < 0 {
                continue;
            }
            let other = if c.flex[1] == flex as i32 {
                c.geom[0]
            } else if c.flex[0] == flex as i32 {
                c.geom[1]
            } else {
                continue;
            };
            for (sum, group) in forces.iter_mut().zip(&groups) {
                if other >= 0 && group.contains(&(other as usize)) {
                    *sum += data.contact_force(i)[0];
                }
            }
        }
        let force = forces[0];
        if !forces.iter().all(|f| f.is_finite()) {
            return Err(PhysicsError::Diverged {
                time_s: data.time(),
                cause: super::Divergence::NonFinite { what: "plate force" },
            });
        }
        // The bodies' travel since first contact: each has closed `s`, the gap first.
        if force > 0.0 && touched_at.is_none() {
            touched_at = Some(s - PLATE_SPEED_M_S * dt);
        }
        if let Some(s0) = touched_at {
            samples.push(Squeezed { travel_m: 2.0 * (s - s0), forces_n: forces });
            if force >= max_force_n {
                break;
            }
        }
    }
    Ok(samples)
}

/// Squeezes `item` (contact stiffness `stiffness`, direct format \[1/s²\]) between the plates
/// until one carries `max_force_n` or they have travelled the item's radius; returns a sample per
/// step from first contact on.
pub fn compress(
    item: &ProduceItem,
    physics: &PhysicsConfig,
    stiffness: f64,
    max_force_n: f64,
) -> Result<Vec<PlateSample>, PhysicsError> {
    let xml = squeeze_scene(item, physics, ([stiffness, critical(stiffness)], physics.contact_solimp), &|sign| {
        plate(item, sign)
    });
    let samples = squeeze(item, physics, &xml, &[&["plate_plus"]], max_force_n)?;
    Ok(samples.into_iter().map(|s| PlateSample { travel_m: s.travel_m, force_n: s.forces_n[0] }).collect())
}

/// The travel at which `samples` first reach `force_n` \[m\] (linear between samples; `None`
/// if they never do).
pub fn travel_at(samples: &[PlateSample], force_n: f64) -> Option<f64> {
    let mut last = PlateSample { travel_m: 0.0, force_n: 0.0 };
    for s in samples {
        if s.force_n >= force_n {
            let f = (force_n - last.force_n) / (s.force_n - last.force_n);
            return Some(last.travel_m + f * (s.travel_m - last.travel_m));
        }
        last = *s;
    }
    None
}

/// The contact stiffness at the start of the calibration \[1/s²\]: that of MuJoCo's positive
/// format at the cell's 5 ms time constant (`1 / (0.99² · 0.005²)`).
const FIRST_STIFFNESS: f64 = 4.1e4;

/// The contact stiffness \[1/s²\] at which `travel_with` gives the travel `target_m`, and that
/// travel: a secant search on the travel against the stiffness (in logarithms, where it is nearly
/// straight) from [`FIRST_STIFFNESS`], to 0.5 %, at most a hundredfold per step and never above
/// what the step can hold (1e9 /s²). When stiffer contacts no longer shorten the travel, or the
/// search ends short of the target, `too_soft(travel)` is the error.
pub(crate) fn search_stiffness(
    target_m: f64,
    travel_with: impl Fn(f64) -> Result<f64, PhysicsError>,
    too_soft: impl Fn(f64) -> PhysicsError,
) -> Result<(f64, f64), PhysicsError> {
    let target = target_m;
    let (mut k0, mut t0) = (FIRST_STIFFNESS, travel_with(FIRST_STIFFNESS)?);
    let mut k1 = k0 * (t0 / target).powi(2);
    let mut t1 = travel_with(k1)?;
    for _ in 0..8 {
        if ((t1 - target) / target).abs() < 5e-3 {
            break;
        }
        let slope = (t1.ln() - t0.ln()) / (k1.ln() - k0.ln());
        if slope.is_nan() || slope >= -1e-3 {
            // Stiffer contacts no longer shorten the travel: the bulk carries it all.
            return Err(too_soft(t1));
        }
        let next = (k1.ln() + (target.ln() - t1.ln()) / slope).exp();
        let next = next.clamp(k1 / 100.0, (k1 * 100.0).min(1e9));
        (k0, t0) = (k1, t1);
        k1 = next;
        t1 = travel_with(k1)?;
    }
    if ((t1 - target) / target).abs() >= 5e-3 {
        return Err(too_soft(t1));
    }
    Ok((k1, t1))
}

/// The contact stiffness \[1/s²\] whose plate test meets Hertz's force at
/// [`REFERENCE_FORCE_N`]: a secant search on the travel at that force against the stiffness (in
/// logarithms, where it is nearly straight), to 0.5 %. An item whose flex alone, with stiff
/// contacts, travels further than Hertz allows cannot be calibrated: an error says so.
pub fn calibrate(item: &ProduceItem, physics: &PhysicsConfig) -> Result<Calibration, PhysicsError> {
    let target = hertz::plates_travel_m(plate_radius_m(item), plate_modulus_pa(item), REFERENCE_FORCE_N);
    let travel_with = |stiffness: f64| -> Result<f64, PhysicsError> {
        let samples = compress(item, physics, stiffness, 1.5 * REFERENCE_FORCE_N)?;
        travel_at(&samples, REFERENCE_FORCE_N).ok_or_else(|| PhysicsError::Object {
            file: item.source.clone(),
            what: format!(
                "cannot calibrate: squeezed across its whole width, it never pushed the plates with {REFERENCE_FORCE_N} N \
                 (contact stiffness {stiffness:.3e} /s²; Hertz's travel at {REFERENCE_FORCE_N} N is {:.1} mm for its \
                 modulus {:.3e} Pa): too soft an item for the plate test",
                target * 1e3,
                item.properties.modulus_pa
            ),
        })
    };
    let too_soft = |travel: f64| PhysicsError::Object {
        file: item.source.clone(),
        what: format!(
            "cannot calibrate: squeezed by {REFERENCE_FORCE_N} N between plates, its flex alone travels {:.3} mm, \
             more than Hertz's {:.3} mm for its modulus and size (raise produce_modulus_pa or coarsen nothing: \
             the flex's bulk is too soft)",
            travel * 1e3,
            target * 1e3
        ),
    };
    let (k1, t1) = search_stiffness(target, travel_with, too_soft)?;
    Ok(Calibration {
        contact_stiffness: k1,
        contact_damping: critical(k1),
        reference_travel_m: target,
        calibrated_travel_m: t1,
    })
}
