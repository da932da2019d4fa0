//! Damage to a produce item: the contact pressure on it, step by step, against its bruise
//! threshold.
//!
//! Each geom that touches the item (a strip link, the pad's bump or casing, the palm, the table)
//! makes one contact patch: MuJoCo's contacts between that geom and the item's flex, their normal
//! forces summed. The patch's pressure is Hertz's for that force ([`super::hertz`]): the item's
//! curvature where the patch sits and the geom's own (the pad's 1.5 mm bump is a sphere; strip
//! links, casing, palm and table are flat), the item's contact modulus `E/(1 − ν²)` against a
//! rigid counterpart (the TPU finger is some 20 times stiffer than fruit flesh: taking it rigid
//! overstates the peak pressure by a few per cent, on the safe side). A step's figures are its
//! patches' largest peak pressure and their summed area above the bruise threshold; a run's are
//! the largest of each over its steps and the time any patch spent above the threshold.

use super::hertz::{self, Geometry};
use super::produce::ProduceItem;

/// One patch at one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PatchAt {
    /// What touches the item there.
    pub toucher: Toucher,
    /// The patch's normal force \[N\].
    pub force_n: f64,
    /// Hertz's figures for it.
    pub patch: hertz::Patch,
}

/// What a patch's other side is, as the summary names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Toucher {
    /// The sensor pad's bump (pad 0 or a further pad of an array).
    PadBump,
    /// The sensor pad's casing.
    PadCasing,
    /// A link of the strip.
    Strip,
    /// The palm beside the guide's exit.
    Palm,
    /// The table, or anything else.
    Other,
}

impl Toucher {
    /// The name summaries and traces give it.
    pub fn name(self) -> &'static str {
        match self {
            Toucher::PadBump => "pad_bump",
            Toucher::PadCasing => "pad_casing",
            Toucher::Strip => "strip",
            Toucher::Palm => "palm",
            Toucher::Other => "other",
        }
    }
}

/// Hertz's patch of a geom with principal curvatures `geom_curvatures` \[1/m\] pressing the item
/// with `force_n` at direction `dir` from the item's centre.
pub fn patch_of(
    item: &ProduceItem,
    dir: [f64; 3],
    geom_curvatures: [f64; 2],
    length_m: f64,
    force_n: f64,
) -> hertz::Patch {
    let p = &item.properties;
    let modulus = hertz::contact_modulus_pa(p.modulus_pa, p.poisson, f64::INFINITY, 0.0);
    let geometry = Geometry::of_curvatures(item.curvatures(dir), geom_curvatures, length_m);
    hertz::patch(force_n, geometry, modulus, p.bruise_pa)
}

/// A run's damage so far.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DamageTally {
    /// The largest peak pressure of any patch at any step \[Pa\].
    pub peak_pa: f64,
    /// What pressed there.
    pub peak_at: Option<Toucher>,
    /// The largest summed area above the bruise threshold at any step \[m²\].
    pub max_area_above_m2: f64,
    /// Time with a patch above the bruise threshold \[s\].
    pub time_above_s: f64,
    /// The last step's largest peak pressure \[Pa\].
    pub now_peak_pa: f64,
    /// The last step's summed area above the threshold \[m²\].
    pub now_area_above_m2: f64,
}

impl DamageTally {
    /// Adds a step of `dt_s` whose patches are `patches`.
    pub fn record(&mut self, patches: &[PatchAt], dt_s: f64) {
        let (mut peak, mut at, mut area) = (0.0, None, 0.0);
        for p in patches {
            if p.patch.peak_pa > peak {
                peak = p.patch.peak_pa;
                at = Some(p.toucher);
            }
            area += p.patch.area_above_m2;
        }
        if peak > self.peak_pa {
            self.peak_pa = peak;
            self.peak_at = at;
        }
        self.max_area_above_m2 = self.max_area_above_m2.max(area);
        if area > 0.0 {
            self.time_above_s += dt_s;
        }
        self.now_peak_pa = peak;
        self.now_area_above_m2 = area;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(toucher: Toucher, peak_pa: f64, area_above_m2: f64) -> PatchAt {
        PatchAt { toucher, force_n: 1.0, patch: hertz::Patch { peak_pa, area_above_m2, ..Default::default() } }
    }

    #[test]
    fn a_tally_keeps_the_peak_the_largest_area_and_the_time_above() {
        let mut t = DamageTally::default();
        t.record(&[at(Toucher::Strip, 5e4, 0.0), at(Toucher::PadBump, 9e4, 0.0)], 0.0025);
        assert_eq!((t.peak_pa, t.peak_at, t.time_above_s), (9e4, Some(Toucher::PadBump), 0.0));
        t.record(&[at(Toucher::PadBump, 2e5, 3e-6), at(Toucher::Strip, 1.5e5, 1e-6)], 0.0025);
        t.record(&[at(Toucher::Strip, 1.6e5, 2e-6)], 0.0025);
        t.record(&[], 0.0025);
        assert_eq!((t.peak_pa, t.peak_at), (2e5, Some(Toucher::PadBump)));
        assert!((t.max_area_above_m2 - 4e-6).abs() < 1e-18 && (t.time_above_s - 0.005).abs() < 1e-15);
        assert_eq!((t.now_peak_pa, t.now_area_above_m2), (0.0, 0.0));
    }
}
