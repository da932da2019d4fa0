//! Spectral mode for a sensor array: every grating of a channel in one sampled spectrum, its peaks
//! found as the interrogator finds them (each run of samples above the threshold is one peak, at
//! its centroid) and handed to gratings by their windows.
//!
//! Two lines closer than about their width merge into one run above the threshold: the
//! interrogator then reports one peak between them, which at most one grating can have: the
//! other has no peak (NaN), and a window holding two peaks, or a peak two windows hold, gives none. The estimator
//! treats a NaN sample as invalid and holds the last estimate, as the real path does with a scan
//! it cannot map. The layout check (`ArrayConfig::multiplexing_faults`) keeps windows a line width
//! apart, so this happens only with a smaller `array.guard_nm`.

use super::array::GratingWindow;
use super::config::SpectralConfig;
use rand::Rng;
use rand_distr::StandardNormal;

/// One channel's sampled spectrum and the gratings on it.
#[derive(Debug, Clone)]
struct Channel {
    channel: usize,
    grid_nm: Vec<f64>,
    spectrum: Vec<f64>,
    /// Indices into the layout's gratings (`ArrayConfig::windows` order) and their windows.
    gratings: Vec<(usize, f64, f64)>,
}

/// The array's channels in spectral mode.
#[derive(Debug, Clone)]
pub struct ArraySpectra {
    cfg: SpectralConfig,
    channels: Vec<Channel>,
    shape: f64,
}

impl ArraySpectra {
    /// Spectra over each channel of `windows` (the layout's gratings, `ArrayConfig::windows`),
    /// each sampled on `cfg`'s step from 1 nm below its lowest window to 1 nm above its highest
    /// (`cfg.start_nm`, `end_nm` and `channel_split_nm` are the single pad's and do not apply).
    pub fn new(cfg: &SpectralConfig, windows: &[GratingWindow]) -> ArraySpectra {
        let mut numbers: Vec<usize> = windows.iter().map(|w| w.channel).collect();
        numbers.sort_unstable();
        numbers.dedup();
        let step = cfg.step_pm / 1000.0;
        let channels = numbers
            .into_iter()
            .map(|channel| {
                let gratings: Vec<(usize, f64, f64)> = windows
                    .iter()
                    .enumerate()
                    .filter(|(_, w)| w.channel == channel)
                    .map(|(i, w)| (i, w.low_nm, w.high_nm))
                    .collect();
                let lo = gratings.iter().map(|g| g.1).fold(f64::INFINITY, f64::min) - 1.0;
                let hi = gratings.iter().map(|g| g.2).fold(f64::NEG_INFINITY, f64::max) + 1.0;
                let n = ((hi - lo) / step).floor() as usize + 1;
                Channel {
                    channel,
                    grid_nm: (0..n).map(|i| lo + i as f64 * step).collect(),
                    spectrum: vec![0.0; n],
                    gratings,
                }
            })
            .collect();
        ArraySpectra { cfg: cfg.clone(), channels, shape: -4.0 * std::f64::consts::LN_2 / (cfg.fwhm_nm * cfg.fwhm_nm) }
    }

    /// Samples every channel for the gratings' true Bragg wavelengths `true_nm` (in the windows'
    /// order) and returns each grating's detected peak \[nm\], NaN where its window holds no peak
    /// or more than one.
    pub fn detect<R: Rng>(&mut self, true_nm: &[f64], rng: &mut R) -> Vec<f64> {
        let mut out = vec![f64::NAN; true_nm.len()];
        let (r, noise, shape, reach) =
            (self.cfg.reflectivity, self.cfg.intensity_noise, self.shape, 3.0 * self.cfg.fwhm_nm);
        for ch in &mut self.channels {
            let lines: Vec<f64> = ch.gratings.iter().map(|g| true_nm[g.0]).collect();
            for (s, &l) in ch.spectrum.iter_mut().zip(&ch.grid_nm) {
                let v: f64 =
                    lines.iter().map(|b| l - b).filter(|d| d.abs() < reach).map(|d| r * (shape * d * d).exp()).sum();
                let z: f64 = rng.sample(StandardNormal);
                *s = v + noise * z;
            }
            // The level is the threshold of a full line (the single pad's detector takes it of the
            // channel's maximum, which with several lines is the same line height); a quarter of
            // the line's width is the narrowest run that is a line.
            let peaks = peaks(&ch.grid_nm, &ch.spectrum, self.cfg.threshold * r, self.cfg.fwhm_nm / 4.0);
            // A peak counts for a grating when it is the only one in the grating's window and no
            // other window holds it (overlapping windows cannot tell whose it is).
            let holders = |p: f64| ch.gratings.iter().filter(|g| p >= g.1 && p < g.2).count();
            for &(i, lo, hi) in &ch.gratings {
                let mut inside = peaks.iter().filter(|&&p| p >= lo && p < hi);
                if let (Some(&p), None) = (inside.next(), inside.next())
                    && holders(p) == 1
                {
                    out[i] = p;
                }
            }
        }
        out
    }

