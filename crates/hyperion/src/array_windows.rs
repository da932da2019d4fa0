//! A sensor array's windows: the further pads' `[[hardware.fbg.pads]]` checked against the
//! `[array]` layout, or derived from it when the scenario gives none.
//!
//! Derived windows: each grating's window is the wavelengths its peak moves over
//! ([`ArrayConfig::windows`]: unloaded, the strain span to the sensor's range, the thermal shift
//! over the layout's temperatures), widened on each side halfway into the gap to its neighbour on
//! the channel (a neighbour's range, or pad 0's window from `[hardware.fbg]`), and to the band's
//! edge where there is none. So a window always holds its grating and never a neighbour's, and two
//! windows on a channel meet at most at an edge (lower edges inclusive, upper exclusive).

use super::fbg_map::FbgWindows;
use super::pad_windows::{PadWindowList, PadWindows};
use tendril_fbg::SensorConfig;
use tendril_fbg::array::{ArrayConfig, BAND_MAX_NM, BAND_MIN_NM, GratingRole, GratingWindow};

/// A layout's fault: the scenario key and the reason.
pub type WindowFault = (String, String);

/// A window that is not derived (pad 0's from `[hardware.fbg]`), as a neighbour of derived ones.
struct Fixed {
    channel: usize,
    min_nm: f64,
    max_nm: f64,
    /// `pad 0's FBG1 window`.
    label: String,
    /// Its keys, lower and upper edge.
    keys: [String; 2],
}

/// A window on a channel, for the disjointness check of given windows.
struct Given {
    channel: usize,
    min_nm: f64,
    max_nm: f64,
    /// Its lower edge's key.
    key: String,
}

fn fbg(role: GratingRole) -> u8 {
    match role {
        GratingRole::Strain => 1,
        GratingRole::Reference => 2,
    }
}

impl FbgWindows {
    /// The windows to read `array`'s layout with (`self` is `[hardware.fbg]`): `self` when the
    /// further pads' windows are given and hold the layout's gratings, else `self` with them derived
    /// (see the module's doc). Errors are (scenario key, reason): given windows that are not one per
    /// further pad, on another channel than the pad, with an FBG2 window the pad does not have (or
    /// without one it has), not holding their grating's range, or meeting another window on their
    /// channel; derived windows that would take in a neighbour (pad 0's windows holding a further
    /// pad's grating, or two gratings' ranges meeting, which [`ArrayConfig::multiplexing_faults`]
    /// reports too).
    pub fn for_layout(&self, array: &ArrayConfig, sensor: &SensorConfig) -> Result<FbgWindows, Vec<WindowFault>> {
        if array.is_single() {
            if self.pads.is_empty() {
                return Ok(*self);
            }
            let reason = format!(
                "{} further pad(s)' windows given, but the scenario has no [array] to give the pads",
                self.pads.len()
            );
            return Err(vec![("hardware.fbg.pads".into(), reason)]);
        }
        let ranges = array.windows(sensor, self.channel);
        if !self.pads.is_empty() {
            let faults = self.check_given(array, &ranges);
            return if faults.is_empty() { Ok(*self) } else { Err(faults) };
        }
        let targets: Vec<&GratingWindow> = ranges.iter().filter(|r| r.pad > 0).collect();
        let fixed = [
            (1, self.fbg1_min_nm, self.fbg1_max_nm, ["hardware.fbg.fbg1_min_nm", "hardware.fbg.fbg1_max_nm"]),
            (2, self.fbg2_min_nm, self.fbg2_max_nm, ["hardware.fbg.fbg2_min_nm", "hardware.fbg.fbg2_max_nm"]),
        ]
        .map(|(fbg, min_nm, max_nm, keys)| Fixed {
            channel: self.channel,
            min_nm,
            max_nm,
            label: format!("pad 0's FBG{fbg} window"),
            keys: keys.map(String::from),
        });
        match derive(&targets, &fixed) {
            Ok(edges) => {
                let pads = pad_windows(array, &targets, &edges);
                Ok(FbgWindows { pads: PadWindowList::new(&pads).map_err(|e| vec![("array.pads".into(), e)])?, ..*self })
            }
            Err(mut faults) => {
                // Suggest pad 0's windows derived from the layout as well, when they exist.
                if let Ok(all) = FbgWindows::derived(array, sensor, self.channel) {
                    for (key, reason) in &mut faults {
                        if key.starts_with("hardware.fbg.fbg") {
                            reason.push_str(&format!(
                                ": narrow pad 0's windows, e.g. fbg1_min_nm = {:.2}, fbg1_max_nm = {:.2}, \
                                 fbg2_min_nm = {:.2}, fbg2_max_nm = {:.2} (derived from the layout), or give \
                                 every pad's windows ([[hardware.fbg.pads]])",
                                all.fbg1_min_nm, all.fbg1_max_nm, all.fbg2_min_nm, all.fbg2_max_nm
                            ));
                        }
                    }
                }
                Err(faults)
            }
        }
    }

