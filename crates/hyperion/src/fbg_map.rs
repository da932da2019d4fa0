//! Peaks to FBG1/FBG2 by wavelength window.
//!
//! The sensor's two gratings sit near 1540 nm (FBG1, strain + temperature) and 1550 nm (FBG2,
//! temperature only) (paper; `signals::Wavelengths`). Each window must hold exactly one peak of
//! the configured channel: none is a missing grating, two is an ambiguity we refuse to guess at.

use serde::{Deserialize, Serialize};

use super::peaks::PeakFrame;
use tendril_config::{Checker, Validate};
use tendril_fbg::signals::Wavelengths;

/// Where to look for each grating's peak.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FbgWindows {
    /// Interrogator channel the sensor fibre is on (1-based).
    pub channel: usize,
    /// FBG1 window lower edge, nm (inclusive).
    pub fbg1_min_nm: f64,
    /// FBG1 window upper edge, nm (exclusive).
    pub fbg1_max_nm: f64,
    /// FBG2 window lower edge, nm (inclusive).
    pub fbg2_min_nm: f64,
    /// FBG2 window upper edge, nm (exclusive).
    pub fbg2_max_nm: f64,
}

impl Default for FbgWindows {
    /// Channel 1; FBG1 in [1535, 1547.8) nm, FBG2 in [1547.8, 1555) nm. FBG1 (1540 nm unloaded)
    /// rises by up to 5.5 nm under force (the paper's 0 → 5482.78 pm span over its 4.69 N range)
    /// and FBG2 (1550 nm) moves only with temperature (10.31 pm/°C), so the split sits midway
    /// between FBG1 at full range (1545.5 nm) and FBG2: over 2 nm of margin either side, about
    /// 95 °C of heating for FBG1 (24.29 pm/°C) and 210 °C of cooling for FBG2. (The midpoint of the
    /// unloaded wavelengths, 1545 nm, would hand FBG1's peak to FBG2's window from about 4.2 N on,
    /// inside the sensor's range.)
    fn default() -> Self {
        Self { channel: 1, fbg1_min_nm: 1535.0, fbg1_max_nm: 1547.8, fbg2_min_nm: 1547.8, fbg2_max_nm: 1555.0 }
    }
}

impl Validate for FbgWindows {
    fn validate(&self, at: &mut Checker) {
        at.require("channel", (1..=16).contains(&self.channel), || format!("must be 1..=16, got {}", self.channel));
        for (name, value) in [
            ("fbg1_min_nm", self.fbg1_min_nm),
            ("fbg1_max_nm", self.fbg1_max_nm),
            ("fbg2_min_nm", self.fbg2_min_nm),
            ("fbg2_max_nm", self.fbg2_max_nm),
        ] {
            // The si255 sweeps 1460-1620 nm (docs/facts.md#hyperion-wavelength-range, unverified).
            at.in_range(name, value, 1460.0, 1620.0);
        }
        at.require("fbg1_max_nm", self.fbg1_max_nm > self.fbg1_min_nm, || "must exceed fbg1_min_nm".to_string());
        at.require("fbg2_max_nm", self.fbg2_max_nm > self.fbg2_min_nm, || "must exceed fbg2_min_nm".to_string());
        let disjoint = self.fbg1_max_nm <= self.fbg2_min_nm || self.fbg2_max_nm <= self.fbg1_min_nm;
        at.require("fbg2_min_nm", disjoint, || "the FBG1 and FBG2 windows overlap".to_string());
    }
}

/// Why a scan could not be mapped.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FbgMapError {
    /// The frame has no such channel.
    #[error("the scan has no channel {channel} ({available} channels)")]
    NoChannel {
        /// Requested channel.
        channel: usize,
        /// Channels in the frame.
        available: usize,
    },
    /// No peak in a grating's window.
    #[error("no FBG{fbg} peak in [{min_nm}, {max_nm}) nm")]
    Missing {
        /// 1 or 2.
        fbg: u8,
        /// Window lower edge.
        min_nm: f64,
        /// Window upper edge.
        max_nm: f64,
    },
    /// More than one peak in a grating's window.
    #[error("{count} peaks in the FBG{fbg} window, expected one")]
    Ambiguous {
        /// 1 or 2.
        fbg: u8,
        /// Peaks found.
        count: usize,
    },
}

impl FbgWindows {
    /// The FBG1/FBG2 wavelengths of one scan.
    pub fn map(&self, frame: &PeakFrame) -> Result<Wavelengths, FbgMapError> {
        let peaks = frame
            .channel(self.channel)
            .ok_or(FbgMapError::NoChannel { channel: self.channel, available: frame.channels.len() })?;
        Ok(Wavelengths {
            fbg1_nm: pick(peaks, 1, self.fbg1_min_nm, self.fbg1_max_nm)?,
            fbg2_nm: pick(peaks, 2, self.fbg2_min_nm, self.fbg2_max_nm)?,
        })
    }
}

fn pick(peaks: &[f64], fbg: u8, min_nm: f64, max_nm: f64) -> Result<f64, FbgMapError> {
    let mut inside = peaks.iter().copied().filter(|p| (min_nm..max_nm).contains(p));
    match (inside.next(), inside.count()) {
        (None, _) => Err(FbgMapError::Missing { fbg, min_nm, max_nm }),
        (Some(p), 0) => Ok(p),
        (Some(_), more) => Err(FbgMapError::Ambiguous { fbg, count: more + 1 }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(peaks: Vec<f64>) -> PeakFrame {
        PeakFrame { channels: vec![peaks, vec![1541.0]], ..PeakFrame::default() }
    }

    #[test]
    fn maps_one_peak_per_window_in_any_order() {
        let w = FbgWindows::default();
        let got = w.map(&frame(vec![1550.3, 1300.0, 1540.2])).unwrap();
        assert_eq!(got, Wavelengths { fbg1_nm: 1540.2, fbg2_nm: 1550.3 });
    }

    #[test]
    fn missing_ambiguous_and_absent_channel_are_typed_errors() {
        let w = FbgWindows::default();
        assert!(matches!(w.map(&frame(vec![1540.2])), Err(FbgMapError::Missing { fbg: 2, .. })));
        assert!(matches!(
            w.map(&frame(vec![1540.2, 1541.0, 1550.0])),
            Err(FbgMapError::Ambiguous { fbg: 1, count: 2 })
        ));
        assert!(matches!(w.map(&frame(vec![f64::NAN, 1550.0])), Err(FbgMapError::Missing { fbg: 1, .. })));
        let on_three = FbgWindows { channel: 3, ..w };
        assert!(matches!(on_three.map(&frame(vec![])), Err(FbgMapError::NoChannel { channel: 3, available: 2 })));
    }

    #[test]
    fn validation_names_the_key() {
        let mut at = Checker::default();
        FbgWindows { fbg2_min_nm: 1544.0, ..FbgWindows::default() }.validate(&mut at);
        assert_eq!(at.errors()[0].0, "fbg2_min_nm");
        let mut ok = Checker::default();
        FbgWindows::default().validate(&mut ok);
        assert!(ok.errors().is_empty());
    }
}
