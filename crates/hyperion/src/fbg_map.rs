//! Peaks to FBG1/FBG2 by wavelength window, pad 0's and a sensor array's further pads'.
//!
//! The sensor's two gratings sit near 1540 nm (FBG1, strain + temperature) and 1550 nm (FBG2,
//! temperature only) (paper; `signals::Wavelengths`). Each window must hold exactly one peak of
//! its channel: none is a missing grating, two is an ambiguity we refuse to guess at; either error
//! names the pad, the grating, the window and the channel. A further pad sharing pad 0's reference
//! grating has no FBG2 window and reads pad 0's FBG2 peak.
//!
//! [`FbgWindows::peak_channels`] is the other way round: every grating's peak on its channel, as
//! the instrument reports a scan (each channel's peaks in ascending wavelength).

use serde::{Deserialize, Serialize};

use super::pad_windows::{PadWindowList, PadWindows};
use super::peaks::PeakFrame;
use tendril_config::{Checker, Validate};
use tendril_fbg::array::{ArrayPeaks, PerPad};
use tendril_fbg::signals::Wavelengths;

/// Where to look for each grating's peak: pad 0's (the paper's sensor) and, with a sensor array,
/// each further pad's.
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
    /// A sensor array's further pads' windows \[-\]: one table per pad of `array.pads`, in its
    /// order, with `channel`, `fbg1_min_nm`, `fbg1_max_nm` and, for a pad with its own reference,
    /// `fbg2_min_nm`, `fbg2_max_nm`; none: derived from the `array` layout, each grating's range
    /// widened halfway into the gap to its neighbours (docs/cell/devices.md#a-sensor-arrays-windows).
    #[serde(skip_serializing_if = "PadWindowList::is_empty")]
    pub pads: PadWindowList,
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
        Self {
            channel: 1,
            fbg1_min_nm: 1535.0,
            fbg1_max_nm: 1547.8,
            fbg2_min_nm: 1547.8,
            fbg2_max_nm: 1555.0,
            pads: PadWindowList::default(),
        }
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
        for (i, p) in self.pads.as_slice().iter().enumerate() {
            p.validate_at(&format!("pads[{i}]."), at);
        }
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
    #[error("pad {pad}: no FBG{fbg} peak in [{min_nm:.2}, {max_nm:.2}) nm on channel {channel}")]
    Missing {
        /// The pad (0: the paper's).
        pad: usize,
        /// 1 or 2.
        fbg: u8,
        /// Window lower edge.
        min_nm: f64,
        /// Window upper edge.
        max_nm: f64,
        /// The window's channel (1-based).
        channel: usize,
    },
    /// More than one peak in a grating's window.
    #[error(
        "pad {pad}: {count} peaks in the FBG{fbg} window [{min_nm:.2}, {max_nm:.2}) nm on channel {channel}, expected one"
    )]
    Ambiguous {
        /// The pad (0: the paper's).
        pad: usize,
        /// 1 or 2.
        fbg: u8,
        /// Peaks found.
        count: usize,
        /// Window lower edge.
        min_nm: f64,
        /// Window upper edge.
        max_nm: f64,
        /// The window's channel (1-based).
        channel: usize,
    },
}

impl FbgWindows {
    /// Pad 0's FBG1/FBG2 wavelengths of one scan.
    pub fn map(&self, frame: &PeakFrame) -> Result<Wavelengths, FbgMapError> {
        let peaks = channel(frame, self.channel)?;
        let window = |fbg, min_nm, max_nm| Window { pad: 0, fbg, min_nm, max_nm, channel: self.channel };
        Ok(Wavelengths {
            fbg1_nm: window(1, self.fbg1_min_nm, self.fbg1_max_nm).pick(peaks)?,
            fbg2_nm: window(2, self.fbg2_min_nm, self.fbg2_max_nm).pick(peaks)?,
        })
    }