    /// Every window derived from the layout, pad 0's as well (on `channel`): what to write in
    /// `[hardware.fbg]` when its default windows would take in a further pad's grating.
    pub fn derived(array: &ArrayConfig, sensor: &SensorConfig, channel: usize) -> Result<FbgWindows, Vec<WindowFault>> {
        let ranges = array.windows(sensor, channel);
        let targets: Vec<&GratingWindow> = ranges.iter().collect();
        let edges = derive(&targets, &[])?;
        let of = |pad, role| targets.iter().zip(&edges).find(|(r, _)| r.pad == pad && r.role == role).map(|(_, e)| *e);
        let ((fbg1_min_nm, fbg1_max_nm), (fbg2_min_nm, fbg2_max_nm)) =
            (of(0, GratingRole::Strain).unwrap_or_default(), of(0, GratingRole::Reference).unwrap_or_default());
        let further: Vec<&GratingWindow> = targets.iter().copied().filter(|r| r.pad > 0).collect();
        let further_edges: Vec<(f64, f64)> =
            targets.iter().zip(&edges).filter(|(r, _)| r.pad > 0).map(|(_, e)| *e).collect();
        let pads = PadWindowList::new(&pad_windows(array, &further, &further_edges))
            .map_err(|e| vec![("array.pads".to_string(), e)])?;
        Ok(FbgWindows { channel, fbg1_min_nm, fbg1_max_nm, fbg2_min_nm, fbg2_max_nm, pads })
    }

    /// The faults of given further windows against the layout's gratings `ranges`.
    fn check_given(&self, array: &ArrayConfig, ranges: &[GratingWindow]) -> Vec<WindowFault> {
        let mut faults = Vec::new();
        let given = self.pads.as_slice();
        if given.len() != array.pads.len() {
            faults.push((
                "hardware.fbg.pads".to_string(),
                format!(
                    "{} further pad(s)' windows given, the layout has {} ([[array.pads]]): one per further pad, in its order",
                    given.len(),
                    array.pads.len()
                ),
            ));
            return faults;
        }
        let mut windows = vec![
            Given {
                channel: self.channel,
                min_nm: self.fbg1_min_nm,
                max_nm: self.fbg1_max_nm,
                key: "hardware.fbg.fbg1_min_nm".into(),
            },
            Given {
                channel: self.channel,
                min_nm: self.fbg2_min_nm,
                max_nm: self.fbg2_max_nm,
                key: "hardware.fbg.fbg2_min_nm".into(),
            },
        ];
        for (i, (w, pad)) in given.iter().zip(&array.pads).enumerate() {
            let key = |name: &str| format!("hardware.fbg.pads[{i}].{name}");
            if w.channel != pad.channel {
                faults.push((
                    key("channel"),
                    format!("must be the pad's channel, array.pads[{i}].channel = {}, got {}", pad.channel, w.channel),
                ));
            }
            match (pad.lambda2_nm, w.fbg2()) {
                (Some(l2), None) => faults.push((
                    key("fbg2_min_nm"),
                    format!(
                        "array.pads[{i}] has its own reference grating (lambda2_nm = {l2} nm): give its FBG2 window"
                    ),
                )),
                (None, Some(_)) => faults.push((
                    key("fbg2_min_nm"),
                    format!(
                        "array.pads[{i}] shares pad 0's reference grating (no lambda2_nm): it has no FBG2 window \
                         of its own (pad 0's FBG2 peak is read)"
                    ),
                )),
                _ => {}
            }
            let mut own = vec![(GratingRole::Strain, (w.fbg1_min_nm, w.fbg1_max_nm), ["fbg1_min_nm", "fbg1_max_nm"])];
            own.extend(w.fbg2().map(|e| (GratingRole::Reference, e, ["fbg2_min_nm", "fbg2_max_nm"])));
            for (role, (min_nm, max_nm), names) in own {
                windows.push(Given { channel: w.channel, min_nm, max_nm, key: key(names[0]) });
                let Some(r) = ranges.iter().find(|r| r.pad == i + 1 && r.role == role) else { continue };
                let reaches = || {
                    format!(
                        "{}'s peak moves over {:.2}-{:.2} nm (the strain span to the sensor's range, \
                         array.min_temperature_c to max_temperature_c)",
                        r.key, r.low_nm, r.high_nm
                    )
                };
                if min_nm > r.low_nm {
                    faults.push((key(names[0]), format!("must not exceed {:.2} nm: {}", r.low_nm, reaches())));
                }
                if max_nm <= r.high_nm {
                    faults.push((key(names[1]), format!("must exceed {:.2} nm: {}", r.high_nm, reaches())));
                }
            }
        }
        for (b, wb) in windows.iter().enumerate() {
            for wa in &windows[..b] {
                if wa.channel == wb.channel && wa.min_nm < wb.max_nm && wb.min_nm < wa.max_nm {
                    faults.push((
                        wb.key.clone(),
                        format!(
                            "the window [{:.2}, {:.2}) nm overlaps {}'s [{:.2}, {:.2}) nm on channel {}: windows on \
                             one channel must be disjoint",
                            wb.min_nm, wb.max_nm, wa.key, wa.min_nm, wa.max_nm, wa.channel
                        ),
                    ));
                }
            }
        }
        faults
    }
}

