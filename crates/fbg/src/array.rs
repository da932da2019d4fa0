//! A sensor array: further FBG pads along the finger beside the paper's one (scenario section
//! `[array]`), and the multiplexing rules that decide whether a layout can be read.
//!
//! The paper's pad stays pad 0: at `finger.pad_position_m`, with the gratings of `[sensor]`
//! (`lambda1_nm`, `lambda2_nm`) on the channel of `[hardware.fbg]`. `[[array.pads]]` adds up to
//! [`MAX_PADS`]` - 1` more, each the same build (casing, uvula, strain response, hysteresis,
//! thermal lags as `[sensor]`) with its own gratings: its own strain grating always, and either
//! its own temperature reference or pad 0's (a pad without `lambda2_nm` shares it; the finger's
//! temperature is one).
//!
//! Gratings on one fibre are told apart by wavelength only (wavelength-division multiplexing): each
//! grating's peak moves over a *window* (its unloaded wavelength, plus the strain span up to the
//! sensor's range, plus the thermal shift over the operating temperatures), and the windows on
//! one channel must keep [`ArrayConfig::guard_nm`] apart and inside the interrogator's band, or two
//! peaks could meet and the interrogator would see one. [`ArrayConfig::multiplexing_faults`] refuses such a
//! layout with the key and the reason.

use crate::config::SensorConfig;
use crate::signals::Wavelengths;
use serde::{Deserialize, Serialize};
use tendril_config::{Checker, Validate};

/// The most pads a layout may have, pad 0 included: eight, as many as one si255 channel's band
/// holds with the default guard (each pad takes about 7 nm for its strain grating and 1 nm for its
/// reference, 100 nm of band: about 12), kept to eight so the per-tick readings stay a fixed size.
pub const MAX_PADS: usize = 8;

/// The further pads a layout may add to pad 0.
pub const MAX_EXTRA_PADS: usize = MAX_PADS - 1;

/// Lower edge of the band every grating must stay in \[nm\]: the HYPERION si255's 1500-1600 nm
/// (the C and L bands its swept laser covers; wider ranges are quoted for some units, so the
/// narrower is taken).
pub const BAND_MIN_NM: f64 = 1500.0;

/// Upper edge of the interrogator's band \[nm\] (see [`BAND_MIN_NM`]).
pub const BAND_MAX_NM: f64 = 1600.0;

/// Interrogator channels (fibres) a layout may name: the HYPERION family has 1, 4, 8 or 16.
pub const MAX_CHANNELS: usize = 16;

/// What force the controller regulates when the finger carries an array (`array.control`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum ArraySignal {
    /// Pad 0's estimate, as with the paper's single pad (the default: the setpoint keeps its
    /// meaning).
    #[default]
    First,
    /// The sum of every pad's estimate: the load the wrap puts on the pads together.
    Total,
    /// The largest pad's estimate: wherever the wrap presses hardest.
    Max,
}

impl ArraySignal {
    /// The signal over the pads' estimates \[N\] (`forces[0]` is pad 0's).
    pub fn of(self, forces: &[f64]) -> f64 {
        match self {
            ArraySignal::First => forces.first().copied().unwrap_or(f64::NAN),
            ArraySignal::Total => forces.iter().sum(),
            ArraySignal::Max => forces.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        }
    }
}

/// One further pad (`[[array.pads]]`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArrayPad {
    /// Distance of the pad's centre from the strip's base \[m\], as `finger.pad_position_m` for
    /// pad 0. The 12 mm casings of two pads must not overlap, and a pad must sit on the strip.
    pub arc_m: f64,
    /// Interrogator channel its fibre is on (1-based); pads on one channel share a fibre.
    #[serde(default = "first_channel")]
    pub channel: usize,
    /// Unstrained Bragg wavelength of its strain grating (under the uvula) at the reference
    /// temperature \[nm\].
    pub lambda1_nm: f64,
    /// Wavelength of its own temperature-reference grating \[nm\]; absent: it shares pad 0's (the
    /// reference grating reads the finger's temperature, which is one along the strip).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lambda2_nm: Option<f64>,
    /// Height of its bump's tip above the strip's inner face \[m\]; absent: pad 0's
    /// (`finger.pad_protrusion_m`, 5.5 mm: the paper's 4 mm casing and 1.5 mm bump). A lower pad
    /// (a thinner casing, recessed into the sleeve) takes less of the wrap's load from its
    /// neighbours (docs/guide/array.md).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub protrusion_m: Option<f64>,
}