    /// Every pad's wavelengths of one scan: pad 0's, and each further pad's in the order of
    /// [`FbgWindows::pads`] (a pad without an FBG2 window gets pad 0's FBG2 peak).
    pub fn map_all(&self, frame: &PeakFrame) -> Result<(Wavelengths, ArrayPeaks), FbgMapError> {
        let first = self.map(frame)?;
        let mut array = PerPad::filled(self.pads.len(), Wavelengths::default());
        for (k, (p, out)) in self.pads.as_slice().iter().zip(array.as_mut_slice()).enumerate() {
            let peaks = channel(frame, p.channel)?;
            let window = |fbg, min_nm, max_nm| Window { pad: k + 1, fbg, min_nm, max_nm, channel: p.channel };
            *out = Wavelengths {
                fbg1_nm: window(1, p.fbg1_min_nm, p.fbg1_max_nm).pick(peaks)?,
                fbg2_nm: match p.fbg2() {
                    Some((lo, hi)) => window(2, lo, hi).pick(peaks)?,
                    None => first.fbg2_nm,
                },
            };
        }
        Ok((first, array))
    }

    /// The highest channel a window is on: the instrument must have at least as many.
    pub fn highest_channel(&self) -> usize {
        self.pads.as_slice().iter().map(|p| p.channel).fold(self.channel, usize::max)
    }

    /// A scan's peaks per channel, channel 1 first, up to [`FbgWindows::highest_channel`]: pad 0's
    /// two gratings on its channel, each further pad's FBG1 (and own FBG2) on the pad's, each
    /// channel's peaks in ascending wavelength as the instrument reports them. `array` holds the
    /// further pads' samples in the order of [`FbgWindows::pads`] (a pad sharing pad 0's
    /// reference adds no peak of its own).
    pub fn peak_channels(&self, first: Wavelengths, array: &ArrayPeaks) -> Vec<Vec<f64>> {
        let mut channels = vec![Vec::new(); self.highest_channel()];
        // Channel 0 does not pass validation; its peaks would have nowhere to go.
        let mut put = |channel: usize, peaks: &[f64]| {
            if let Some(c) = channel.checked_sub(1).and_then(|i| channels.get_mut(i)) {
                c.extend_from_slice(peaks);
            }
        };
        put(self.channel, &[first.fbg1_nm, first.fbg2_nm]);
        for (p, w) in self.pads.as_slice().iter().zip(array.as_slice()) {
            let own = [w.fbg1_nm, w.fbg2_nm];
            put(p.channel, if p.fbg2().is_some() { &own } else { &own[..1] });
        }
        for peaks in &mut channels {
            peaks.sort_by(f64::total_cmp);
        }
        channels
    }

    /// The further pads' windows.
    pub fn pad_windows(&self) -> &[PadWindows] {
        self.pads.as_slice()
    }
}

fn channel(frame: &PeakFrame, channel: usize) -> Result<&[f64], FbgMapError> {
    frame.channel(channel).ok_or(FbgMapError::NoChannel { channel, available: frame.channels.len() })
}

/// One grating's window, for picking its peak.
struct Window {
    pad: usize,
    fbg: u8,
    min_nm: f64,
    max_nm: f64,
    channel: usize,
}

impl Window {
    fn pick(&self, peaks: &[f64]) -> Result<f64, FbgMapError> {
        let Window { pad, fbg, min_nm, max_nm, channel } = *self;
        let mut inside = peaks.iter().copied().filter(|p| (min_nm..max_nm).contains(p));
        match (inside.next(), inside.count()) {
            (None, _) => Err(FbgMapError::Missing { pad, fbg, min_nm, max_nm, channel }),
            (Some(p), 0) => Ok(p),
            (Some(_), more) => Err(FbgMapError::Ambiguous { pad, fbg, count: more + 1, min_nm, max_nm, channel }),
        }
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
            Err(FbgMapError::Ambiguous { pad: 0, fbg: 1, count: 2, .. })
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