/// The further pads' windows from their gratings' derived edges (`targets` and `edges` in step).
fn pad_windows(array: &ArrayConfig, targets: &[&GratingWindow], edges: &[(f64, f64)]) -> Vec<PadWindows> {
    (1..=array.pads.len())
        .map(|pad| {
            let of = |role| targets.iter().zip(edges).find(|(r, _)| r.pad == pad && r.role == role).map(|(_, e)| *e);
            let (fbg1_min_nm, fbg1_max_nm) = of(GratingRole::Strain).unwrap_or_default();
            let fbg2 = of(GratingRole::Reference);
            PadWindows {
                channel: array.pads[pad - 1].channel,
                fbg1_min_nm,
                fbg1_max_nm,
                fbg2_min_nm: fbg2.map(|e| e.0),
                fbg2_max_nm: fbg2.map(|e| e.1),
            }
        })
        .collect()
}

/// Each target grating's window \[lower, upper) nm: its range widened halfway into the gap to its
/// nearest neighbour below and above on its channel (another target's range, or a fixed window),
/// to the band's edge where there is none. A neighbour meeting the range is a fault.
fn derive(targets: &[&GratingWindow], fixed: &[Fixed]) -> Result<Vec<(f64, f64)>, Vec<WindowFault>> {
    let mut faults = Vec::new();
    let mut edges = Vec::with_capacity(targets.len());
    for (t, r) in targets.iter().enumerate() {
        let (mut lo, mut hi) = (BAND_MIN_NM.min(r.low_nm), BAND_MAX_NM.max(r.high_nm));
        for (j, o) in targets.iter().enumerate() {
            if j == t || o.channel != r.channel {
                continue;
            }
            if o.high_nm <= r.low_nm {
                lo = lo.max(0.5 * (o.high_nm + r.low_nm));
            } else if o.low_nm >= r.high_nm {
                hi = hi.min(0.5 * (r.high_nm + o.low_nm));
            } else if j < t {
                faults.push((
                    r.key.clone(),
                    format!(
                        "the grating's peak moves over {:.2}-{:.2} nm, which meets {}'s {:.2}-{:.2} nm on channel {}: \
                         no window can tell them apart",
                        r.low_nm, r.high_nm, o.key, o.low_nm, o.high_nm, r.channel
                    ),
                ));
            }
        }
        for f in fixed.iter().filter(|f| f.channel == r.channel) {
            if f.max_nm <= r.low_nm {
                lo = lo.max(0.5 * (f.max_nm + r.low_nm));
            } else if f.min_nm > r.high_nm {
                hi = hi.min(0.5 * (r.high_nm + f.min_nm));
            } else {
                // The edge of the fixed window on the grating's side is the one to move.
                let key = if r.low_nm < f.min_nm { &f.keys[0] } else { &f.keys[1] };
                faults.push((
                    key.clone(),
                    format!(
                        "{} [{:.2}, {:.2}) nm on channel {} takes in pad {}'s FBG{} peak, which moves over \
                         {:.2}-{:.2} nm ({})",
                        f.label,
                        f.min_nm,
                        f.max_nm,
                        f.channel,
                        r.pad,
                        fbg(r.role),
                        r.low_nm,
                        r.high_nm,
                        r.key
                    ),
                ));
            }
        }
        edges.push((lo, hi));
    }
    if faults.is_empty() { Ok(edges) } else { Err(faults) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tendril_fbg::array::ArrayPad;

    /// `scenarios/hammer-array.toml`'s layout: pads at 1525 and 1560 nm, sharing pad 0's reference.
    fn hammer_array() -> ArrayConfig {
        let pad = |arc_m, lambda1_nm| ArrayPad { arc_m, channel: 1, lambda1_nm, lambda2_nm: None, protrusion_m: None };
        ArrayConfig { pads: vec![pad(0.012, 1525.0), pad(0.0775, 1560.0)], ..ArrayConfig::default() }
    }

    #[test]
    fn the_single_pad_keeps_its_windows() {
        let w = FbgWindows::default();
        assert_eq!(w.for_layout(&ArrayConfig::default(), &SensorConfig::default()), Ok(w));
    }

    #[test]
    fn derived_windows_hold_their_grating_and_meet_halfway_to_pad_zeros() {
        let sensor = SensorConfig::default();
        let w = FbgWindows::default().for_layout(&hammer_array(), &sensor).unwrap();
        let ranges = hammer_array().windows(&sensor, 1);
        let [one, two] = w.pads.as_slice() else { panic!("{w:?}") };
        // Pad 1's FBG1 (1524.76-1531.28 nm): from the band's edge to halfway to pad 0's FBG1 window.
        assert_eq!(one.fbg1_min_nm, BAND_MIN_NM);
        assert!((one.fbg1_max_nm - 0.5 * (ranges[2].high_nm + 1535.0)).abs() < 1e-9, "{one:?}");
        // Pad 2's FBG1 (1559.76-1566.28 nm): from halfway to pad 0's FBG2 window to the band's edge.
        assert!((two.fbg1_min_nm - 0.5 * (1555.0 + ranges[3].low_nm)).abs() < 1e-9, "{two:?}");
        assert_eq!((two.fbg1_max_nm, two.fbg2()), (BAND_MAX_NM, None));
        assert_eq!(w.highest_channel(), 1);
    }

    #[test]
    fn pad_zeros_default_windows_taking_in_a_further_grating_are_named() {
        let sensor = SensorConfig::default();
        let crowded = ArrayConfig {
            pads: vec![ArrayPad { arc_m: 0.03, channel: 1, lambda1_nm: 1531.0, lambda2_nm: None, protrusion_m: None }],
            ..ArrayConfig::default()
        };
        let faults = FbgWindows::default().for_layout(&crowded, &sensor).unwrap_err();
        assert_eq!(faults[0].0, "hardware.fbg.fbg1_min_nm", "{faults:?}");
        assert!(faults[0].1.contains("takes in pad 1's FBG1 peak") && faults[0].1.contains("e.g."), "{faults:?}");
        // The windows derived for every pad read it.
        let all = FbgWindows::derived(&crowded, &sensor, 1).unwrap();
        assert!(all.for_layout(&crowded, &sensor).is_ok());
        assert!(all.fbg1_min_nm > 1537.0 && all.fbg1_min_nm < 1539.757, "{all:?}");
    }

    #[test]
    fn given_windows_are_checked_against_the_layout() {
        let sensor = SensorConfig::default();
        let layout = hammer_array();
        let good = FbgWindows::default().for_layout(&layout, &sensor).unwrap();
        assert_eq!(good.for_layout(&layout, &sensor), Ok(good), "the derived windows pass as given ones");
        let with = |pads: &[PadWindows]| FbgWindows { pads: PadWindowList::new(pads).unwrap(), ..good };
        let [one, two] = *good.pads.as_slice() else { panic!() };
        let first_key = |w: FbgWindows| w.for_layout(&layout, &sensor).unwrap_err()[0].0.clone();
        assert_eq!(first_key(with(&[one])), "hardware.fbg.pads");
        assert_eq!(first_key(with(&[PadWindows { channel: 2, ..one }, two])), "hardware.fbg.pads[0].channel");
        assert_eq!(
            first_key(with(&[PadWindows { fbg1_max_nm: 1530.0, ..one }, two])),
            "hardware.fbg.pads[0].fbg1_max_nm"
        );
        let own_ref = PadWindows { fbg2_min_nm: Some(1590.0), fbg2_max_nm: Some(1595.0), ..two };
        assert_eq!(first_key(with(&[one, own_ref])), "hardware.fbg.pads[1].fbg2_min_nm");
        let into_pad0 = PadWindows { fbg1_max_nm: 1536.0, ..one };
        let faults = with(&[into_pad0, two]).for_layout(&layout, &sensor).unwrap_err();
        assert_eq!(faults[0].0, "hardware.fbg.pads[0].fbg1_min_nm", "{faults:?}");
        assert!(faults[0].1.contains("overlaps hardware.fbg.fbg1_min_nm's"), "{faults:?}");
        let extra = FbgWindows { pads: PadWindowList::new(&[one]).unwrap(), ..FbgWindows::default() };
        assert_eq!(extra.for_layout(&ArrayConfig::default(), &sensor).unwrap_err()[0].0, "hardware.fbg.pads");
    }
}