fn first_channel() -> usize {
    1
}

/// The sensor layout beyond the paper's pad (`[array]`); empty by default, which is the paper's
/// single pad and every answer as without the section.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ArrayConfig {
    /// The further pads, base to tip or in any order (at most [`MAX_EXTRA_PADS`]), each a table
    /// with `arc_m`, `lambda1_nm` and optionally `channel`, `lambda2_nm`, `protrusion_m`
    /// (`ArrayPad`).
    pub pads: Vec<ArrayPad>,
    /// What the controller regulates: `"first"` (pad 0), `"total"` or `"max"`.
    pub control: ArraySignal,
    /// Lowest temperature the layout must read without two windows meeting [°C]: 15 °C, a cool
    /// lab (a stated choice; the paper's tests run 25-45 °C).
    pub min_temperature_c: f64,
    /// Highest such temperature [°C]: 45 °C, the top of the paper's thermal tests (Sec. IV-B).
    pub max_temperature_c: f64,
    /// Least gap between two windows on one channel \[nm\]: 0.65 nm, one reflection line's full
    /// width at half maximum (`interrogator.spectral.fwhm_nm`, paper: 0.6-0.7 nm). Closer, the two
    /// lines' halves overlap and a centroid detector at half height sees one peak between them.
    pub guard_nm: f64,
    /// The array's slip cue (`tendril_control::array_cue`): an alarm when this fraction of the
    /// pads' load has moved from pad to pad against its slow average [-]. 0.3, a stated choice
    /// (about a third of the load moved): with it, on the whole-link default it was set on, the
    /// cue stayed silent in every held run of the placement study and saw the knocked crimpers'
    /// drops; on today's half-link default it alarms in some held runs and early in the knocked
    /// crimpers' lifts, before their knocks (docs/studies/placement.md). Not retuned yet.
    pub cue_transfer: f64,
    /// Time constant of the shares' slow average \[s\]: 1 s, the time the lift takes to bring the
    /// object's weight on (its acceleration ramp), so that drift is followed and a knock is not.
    pub cue_tau_s: f64,
    /// Least load on the pads together for the cue to watch \[N\]: 0.2 N, about thirty times one
    /// sample's noise (3 pm over 527 pm/N, paper Sec. IV-B); below it no distribution is known.
    pub cue_min_load_n: f64,
    /// Acting on the cue: from its first alarm in a carry the setpoint is multiplied by this
    /// factor for the rest of the run [-]; 1: the cue only reports (the default).
    pub retighten_factor: f64,
    /// Each further pad's own eq. 8 calibration, in `pads`' order (`[[array.calibrations]]`, the
    /// keys of `[estimator]`), from the bench procedures run on that pad; empty: every pad uses
    /// `[estimator]`'s (the pads are one build).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub calibrations: Vec<crate::estimate::ForceCalibration>,
}

impl Default for ArrayConfig {
    fn default() -> Self {
        ArrayConfig {
            pads: Vec::new(),
            control: ArraySignal::First,
            min_temperature_c: 15.0,
            max_temperature_c: 45.0,
            guard_nm: 0.65,
            cue_transfer: 0.3,
            cue_tau_s: 1.0,
            cue_min_load_n: 0.2,
            retighten_factor: 1.0,
            calibrations: Vec::new(),
        }
    }
}