    /// The channels the spectra cover (1-based).
    pub fn channels(&self) -> Vec<usize> {
        self.channels.iter().map(|c| c.channel).collect()
    }
}

/// Every run of samples above `level`, as the centroid of its excess over the level \[nm\]. The
/// intensity noise crosses the level now and then near a line's flanks: runs apart by at most
/// [`MERGE_GAP`] samples are one run, and a run narrower than `min_width_nm` (a noise blip; a
/// line's run at half height is its full width) is no peak.
fn peaks(grid_nm: &[f64], intensity: &[f64], level: f64, min_width_nm: f64) -> Vec<f64> {
    let mut out = Vec::new();
    let (mut num, mut den) = (0.0, 0.0);
    let (mut first, mut last, mut below) = (f64::NAN, f64::NAN, 0usize);
    let close = |num: f64, den: f64, first: f64, last: f64, out: &mut Vec<f64>| {
        if den > 0.0 && last - first >= min_width_nm {
            out.push(num / den);
        }
    };
    for (&l, &v) in grid_nm.iter().zip(intensity) {
        if v > level {
            if den == 0.0 {
                first = l;
            }
            num += (v - level) * l;
            den += v - level;
            last = l;
            below = 0;
        } else if den > 0.0 {
            below += 1;
            if below > MERGE_GAP {
                close(num, den, first, last, &mut out);
                (num, den) = (0.0, 0.0);
            }
        }
    }
    close(num, den, first, last, &mut out);
    out
}

/// Samples below the level that still join two runs into one peak: 2 (20 pm on the default
/// 10 pm grid), a noise dip inside a line's top, far below a line's width.
const MERGE_GAP: usize = 2;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::array::{ArrayConfig, ArrayPad};
    use crate::config::SensorConfig;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    fn layout(guard_nm: f64, lambda1_nm: f64) -> Vec<GratingWindow> {
        let pad = ArrayPad { arc_m: 0.03, channel: 1, lambda1_nm, lambda2_nm: None, protrusion_m: None };
        ArrayConfig { pads: vec![pad], guard_nm, ..ArrayConfig::default() }.windows(&SensorConfig::default(), 1)
    }

    #[test]
    fn every_grating_of_a_channel_is_found_in_its_window() {
        let windows = layout(0.65, 1525.0);
        let mut s = ArraySpectra::new(&SpectralConfig { intensity_noise: 0.0, ..SpectralConfig::default() }, &windows);
        let truth = [1541.2345, 1550.0123, 1527.5];
        let found = s.detect(&truth, &mut ChaCha8Rng::seed_from_u64(1));
        for (t, f) in truth.iter().zip(&found) {
            assert!((t - f).abs() < 1e-3, "{truth:?} → {found:?}");
        }
        assert_eq!(s.channels(), vec![1]);
    }

    #[test]
    fn two_lines_closer_than_their_width_read_as_one_peak_and_a_missing_one() {
        // A layout whose guard was set to nothing: pad 1's strain window runs into pad 0's.
        let windows = layout(0.0, 1534.0);
        let mut s = ArraySpectra::new(&SpectralConfig { intensity_noise: 0.0, ..SpectralConfig::default() }, &windows);
        // Pad 1 strained up to 1540.2 nm, 0.2 nm from pad 0's unloaded 1540.0 nm.
        let found = s.detect(&[1540.0, 1550.0, 1540.2], &mut ChaCha8Rng::seed_from_u64(1));
        assert!((found[1] - 1550.0).abs() < 1e-3, "the reference stands alone: {found:?}");
        assert!(found[0].is_nan() || found[2].is_nan(), "one merged peak cannot be both: {found:?}");
        // Apart, each in its own part of the overlapping windows, both are read again.
        let found = s.detect(&[1541.0, 1550.0, 1538.0], &mut ChaCha8Rng::seed_from_u64(1));
        assert!((found[0] - 1541.0).abs() < 1e-3 && (found[2] - 1538.0).abs() < 1e-3, "{found:?}");
    }
}
