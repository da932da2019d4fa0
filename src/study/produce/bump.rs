//! The pad's bump on each produce item, as `bump.csv` holds it: the bump's calibrated contact
//! between two bump spheres against Hertz (travel and peak pressure), and the whole pad (casing
//! and bump, square to the item) pressing the item onto a plate: the bump's share of the pad's
//! force and its pressure.

use tendril_run::scenario::PickPlaceScenario;
use tendril_twin::physics::bump::{self, PadShape};
use tendril_twin::physics::{damage, hertz, plates};

/// The pad forces the bump is judged at \[N\]: the paper's smallest setpoint's half, the run's
/// default setpoint, the plates' reference and twice it (where the bump has sunk most of its
/// height into a cherry tomato).
pub const FORCES_N: [f64; 4] = [0.3, 0.6, 1.0, 2.0];

/// One item at one force.
#[derive(Debug, Clone, PartialEq)]
pub struct BumpRow {
    /// The item.
    pub item: String,
    /// The force \[N\].
    pub force_n: f64,
    /// The bump's calibrated contact stiffness \[1/s²\].
    pub contact_stiffness: f64,
    /// Its reference force \[N\].
    pub reference_force_n: f64,
    /// Two bump spheres squeezing the item: their travel at the force \[mm\] (`None`: never
    /// reached, up to the item's radius).
    pub spheres_travel_mm: Option<f64>,
    /// Hertz's travel at the force \[mm\].
    pub hertz_travel_mm: f64,
    /// The damage model's peak pressure for the force on a bump \[kPa\].
    pub peak_kpa: f64,
    /// Hertz's peak pressure at the spheres' travel \[kPa\].
    pub hertz_peak_kpa: Option<f64>,
    /// The pad pressing the item onto a plate: the bump's share of the pad's force at the force.
    pub pad_bump_share: Option<f64>,
    /// The damage model's peak pressure under the bump there \[kPa\].
    pub pad_bump_peak_kpa: Option<f64>,
}

impl BumpRow {
    /// The columns of `bump.csv`.
    pub const HEADER: [&'static str; 10] = [
        "item",
        "force_n",
        "bump_stiffness_per_s2",
        "bump_reference_force_n",
        "spheres_travel_mm",
        "hertz_travel_mm",
        "peak_kpa",
        "hertz_peak_kpa",
        "pad_bump_share",
        "pad_bump_peak_kpa",
    ];

    /// The row's cells, in [`BumpRow::HEADER`]'s order.
    pub fn cells(&self) -> Vec<String> {
        let opt = |x: Option<f64>, digits: usize| x.map_or_else(String::new, |x| format!("{x:.digits$}"));
        vec![
            self.item.clone(),
            format!("{}", self.force_n),
            format!("{:.4e}", self.contact_stiffness),
            format!("{:.4}", self.reference_force_n),
            opt(self.spheres_travel_mm, 4),
            format!("{:.4}", self.hertz_travel_mm),
            format!("{:.1}", self.peak_kpa),
            opt(self.hertz_peak_kpa, 1),
            opt(self.pad_bump_share, 3),
            opt(self.pad_bump_peak_kpa, 1),
        ]
    }
}

/// The first sample at or above `force_n` of a press.
fn first_at<T: Copy>(samples: &[T], force: impl Fn(&T) -> f64, force_n: f64) -> Option<T> {
    samples.iter().copied().find(|s| force(s) >= force_n)
}

/// The bump test of the item of `scenario` (its pad from the shipped `sensor_pad.xml`).
pub fn bump_test(scenario: &std::path::Path) -> anyhow::Result<Vec<BumpRow>> {
    let s: PickPlaceScenario = tendril_config::load(scenario, &[])?;
    let raw = s.object.model()?.produce.ok_or_else(|| anyhow::anyhow!("{}: not a produce item", scenario.display()))?;
    let item = raw.configured(&s.produce, s.object.mass_kg, s.object.friction)?;
    let physics = &s.physics;
    let pad_text = match &physics.models_dir {
        Some(dir) => std::fs::read_to_string(dir.join("sensor_pad.xml"))?,
        None => include_str!("../../../models/sensor_pad.xml").to_string(),
    };
    let pad = PadShape::read(&pad_text)?;
    let plate = plates::calibrate(&item, physics)?;
    let cal = bump::calibrate(&item, physics, &pad, plate.contact(physics))?;
    let top = FORCES_N.iter().cloned().fold(0.0, f64::max);
    let spheres = bump::spheres(&item, physics, &pad, plate.contact(physics), cal.contact_stiffness, top)?;
    let pressed = bump::pad_press(&item, physics, &pad, plate.contact(physics), cal.contact(physics), top)?;
    let (r, e) = (bump::radius_m(&item, &pad), plates::plate_modulus_pa(&item));
    let on_bump = |force: f64| damage::patch_of(&item, [1.0, 0.0, 0.0], [1.0 / pad.bump_radius_m; 2], 1.0, force);
    let name = s.object.label();
    Ok(FORCES_N
        .iter()
        .map(|&f| {
            let travel = plates::travel_at(&spheres, f);
            let at_pad = first_at(&pressed, |p| p.force_n, f);
            BumpRow {
                item: name.clone(),
                force_n: f,
                contact_stiffness: cal.contact_stiffness,
                reference_force_n: cal.reference_force_n,
                spheres_travel_mm: travel.map(|t| t * 1e3),
                hertz_travel_mm: hertz::plates_travel_m(r, e, f) * 1e3,
                peak_kpa: on_bump(f).peak_pa / 1e3,
                hertz_peak_kpa: travel.map(|t| hertz::plates_patch(r, e, t).0 / 1e3),
                pad_bump_share: at_pad.map(|p| p.bump_force_n / p.force_n),
                pad_bump_peak_kpa: at_pad.map(|p| on_bump(p.bump_force_n).peak_pa / 1e3),
            }
        })
        .collect())
}