impl Validate for ArrayConfig {
    fn validate(&self, at: &mut Checker) {
        at.require("pads", self.pads.len() <= MAX_EXTRA_PADS, || {
            format!("at most {MAX_EXTRA_PADS} further pads ({MAX_PADS} with pad 0), got {}", self.pads.len())
        });
        for (i, p) in self.pads.iter().enumerate() {
            at.finite(&format!("pads[{i}].arc_m"), p.arc_m);
            at.require(&format!("pads[{i}].channel"), (1..=MAX_CHANNELS).contains(&p.channel), || {
                format!("must be 1..={MAX_CHANNELS}, got {}", p.channel)
            });
            at.in_range(&format!("pads[{i}].lambda1_nm"), p.lambda1_nm, BAND_MIN_NM, BAND_MAX_NM);
            if let Some(l2) = p.lambda2_nm {
                at.in_range(&format!("pads[{i}].lambda2_nm"), l2, BAND_MIN_NM, BAND_MAX_NM);
            }
            if let Some(h) = p.protrusion_m {
                // As finger.pad_protrusion_m: from a bump just proud of the face to the casing and
                // bump standing on it.
                at.in_range(&format!("pads[{i}].protrusion_m"), h, 0.0005, 0.0055);
            }
        }
        at.finite("min_temperature_c", self.min_temperature_c);
        at.require("max_temperature_c", self.max_temperature_c >= self.min_temperature_c, || {
            format!("must not be below min_temperature_c ({})", self.min_temperature_c)
        });
        at.in_range("guard_nm", self.guard_nm, 0.0, 10.0);
        // A transfer is a fraction of the load (at most 1); 0 would alarm on every tick's noise.
        at.require("cue_transfer", self.cue_transfer > 0.0 && self.cue_transfer <= 1.0, || {
            format!("must be > 0 and at most 1, got {}", self.cue_transfer)
        });
        // 60 s: longer than any carry of the task, beyond which the average never moves.
        at.in_range("cue_tau_s", self.cue_tau_s, 0.0, 60.0);
        // Up to the range of all eight pads together (8 × 4.69 N).
        at.in_range("cue_min_load_n", self.cue_min_load_n, 0.0, 8.0 * 4.69);
        // At most 3×: a setpoint above the sensor's range is refused anyway, and the grip's
        // force grows with it (docs/guide/array.md).
        at.in_range("retighten_factor", self.retighten_factor, 1.0, 3.0);
        at.require("calibrations", self.calibrations.is_empty() || self.calibrations.len() == self.pads.len(), || {
            format!("one per further pad ({}) or none, got {}", self.pads.len(), self.calibrations.len())
        });
        for (i, c) in self.calibrations.iter().enumerate() {
            at.section(&format!("calibrations[{i}]"), c);
        }
    }
}

/// Which of a pad's gratings.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GratingRole {
    /// FBG1, under the uvula: strain and temperature.
    Strain,
    /// FBG2, strain-free: temperature only.
    Reference,
}

/// Where one grating's peak can be: the wavelength window it moves over.
#[derive(Debug, Clone, PartialEq)]
pub struct GratingWindow {
    /// The pad (0: the paper's).
    pub pad: usize,
    /// Strain or reference grating.
    pub role: GratingRole,
    /// Interrogator channel (1-based).
    pub channel: usize,
    /// Lowest wavelength the peak reaches \[nm\].
    pub low_nm: f64,
    /// Highest wavelength the peak reaches \[nm\].
    pub high_nm: f64,
    /// The scenario key that sets the grating's wavelength (for errors).
    pub key: String,
}

impl ArrayConfig {
    /// Whether this is the default section (no further pad, every setting at its default): what a
    /// scenario without `[array]` has, and what a recorded scenario leaves out.
    pub fn is_default(&self) -> bool {
        *self == ArrayConfig::default()
    }

    /// Whether the layout is the paper's single pad.
    pub fn is_single(&self) -> bool {
        self.pads.is_empty()
    }

    /// Number of pads, pad 0 included.
    pub fn pad_count(&self) -> usize {
        1 + self.pads.len()
    }

    /// The sensor model of further pad `k` (1-based: pad 0 is `sensor` itself): `sensor` with the
    /// pad's own wavelengths (a shared reference keeps pad 0's `lambda2_nm`, and so its peak).
    pub fn pad_sensor(&self, sensor: &SensorConfig, k: usize) -> SensorConfig {
        let p = &self.pads[k - 1];
        SensorConfig {
            lambda1_nm: p.lambda1_nm,
            lambda2_nm: p.lambda2_nm.unwrap_or(sensor.lambda2_nm),
            ..sensor.clone()
        }
    }

