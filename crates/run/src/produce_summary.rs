//! A produce item's figures in `summary.json`: the damage the grip did and, for a harvest, how
//! the item came off its plant.

use super::report::{Drop, Outcome};
use super::trace::TraceRow;
use serde::{Deserialize, Serialize};
use tendril_cell::ProduceTruth;

/// How a harvest ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Harvest {
    /// The stem let go and the item stayed in the hand to the release.
    Harvested,
    /// The stem held and the grip too: the item never came off.
    Stayed,
    /// The item slid out of the grip while the stem still held it.
    Slipped,
    /// The stem let go, then the item fell out of the grip.
    Dropped,
}

impl Harvest {
    /// The harvest's end, from whether and when the stem let go and whether and when the item
    /// was lost (cell times \[s\]).
    pub fn judge(detached_s: Option<f64>, drop: Option<Drop>) -> Harvest {
        match (detached_s, drop) {
            (Some(_), None) => Harvest::Harvested,
            (None, None) => Harvest::Stayed,
            (Some(d), Some(l)) if l.cell_time_s >= d => Harvest::Dropped,
            (_, Some(_)) => Harvest::Slipped,
        }
    }

    /// The name summaries give it.
    pub fn name(self) -> &'static str {
        match self {
            Harvest::Harvested => "harvested",
            Harvest::Stayed => "stayed",
            Harvest::Slipped => "slipped",
            Harvest::Dropped => "dropped",
        }
    }
}

/// A produce item's figures over a run.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct ProduceSummary {
    /// The largest peak contact pressure on the item at any physics step \[kPa\].
    pub peak_pressure_kpa: f64,
    /// What pressed there (`pad_bump`, `pad_casing`, `strip`, `palm`, `other`).
    pub peak_at: String,
    /// The item's bruise threshold \[kPa\].
    pub bruise_threshold_kpa: f64,
    /// The largest area above the threshold at one step, all contacts together \[mm²\].
    pub bruise_area_mm2: f64,
    /// Time some contact spent above the threshold \[s\].
    pub time_above_s: f64,
    /// Whether any contact went above the threshold.
    pub bruised: bool,
    /// How a harvest ended: `harvested`, `stayed`, `slipped` or `dropped` (absent for a
    /// pick-and-place).
    pub harvest: Option<String>,
    /// When the stem let go, after the arm started moving \[s\].
    pub detached_s: Option<f64>,
    /// The stem's largest tension \[N\].
    pub max_stem_tension_n: Option<f64>,
    /// The force at which the stem lets go \[N\].
    pub detach_n: Option<f64>,
    /// The pad's bump's share of the pad's force while the item is held (mean over the ticks
    /// where the pad carries more than [`PAD_LOADED_N`]): the pad's force is what the twin's
    /// sensor reads, the bump's and the casing's together; a sensor that felt the bump alone would
    /// read this share of it.
    pub bump_share: Option<f64>,
}

/// The pad force above which a tick counts towards [`ProduceSummary::bump_share`] \[N\]: half the
/// guarded close's contact threshold (0.1 N), clear of the sensor's noise.
pub const PAD_LOADED_N: f64 = 0.05;

/// The bump's mean share of the pad's force over `rows` while the item is held.
fn bump_share(rows: &[TraceRow]) -> Option<f64> {
    let shares: Vec<f64> = rows
        .iter()
        .filter(|r| r.phase.holding() && r.true_force_n > PAD_LOADED_N)
        .filter_map(|r| r.produce.map(|p| p.bump_force_n / r.true_force_n))
        .collect();
    (!shares.is_empty()).then(|| shares.iter().sum::<f64>() / shares.len() as f64)
}

impl ProduceSummary {
    /// The figures of a run whose item ended as `truth`, lost at `drop` (if it was), the arm
    /// having started moving at `motion_start_s`, its ticks `rows`.
    pub fn new(
        truth: &ProduceTruth,
        outcome: Outcome,
        drop: Option<Drop>,
        motion_start_s: Option<f64>,
        rows: &[TraceRow],
    ) -> Self {
        let harvest = (truth.harvest && outcome != Outcome::Error).then(|| Harvest::judge(truth.detached_s, drop));
        ProduceSummary {
            peak_pressure_kpa: truth.peak_pa / 1e3,
            peak_at: truth.peak_at.to_string(),
            bruise_threshold_kpa: truth.bruise_pa / 1e3,
            bruise_area_mm2: truth.max_area_above_m2 * 1e6,
            time_above_s: truth.time_above_s,
            bruised: truth.peak_pa > truth.bruise_pa,
            harvest: harvest.map(|h| h.name().to_string()),
            detached_s: truth.detached_s.map(|d| d - motion_start_s.unwrap_or(0.0)),
            max_stem_tension_n: truth.harvest.then_some(truth.max_stem_tension_n),
            detach_n: truth.detach_n,
            bump_share: bump_share(rows),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tendril_cell::Phase;

    fn lost(t: f64) -> Option<Drop> {
        Some(Drop { cell_time_s: t, phase: Phase::Lift })
    }

    #[test]
    fn a_harvest_is_judged_by_the_stem_and_the_grip() {
        assert_eq!(Harvest::judge(Some(20.0), None), Harvest::Harvested);
        assert_eq!(Harvest::judge(None, None), Harvest::Stayed);
        assert_eq!(Harvest::judge(None, lost(21.0)), Harvest::Slipped);
        assert_eq!(Harvest::judge(Some(25.0), lost(21.0)), Harvest::Slipped, "lost before the stem let go");
        assert_eq!(Harvest::judge(Some(20.0), lost(22.0)), Harvest::Dropped);
    }

    #[test]
    fn the_figures_come_in_kpa_and_mm2_and_a_pick_and_place_has_no_harvest() {
        let truth = ProduceTruth {
            peak_pa: 150e3,
            peak_at: "pad_bump",
            max_area_above_m2: 2e-6,
            time_above_s: 0.5,
            bruise_pa: 100e3,
            ..Default::default()
        };
        let s = ProduceSummary::new(&truth, Outcome::Held, None, Some(20.0), &[]);
        assert_eq!((s.peak_pressure_kpa, s.bruise_threshold_kpa, s.bruised), (150.0, 100.0, true));
        assert!((s.bruise_area_mm2 - 2.0).abs() < 1e-12 && s.harvest.is_none() && s.max_stem_tension_n.is_none());
        let harvest = ProduceTruth { harvest: true, detached_s: Some(23.5), max_stem_tension_n: 6.0, ..truth };
        let s = ProduceSummary::new(&harvest, Outcome::Held, None, Some(20.0), &[]);
        assert_eq!(
            (s.harvest.as_deref(), s.detached_s, s.max_stem_tension_n),
            (Some("harvested"), Some(3.5), Some(6.0))
        );
    }
}
