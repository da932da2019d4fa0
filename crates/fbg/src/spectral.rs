//! Spectral mode of the interrogator: sampled reflection spectra and a centroid peak detector.

use super::config::SpectralConfig;
use rand::Rng;
use rand_distr::StandardNormal;

/// Simulates the sampled spectrum of the two gratings and detects both peaks.
#[derive(Debug, Clone)]
pub struct SpectralInterrogator {
    cfg: SpectralConfig,
    grid_nm: Vec<f64>,
    spectrum: Vec<f64>,
    split: usize,
    // −4 ln 2 / FWHM²: the Gaussian line's exponent factor [1/nm²].
    shape: f64,
}

impl SpectralInterrogator {
    /// Builds the wavelength grid for a validated configuration.
    pub fn new(cfg: &SpectralConfig) -> SpectralInterrogator {
        let step = cfg.step_pm / 1000.0;
        let n = ((cfg.end_nm - cfg.start_nm) / step).floor() as usize + 1;
        let grid_nm: Vec<f64> = (0..n).map(|i| cfg.start_nm + i as f64 * step).collect();
        let split = grid_nm.partition_point(|&l| l < cfg.channel_split_nm);
        SpectralInterrogator {
            cfg: cfg.clone(),
            spectrum: vec![0.0; n],
            grid_nm,
            split,
            shape: -4.0 * std::f64::consts::LN_2 / (cfg.fwhm_nm * cfg.fwhm_nm),
        }
    }

    /// The last sampled spectrum (reflectivity per grid point) and its grid \[nm\].
    pub fn spectrum(&self) -> (&[f64], &[f64]) {
        (&self.grid_nm, &self.spectrum)
    }

    /// Samples the spectrum for true Bragg wavelengths `b1_nm`, `b2_nm` and returns the detected peaks \[nm\].
    pub fn detect<R: Rng>(&mut self, b1_nm: f64, b2_nm: f64, rng: &mut R) -> (f64, f64) {
        let (r, noise, shape) = (self.cfg.reflectivity, self.cfg.intensity_noise, self.shape);
        for (s, &l) in self.spectrum.iter_mut().zip(&self.grid_nm) {
            let (d1, d2) = (l - b1_nm, l - b2_nm);
            // Lines are negligible beyond 3 FWHM (e^-25); skipping the exp there halves the cost.
            let mut v = 0.0;
            if d1.abs() < 3.0 * self.cfg.fwhm_nm {
                v += r * (shape * d1 * d1).exp();
            }
            if d2.abs() < 3.0 * self.cfg.fwhm_nm {
                v += r * (shape * d2 * d2).exp();
            }
            let z: f64 = rng.sample(StandardNormal);
            *s = v + noise * z;
        }
        let p1 = centroid(&self.grid_nm[..self.split], &self.spectrum[..self.split], self.cfg.threshold);
        let p2 = centroid(&self.grid_nm[self.split..], &self.spectrum[self.split..], self.cfg.threshold);
        (p1.unwrap_or(b1_nm), p2.unwrap_or(b2_nm))
    }
}

/// The noise-free reflection spectrum of gratings at `lines_nm` \[nm\] on `cfg`'s grid: the same
/// Gaussian lines (FWHM, peak reflectivity) [`SpectralInterrogator`] samples, summed, without its
/// intensity noise (for the virtual interrogator's `#GetSpectrum`). Returns (grid, reflectivity).
pub fn line_spectrum(cfg: &SpectralConfig, lines_nm: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let step = cfg.step_pm / 1000.0;
    let n = ((cfg.end_nm - cfg.start_nm) / step).floor() as usize + 1;
    let shape = -4.0 * std::f64::consts::LN_2 / (cfg.fwhm_nm * cfg.fwhm_nm);
    let grid: Vec<f64> = (0..n).map(|i| cfg.start_nm + i as f64 * step).collect();
    let reflectivity = grid
        .iter()
        .map(|&l| {
            lines_nm
                .iter()
                .map(|&b| l - b)
                .filter(|d| d.abs() < 3.0 * cfg.fwhm_nm)
                .map(|d| cfg.reflectivity * (shape * d * d).exp())
                .sum()
        })
        .collect();
    (grid, reflectivity)
}

/// Centroid of the contiguous run of samples above `threshold` × maximum around the maximum;
/// `None` for an empty channel or a flat (non-positive) maximum.
pub fn centroid(grid_nm: &[f64], intensity: &[f64], threshold: f64) -> Option<f64> {
    let (imax, &max) = intensity.iter().enumerate().max_by(|a, b| a.1.total_cmp(b.1))?;
    if max <= 0.0 {
        return None;
    }
    let level = threshold * max;
    let mut lo = imax;
    while lo > 0 && intensity[lo - 1] > level {
        lo -= 1;
    }
    let mut hi = imax;
    while hi + 1 < intensity.len() && intensity[hi + 1] > level {
        hi += 1;
    }
    // Weights above the threshold level, so samples at the edge of the run count for little.
    let (mut num, mut den) = (0.0, 0.0);
    for i in lo..=hi {
        let w = intensity[i] - level;
        num += w * grid_nm[i];
        den += w;
    }
    if den > 0.0 { Some(num / den) } else { Some(grid_nm[imax]) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn noiseless_centroid_finds_peaks_off_grid_within_a_picometre() {
        let cfg = SpectralConfig { intensity_noise: 0.0, ..SpectralConfig::default() };
        let mut s = SpectralInterrogator::new(&cfg);
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        for k in 0..20 {
            let b1 = 1540.0 + 0.2731 * k as f64;
            let (p1, p2) = s.detect(b1, 1550.0037, &mut rng);
            assert!((p1 - b1).abs() < 1e-3, "{p1} vs {b1}");
            assert!((p2 - 1550.0037).abs() < 1e-3, "{p2}");
        }
    }

    #[test]
    fn the_line_spectrum_peaks_at_the_lines_with_the_configured_reflectivity() {
        let cfg = SpectralConfig::default();
        let (grid, r) = line_spectrum(&cfg, &[1540.0, 1550.0]);
        assert_eq!(grid.len(), 1801);
        let at = |nm: f64| r[grid.iter().position(|&l| (l - nm).abs() < 1e-6).unwrap()];
        assert!((at(1540.0) - cfg.reflectivity).abs() < 1e-12);
        let half = cfg.reflectivity * (-4.0 * std::f64::consts::LN_2 * 0.09 / (cfg.fwhm_nm * cfg.fwhm_nm)).exp();
        assert!((at(1540.3) - half).abs() < 1e-9, "the Gaussian line 0.3 nm off its centre");
        assert_eq!(at(1545.0), 0.0);
        let split = grid.partition_point(|&l| l < cfg.channel_split_nm);
        let centre = centroid(&grid[..split], &r[..split], cfg.threshold).unwrap();
        assert!((centre - 1540.0).abs() < 1e-3, "{centre}");
    }

    #[test]
    fn noisy_peaks_jitter_by_a_few_picometres() {
        let mut s = SpectralInterrogator::new(&SpectralConfig::default());
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let errs: Vec<f64> = (0..2000).map(|_| (s.detect(1542.0, 1550.0, &mut rng).0 - 1542.0) * 1000.0).collect();
        let rms = (errs.iter().map(|e| e * e).sum::<f64>() / errs.len() as f64).sqrt();
        println!("spectral peak jitter {rms:.2} pm");
        assert!(rms > 2.0 && rms < 4.0, "peak jitter {rms} pm (the paper: ≈ 3 pm)");
    }
}