    /// Every grating of the layout with its window, pad 0's on `first_channel`; a shared reference
    /// grating is listed once.
    pub fn windows(&self, sensor: &SensorConfig, first_channel: usize) -> Vec<GratingWindow> {
        let thermal = |k_pm_per_c: f64| {
            let a = k_pm_per_c * (self.min_temperature_c - sensor.reference_temperature_c) * 1e-3;
            let b = k_pm_per_c * (self.max_temperature_c - sensor.reference_temperature_c) * 1e-3;
            (a.min(b), a.max(b))
        };
        let (t1_lo, t1_hi) = thermal(sensor.kt1_pm_per_c);
        let (t2_lo, t2_hi) = thermal(sensor.kt2_pm_per_c);
        let span_nm = sensor.backbone_pm(sensor.range_n) * 1e-3;
        let strain = |pad, channel, l1: f64, key: String| GratingWindow {
            pad,
            role: GratingRole::Strain,
            channel,
            low_nm: l1 + t1_lo + span_nm.min(0.0),
            high_nm: l1 + t1_hi + span_nm.max(0.0),
            key,
        };
        let reference = |pad, channel, l2: f64, key: String| GratingWindow {
            pad,
            role: GratingRole::Reference,
            channel,
            low_nm: l2 + t2_lo,
            high_nm: l2 + t2_hi,
            key,
        };
        let mut out = vec![
            strain(0, first_channel, sensor.lambda1_nm, "sensor.lambda1_nm".into()),
            reference(0, first_channel, sensor.lambda2_nm, "sensor.lambda2_nm".into()),
        ];
        for (i, p) in self.pads.iter().enumerate() {
            out.push(strain(i + 1, p.channel, p.lambda1_nm, format!("array.pads[{i}].lambda1_nm")));
            if let Some(l2) = p.lambda2_nm {
                out.push(reference(i + 1, p.channel, l2, format!("array.pads[{i}].lambda2_nm")));
            }
        }
        out
    }

    /// The layout's multiplexing faults, as (scenario key, reason): a window outside the band, two
    /// windows on one channel closer than the guard, a pad sharing pad 0's reference on another
    /// fibre. Empty when the layout can be read.
    pub fn multiplexing_faults(&self, sensor: &SensorConfig, first_channel: usize) -> Vec<(String, String)> {
        let mut faults = Vec::new();
        for (i, p) in self.pads.iter().enumerate() {
            if p.lambda2_nm.is_none() && p.channel != first_channel {
                faults.push((
                    format!("array.pads[{i}].lambda2_nm"),
                    format!(
                        "the pad is on channel {} and shares pad 0's reference grating, which is on channel \
                         {first_channel}: give it its own reference (lambda2_nm) or put it on channel {first_channel}",
                        p.channel
                    ),
                ));
            }
        }
        let windows = self.windows(sensor, first_channel);
        for w in &windows {
            if w.low_nm < BAND_MIN_NM || w.high_nm > BAND_MAX_NM {
                faults.push((
                    w.key.clone(),
                    format!(
                        "the grating's peak moves over {:.2}-{:.2} nm, outside the interrogator's {BAND_MIN_NM}-{BAND_MAX_NM} nm band",
                        w.low_nm, w.high_nm
                    ),
                ));
            }
        }
        for (a, wa) in windows.iter().enumerate() {
            for wb in windows.iter().skip(a + 1) {
                let gap = (wb.low_nm - wa.high_nm).max(wa.low_nm - wb.high_nm);
                if wa.channel == wb.channel && gap < self.guard_nm {
                    faults.push((
                        wb.key.clone(),
                        format!(
                            "its window {:.2}-{:.2} nm comes within {:.2} nm of {}'s {:.2}-{:.2} nm on channel {} \
                             (at least guard_nm = {} nm apart, or another channel)",
                            wb.low_nm, wb.high_nm, gap, wa.key, wa.low_nm, wa.high_nm, wa.channel, self.guard_nm
                        ),
                    ));
                }
            }
        }
        faults
    }
}

/// Up to [`MAX_EXTRA_PADS`] values, one per further pad (pad 0's stay where they were without an
/// array): a fixed size, so the per-tick readings stay `Copy` and allocate nothing.
#[derive(Debug, Clone, Copy, Default)]
pub struct PerPad<T: Copy + Default> {
    len: u8,
    values: [T; MAX_EXTRA_PADS],
}

impl<T: Copy + Default> PerPad<T> {
    /// `n` further pads, each `value` (`n` capped at [`MAX_EXTRA_PADS`]).
    pub fn filled(n: usize, value: T) -> Self {
        let mut v = PerPad { len: n.min(MAX_EXTRA_PADS) as u8, values: [T::default(); MAX_EXTRA_PADS] };
        v.values[..v.len as usize].fill(value);
        v
    }

    /// The values, further pad 1 first.
    pub fn as_slice(&self) -> &[T] {
        &self.values[..self.len as usize]
    }

    /// The values, mutably.
    pub fn as_mut_slice(&mut self) -> &mut [T] {
        &mut self.values[..self.len as usize]
    }

    /// Number of further pads.
    pub fn len(&self) -> usize {
        self.len as usize
    }

