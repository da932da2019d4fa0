//! Where a sensor array's further pads' peaks are (`[[hardware.fbg.pads]]`): one [`PadWindows`]
//! per further pad, in the order of `[[array.pads]]`, kept in a fixed-size [`PadWindowList`] so
//! `[hardware]` stays `Copy`.

use serde::{Deserialize, Serialize};
use tendril_config::Checker;
use tendril_fbg::array::MAX_EXTRA_PADS;

/// One further pad's windows: its channel, its FBG1 window and, when the pad has its own
/// temperature reference, its FBG2 window (a pad sharing pad 0's reference has none: it reads pad
/// 0's FBG2 peak).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PadWindows {
    /// Interrogator channel the pad's fibre is on (1-based): the layout's `array.pads[i].channel`.
    #[serde(default = "first_channel")]
    pub channel: usize,
    /// FBG1 window lower edge \[nm\] (inclusive).
    pub fbg1_min_nm: f64,
    /// FBG1 window upper edge \[nm\] (exclusive).
    pub fbg1_max_nm: f64,
    /// FBG2 window lower edge \[nm\] (inclusive); only for a pad with its own reference.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fbg2_min_nm: Option<f64>,
    /// FBG2 window upper edge \[nm\] (exclusive); only for a pad with its own reference.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fbg2_max_nm: Option<f64>,
}

fn first_channel() -> usize {
    1
}

impl Default for PadWindows {
    /// Channel 1, empty windows (a placeholder: every listed pad's windows are set).
    fn default() -> Self {
        PadWindows { channel: 1, fbg1_min_nm: 0.0, fbg1_max_nm: 0.0, fbg2_min_nm: None, fbg2_max_nm: None }
    }
}

impl PadWindows {
    /// The FBG2 window, when the pad has its own reference grating.
    pub fn fbg2(&self) -> Option<(f64, f64)> {
        self.fbg2_min_nm.zip(self.fbg2_max_nm)
    }

    /// Range checks of one pad's windows, under `prefix` (`pads[0].`).
    pub(crate) fn validate_at(&self, prefix: &str, at: &mut Checker) {
        at.require(&format!("{prefix}channel"), (1..=16).contains(&self.channel), || {
            format!("must be 1..=16, got {}", self.channel)
        });
        let mut edges = vec![("fbg1_min_nm", self.fbg1_min_nm), ("fbg1_max_nm", self.fbg1_max_nm)];
        edges.extend(self.fbg2_min_nm.map(|v| ("fbg2_min_nm", v)));
        edges.extend(self.fbg2_max_nm.map(|v| ("fbg2_max_nm", v)));
        for (name, value) in edges {
            // The si255 sweeps 1460-1620 nm, as for pad 0's windows.
            at.in_range(&format!("{prefix}{name}"), value, 1460.0, 1620.0);
        }
        at.require(&format!("{prefix}fbg1_max_nm"), self.fbg1_max_nm > self.fbg1_min_nm, || {
            "must exceed fbg1_min_nm".to_string()
        });
        at.require(&format!("{prefix}fbg2_max_nm"), self.fbg2_min_nm.is_some() == self.fbg2_max_nm.is_some(), || {
            "give both fbg2_min_nm and fbg2_max_nm (a pad with its own reference), or neither".to_string()
        });
        if let Some((lo, hi)) = self.fbg2() {
            at.require(&format!("{prefix}fbg2_max_nm"), hi > lo, || "must exceed fbg2_min_nm".to_string());
            let disjoint = self.fbg1_max_nm <= lo || hi <= self.fbg1_min_nm;
            at.require(&format!("{prefix}fbg2_min_nm"), disjoint, || "the FBG1 and FBG2 windows overlap".to_string());
        }
    }
}

/// The further pads' windows, at most [`MAX_EXTRA_PADS`]; written in TOML as a list of tables
/// (`[[hardware.fbg.pads]]`), empty by default (the paper's single pad, or windows derived from
/// the `[array]` layout).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(try_from = "Vec<PadWindows>", into = "Vec<PadWindows>")]
pub struct PadWindowList {
    len: u8,
    items: [PadWindows; MAX_EXTRA_PADS],
}

impl PadWindowList {
    /// The windows of `pads` (at most [`MAX_EXTRA_PADS`]; more is an error naming the count).
    pub fn new(pads: &[PadWindows]) -> Result<Self, String> {
        if pads.len() > MAX_EXTRA_PADS {
            return Err(format!("at most {MAX_EXTRA_PADS} further pads' windows, got {}", pads.len()));
        }
        let mut list = PadWindowList { len: pads.len() as u8, items: [PadWindows::default(); MAX_EXTRA_PADS] };
        list.items[..pads.len()].copy_from_slice(pads);
        Ok(list)
    }

    /// The windows, further pad 1 first.
    pub fn as_slice(&self) -> &[PadWindows] {
        &self.items[..self.len as usize]
    }

    /// Number of further pads given.
    pub fn len(&self) -> usize {
        self.len as usize
    }

    /// Whether none is given.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

impl TryFrom<Vec<PadWindows>> for PadWindowList {
    type Error = String;
    fn try_from(pads: Vec<PadWindows>) -> Result<Self, String> {
        PadWindowList::new(&pads)
    }
}

impl From<PadWindowList> for Vec<PadWindows> {
    fn from(list: PadWindowList) -> Self {
        list.as_slice().to_vec()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_list_keeps_its_pads_and_refuses_too_many() {
        let p = PadWindows { fbg1_min_nm: 1520.0, fbg1_max_nm: 1530.0, ..PadWindows::default() };
        let list = PadWindowList::new(&[p, p]).unwrap();
        assert_eq!(list.as_slice(), &[p, p]);
        assert!(PadWindowList::new(&[p; 8]).unwrap_err().contains("at most 7"));
        assert!(PadWindowList::default().is_empty());
    }

    #[test]
    fn one_pads_checks_name_their_key() {
        let mut at = Checker::default();
        let p =
            PadWindows { fbg1_min_nm: 1530.0, fbg1_max_nm: 1520.0, fbg2_min_nm: Some(1525.0), ..Default::default() };
        p.validate_at("pads[1].", &mut at);
        let keys: Vec<&str> = at.errors().iter().map(|(k, _)| k.as_str()).collect();
        assert_eq!(keys, ["pads[1].fbg1_max_nm", "pads[1].fbg2_max_nm"], "{:?}", at.errors());
    }
}