    /// Whether there is none (the paper's single pad).
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

impl<T: Copy + Default + PartialEq> PartialEq for PerPad<T> {
    /// The pads' values only (the unused slots are not part of the value).
    fn eq(&self, other: &Self) -> bool {
        self.as_slice() == other.as_slice()
    }
}

impl<T: Copy + Default + Serialize> Serialize for PerPad<T> {
    /// As a list of the further pads' values.
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.as_slice().serialize(s)
    }
}

/// The further pads' interrogator samples (pad 0's is `CellState::wavelengths`).
pub type ArrayPeaks = PerPad<Wavelengths>;

#[cfg(test)]
mod tests {
    use super::*;

    fn pad(arc_m: f64, lambda1_nm: f64) -> ArrayPad {
        ArrayPad { arc_m, channel: 1, lambda1_nm, lambda2_nm: None, protrusion_m: None }
    }

    #[test]
    fn the_default_layout_is_the_single_pad_and_reads() {
        let a = ArrayConfig::default();
        assert!(a.is_single());
        assert!(a.multiplexing_faults(&SensorConfig::default(), 1).is_empty());
    }

    #[test]
    fn pad_zeros_strain_window_spans_the_range_and_the_temperatures() {
        let w = ArrayConfig::default().windows(&SensorConfig::default(), 1);
        // 1540 nm - 10 °C × 24.29 pm/°C up to 1540 nm + the backbone at 4.69 N (5.795 nm: the
        // hysteresis-free curve, above the loading branch's 5.48 nm) + 20 °C × 24.29 pm/°C.
        assert!((w[0].low_nm - 1539.757).abs() < 0.01, "{w:?}");
        assert!((w[0].high_nm - (1540.0 + 5.795 + 0.4858)).abs() < 0.01, "{w:?}");
        assert_eq!(w[1].role, GratingRole::Reference);
    }

    #[test]
    fn three_pads_fit_on_one_fibre_and_a_crowded_one_is_refused_with_its_key() {
        let sensor = SensorConfig::default();
        let good = ArrayConfig { pads: vec![pad(0.03, 1525.0), pad(0.09, 1560.0)], ..ArrayConfig::default() };
        assert!(good.multiplexing_faults(&sensor, 1).is_empty(), "{:?}", good.multiplexing_faults(&sensor, 1));
        let crowded = ArrayConfig { pads: vec![pad(0.03, 1543.0)], ..ArrayConfig::default() };
        let faults = crowded.multiplexing_faults(&sensor, 1);
        assert_eq!(faults[0].0, "array.pads[0].lambda1_nm", "{faults:?}");
        assert!(faults[0].1.contains("sensor.lambda1_nm"), "{faults:?}");
        // The same grating on its own fibre (with its own reference) reads.
        let apart = ArrayConfig {
            pads: vec![ArrayPad { channel: 2, lambda2_nm: Some(1556.0), ..pad(0.03, 1543.0) }],
            ..ArrayConfig::default()
        };
        assert!(apart.multiplexing_faults(&sensor, 1).is_empty(), "{:?}", apart.multiplexing_faults(&sensor, 1));
    }

    #[test]
    fn a_window_out_of_band_and_a_reference_shared_across_fibres_are_refused() {
        let sensor = SensorConfig::default();
        let high = ArrayConfig { pads: vec![pad(0.03, 1596.0)], ..ArrayConfig::default() };
        assert!(high.multiplexing_faults(&sensor, 1)[0].1.contains("band"));
        let other_fibre =
            ArrayConfig { pads: vec![ArrayPad { channel: 2, ..pad(0.03, 1560.0) }], ..ArrayConfig::default() };
        assert_eq!(other_fibre.multiplexing_faults(&sensor, 1)[0].0, "array.pads[0].lambda2_nm");
    }

    #[test]
    fn the_signals_over_the_pads() {
        let f = [0.5, 0.25, 1.0];
        assert_eq!(ArraySignal::First.of(&f), 0.5);
        assert_eq!(ArraySignal::Total.of(&f), 1.75);
        assert_eq!(ArraySignal::Max.of(&f), 1.0);
    }

    #[test]
    fn per_pad_values_keep_their_count() {
        let mut p = PerPad::filled(3, 0.0_f64);
        p.as_mut_slice()[2] = 4.0;
        assert_eq!(p.as_slice(), &[0.0, 0.0, 4.0]);
        assert!(PerPad::<f64>::default().is_empty());
    }
}
