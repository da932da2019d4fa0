//! A sensor array on the real path (issue 40): every peak of a layout goes through the virtual
//! HYPERION and back to its pad. Property tests over random layouts that can be read (1-8 pads,
//! 1-2 channels, own or shared references, no multiplexing fault): wavelengths anywhere in each
//! grating's range → the virtual device's peak frame → bytes → decoded → mapped by the windows
//! derived from the layout → the same wavelengths; a grating's peak taken out, or a second peak put
//! in its window, is an error naming that pad and grating. And the errors' exact words.

use proptest::prelude::*;
use tendril_codec::Decoded;
use tendril_fbg::SensorConfig;
use tendril_fbg::array::{ArrayConfig, ArrayPad, ArrayPeaks, GratingRole, GratingWindow, PerPad};
use tendril_fbg::signals::Wavelengths;
use tendril_hyperion::{
    FbgMapError, FbgWindows, InterrogatorConfig, PeakFrame, PeakHeader, Request, Response, VirtualInterrogator,
    decode_stream_frame,
};

/// One generated grating before placement: its pad, role, channel, and a key ordering it on its
/// channel.
#[derive(Debug, Clone)]
struct Slot {
    pad: usize,
    role: GratingRole,
    channel: usize,
    order: u32,
}

/// A random readable layout: pad 0's channel, how many further pads, each one's channel and
/// whether it has its own reference, the gratings' order on each channel and how the slack of
/// the band is shared between the gaps.
#[derive(Debug, Clone)]
struct Layout {
    first_channel: usize,
    sensor: SensorConfig,
    array: ArrayConfig,
}

fn layout() -> impl Strategy<Value = Layout> {
    (1usize..=2, prop::collection::vec((1usize..=2, any::<bool>()), 0..=7)).prop_flat_map(|(first_channel, pads)| {
        // A pad on another channel than pad 0 cannot share its reference.
        let pads: Vec<(usize, bool)> = pads.into_iter().map(|(c, own)| (c, own || c != first_channel)).collect();
        let gratings = 2 + pads.len() + pads.iter().filter(|p| p.1).count();
        (
            Just(first_channel),
            Just(pads),
            prop::collection::vec(any::<u32>(), gratings),
            prop::collection::vec(0.0..1.0f64, gratings + 2),
            0.0..1.0f64,
        )
            .prop_map(|(first_channel, pads, orders, shares, used)| place(first_channel, &pads, &orders, &shares, used))
    })
}

/// Places the gratings on their channels in `orders`' order, guard apart plus a share of the free
/// band each, so the layout has no multiplexing fault by construction.
fn place(first_channel: usize, pads: &[(usize, bool)], orders: &[u32], shares: &[f64], used: f64) -> Layout {
    let sensor = SensorConfig::default();
    let guard = ArrayConfig::default().guard_nm + 1e-6;
    // Each role's offset of its range from the grating's wavelength, and its width.
    let probe = ArrayConfig::default().windows(&sensor, 1);
    let shape = |role: GratingRole| {
        let w = probe.iter().find(|w| w.role == role).unwrap();
        let lambda = if role == GratingRole::Strain { sensor.lambda1_nm } else { sensor.lambda2_nm };
        (w.low_nm - lambda, w.high_nm - w.low_nm)
    };
    let mut slots = vec![
        Slot { pad: 0, role: GratingRole::Strain, channel: first_channel, order: orders[0] },
        Slot { pad: 0, role: GratingRole::Reference, channel: first_channel, order: orders[1] },
    ];
    let mut k = 2;
    for (i, &(channel, own)) in pads.iter().enumerate() {
        slots.push(Slot { pad: i + 1, role: GratingRole::Strain, channel, order: orders[k] });
        k += 1;
        if own {
            slots.push(Slot { pad: i + 1, role: GratingRole::Reference, channel, order: orders[k] });
            k += 1;
        }
    }
    let mut lambda = vec![[f64::NAN; 2]; 1 + pads.len()];
    for channel in 1..=2 {
        let mut on: Vec<&Slot> = slots.iter().filter(|s| s.channel == channel).collect();
        on.sort_by_key(|s| (s.order, s.pad));
        if on.is_empty() {
            continue;
        }
        let needed: f64 = on.iter().map(|s| shape(s.role).1).sum::<f64>() + guard * (on.len() - 1) as f64;
        let free = (tendril_fbg::array::BAND_MAX_NM - tendril_fbg::array::BAND_MIN_NM - 0.02 - needed).max(0.0);
        let parts = &shares[..on.len() + 1];
        let total: f64 = parts.iter().sum::<f64>().max(1e-9);
        let mut cursor = tendril_fbg::array::BAND_MIN_NM + 0.01;
        for (j, s) in on.iter().enumerate() {
            cursor += free * used * parts[j] / total;
            let (offset, width) = shape(s.role);
            lambda[s.pad][(s.role == GratingRole::Reference) as usize] = cursor - offset;
            cursor += width + guard;
        }
    }
    let sensor = SensorConfig { lambda1_nm: lambda[0][0], lambda2_nm: lambda[0][1], ..sensor };
    let array = ArrayConfig {
        pads: pads
            .iter()
            .enumerate()
            .map(|(i, &(channel, own))| ArrayPad {
                arc_m: 0.01 + 0.013 * i as f64,
                channel,
                lambda1_nm: lambda[i + 1][0],
                lambda2_nm: own.then_some(lambda[i + 1][1]),
                protrusion_m: None,
            })
            .collect(),
        ..ArrayConfig::default()
    };
    Layout { first_channel, sensor, array }
}

/// The gratings' ranges and, for each, a wavelength `fractions` of the way through it; as pad 0's
/// sample and the further pads' (a shared reference reads pad 0's FBG2 peak, as the twin does).
fn sample(ranges: &[GratingWindow], fractions: &[f64], pads: usize) -> (Wavelengths, ArrayPeaks) {
    let mut all = vec![Wavelengths::default(); 1 + pads];
    for (r, f) in ranges.iter().zip(fractions) {
        let nm = r.low_nm + f * (r.high_nm - r.low_nm);
        match r.role {
            GratingRole::Strain => all[r.pad].fbg1_nm = nm,
            GratingRole::Reference => all[r.pad].fbg2_nm = nm,
        }
    }
    let shared = all[0].fbg2_nm;
    for w in &mut all[1..] {
        if w.fbg2_nm.is_nan() {
            w.fbg2_nm = shared;
        }
    }
    let mut array = PerPad::filled(pads, Wavelengths::default());
    array.as_mut_slice().copy_from_slice(&all[1..]);
    (all[0], array)
}

/// The frame a virtual si255 with enough channels streams for `channels`, through its bytes.
fn through_the_device(channels: Vec<Vec<f64>>, serial: u64) -> PeakFrame {
    let channel_count = [4u32, 8, 16].into_iter().find(|&n| n as usize >= channels.len()).unwrap();
    let mut dev =
        VirtualInterrogator::new(InterrogatorConfig { channel_count, ..InterrogatorConfig::default() }).unwrap();
    let frame = PeakFrame { header: PeakHeader { serial_number: serial, ..PeakHeader::default() }, channels };
    dev.set_peaks(frame).unwrap();
    // `#GetPeaks` and the stream carry the same scan.
    let mut request = Request::new("#GetPeaks", "").encode().unwrap();
    let reply = dev.feed(&mut request).unwrap();
    let Decoded::Frame { packet, .. } = Response::decode(&reply) else { panic!("no reply") };
    let polled = PeakFrame::decode(&packet.into_result().unwrap()).unwrap();
    let (bytes, _) = dev.stream_after(None).unwrap();
    let Decoded::Frame { packet: streamed, consumed } = decode_stream_frame(&bytes) else { panic!("no frame") };
    assert_eq!(consumed, bytes.len());
    assert_eq!(polled, streamed);
    streamed
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn every_readable_layout_round_trips_through_the_virtual_interrogator(
        l in layout(),
        fractions in prop::collection::vec(0.0..=1.0f64, 16),
        serial in 1u64..1_000_000,
    ) {
        let faults = l.array.multiplexing_faults(&l.sensor, l.first_channel);
        prop_assert!(faults.is_empty(), "the generator made a faulty layout: {:?}", faults);
        let windows = FbgWindows::derived(&l.array, &l.sensor, l.first_channel).unwrap();
        // The derived windows pass as given ones, and the scenario's range checks.
        prop_assert_eq!(windows.for_layout(&l.array, &l.sensor), Ok(windows));
        let mut at = tendril_config::Checker::default();
        tendril_config::Validate::validate(&windows, &mut at);
        prop_assert!(at.errors().is_empty(), "{:?}", at.errors());
        let ranges = l.array.windows(&l.sensor, l.first_channel);
        let (first, array) = sample(&ranges, &fractions, l.array.pads.len());
        let channels = windows.peak_channels(first, &array);
        prop_assert_eq!(channels.len(), windows.highest_channel());
        prop_assert_eq!(channels.iter().map(Vec::len).sum::<usize>(), ranges.len(), "one peak per grating");
        for peaks in &channels {
            prop_assert!(peaks.windows(2).all(|p| p[0] <= p[1]), "ascending: {:?}", peaks);
        }
        let frame = through_the_device(channels, serial);
        prop_assert_eq!(frame.header.serial_number, serial);
        // (`PerPad`'s `==` compares its unused slots too, NaN for wavelengths: compare the pads'.)
        let (got_first, got_array) = windows.map_all(&frame).unwrap();
        prop_assert_eq!((got_first, got_array.as_slice()), (first, array.as_slice()));
    }

    #[test]
    fn a_missing_or_doubled_peak_names_its_pad_and_grating(
        l in layout(),
        fractions in prop::collection::vec(0.0..=1.0f64, 16),
        pick in any::<prop::sample::Index>(),
        doubled in any::<bool>(),
    ) {
        let windows = FbgWindows::derived(&l.array, &l.sensor, l.first_channel).unwrap();
        let ranges = l.array.windows(&l.sensor, l.first_channel);
        let (first, array) = sample(&ranges, &fractions, l.array.pads.len());
        let mut channels = windows.peak_channels(first, &array);
        let r = &ranges[pick.index(ranges.len())];
        let fbg = if r.role == GratingRole::Strain { 1 } else { 2 };
        let peaks = &mut channels[r.channel - 1];
        let at = peaks.iter().position(|&p| p >= r.low_nm && p <= r.high_nm).unwrap();
        if doubled {
            // A second line within its range (a reflection, a broken grating read twice).
            let other = if peaks[at] > 0.5 * (r.low_nm + r.high_nm) { r.low_nm } else { r.high_nm };
            peaks.insert(at, other);
        } else {
            peaks.remove(at);
        }
        peaks.sort_by(f64::total_cmp);
        let got = windows.map_all(&through_the_device(channels, 1));
        match got {
            Err(FbgMapError::Ambiguous { pad, fbg: f, count: 2, channel, .. }) if doubled => {
                prop_assert_eq!((pad, f, channel), (r.pad, fbg, r.channel));
            }
            Err(FbgMapError::Missing { pad, fbg: f, channel, .. }) if !doubled => {
                prop_assert_eq!((pad, f, channel), (r.pad, fbg, r.channel));
            }
            other => prop_assert!(false, "doubled {}: {:?} for pad {} FBG{}", doubled, other, r.pad, fbg),
        }
    }
}

/// `scenarios/hammer-array.toml`'s layout: pads at 1525 nm and 1560 nm on channel 1, sharing pad 0's
/// reference; pad 0's windows the defaults.
fn hammer_array() -> (FbgWindows, ArrayConfig) {
    let pad = |arc_m, lambda1_nm| ArrayPad { arc_m, channel: 1, lambda1_nm, lambda2_nm: None, protrusion_m: None };
    let array = ArrayConfig { pads: vec![pad(0.012, 1525.0), pad(0.0775, 1560.0)], ..ArrayConfig::default() };
    (FbgWindows::default().for_layout(&array, &SensorConfig::default()).unwrap(), array)
}

#[test]
fn the_errors_name_the_pad_the_grating_the_window_and_the_channel() {
    let (windows, _) = hammer_array();
    let scan = |peaks: Vec<f64>| PeakFrame { channels: vec![peaks], ..PeakFrame::default() };
    let ok = windows.map_all(&scan(vec![1526.0, 1541.0, 1550.0, 1561.0])).unwrap();
    assert_eq!(ok.0, Wavelengths { fbg1_nm: 1541.0, fbg2_nm: 1550.0 });
    assert_eq!(ok.1.as_slice()[1], Wavelengths { fbg1_nm: 1561.0, fbg2_nm: 1550.0 }, "pad 0's reference");
    let missing = windows.map_all(&scan(vec![1526.0, 1541.0, 1550.0])).unwrap_err();
    assert_eq!(missing.to_string(), "pad 2: no FBG1 peak in [1557.38, 1600.00) nm on channel 1");
    let doubled = windows.map_all(&scan(vec![1526.0, 1527.5, 1541.0, 1550.0, 1561.0])).unwrap_err();
    assert_eq!(
        doubled.to_string(),
        "pad 1: 2 peaks in the FBG1 window [1500.00, 1533.14) nm on channel 1, expected one"
    );
    let pad0 = windows.map_all(&scan(vec![1526.0, 1541.0, 1561.0])).unwrap_err();
    assert_eq!(pad0.to_string(), "pad 0: no FBG2 peak in [1547.80, 1555.00) nm on channel 1");
    let on_two = FbgWindows { channel: 2, ..windows };
    assert_eq!(on_two.map_all(&scan(vec![1541.0])).unwrap_err(), FbgMapError::NoChannel { channel: 2, available: 1 });
}

#[test]
fn the_virtual_device_serves_each_channels_peaks_in_ascending_order() {
    let sensor = SensorConfig::default();
    let array = ArrayConfig {
        pads: vec![
            ArrayPad { arc_m: 0.012, channel: 3, lambda1_nm: 1525.0, lambda2_nm: Some(1510.0), protrusion_m: None },
            ArrayPad { arc_m: 0.0775, channel: 1, lambda1_nm: 1560.0, lambda2_nm: None, protrusion_m: None },
        ],
        ..ArrayConfig::default()
    };
    let windows = FbgWindows::default().for_layout(&array, &sensor).unwrap();
    assert_eq!(windows.highest_channel(), 3);
    let first = Wavelengths { fbg1_nm: 1541.0, fbg2_nm: 1550.0 };
    let mut further = PerPad::filled(2, first);
    further.as_mut_slice()[0] = Wavelengths { fbg1_nm: 1526.0, fbg2_nm: 1510.1 };
    further.as_mut_slice()[1] = Wavelengths { fbg1_nm: 1561.0, fbg2_nm: 1550.0 };
    let channels = windows.peak_channels(first, &further);
    assert_eq!(channels, vec![vec![1541.0, 1550.0, 1561.0], vec![], vec![1510.1, 1526.0]]);
    let (got_first, got_further) = windows.map_all(&through_the_device(channels, 7)).unwrap();
    assert_eq!((got_first, got_further.as_slice()), (first, further.as_slice()));
}

/// The key and reason `scenarios/hammer-array.toml` with `sets` is refused with.
fn refusal(sets: &[&str]) -> (String, String) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/hammer-array.toml");
    let overrides: Vec<tendril_config::Override> = sets.iter().map(|s| s.parse().unwrap()).collect();
    match tendril_config::load::<tendril_run::scenario::PickPlaceScenario>(&path, &overrides) {
        Ok(_) => panic!("{sets:?} was accepted"),
        Err(tendril_config::ScenarioError::Invalid { key, reason, .. }) => (key, reason),
        Err(e) => panic!("{sets:?}: {e}"),
    }
}

#[test]
fn the_scenario_refuses_windows_that_cannot_read_the_layout_on_their_key() {
    let given = |pads: &str| format!("hardware.fbg.pads=[{pads}]");
    let cases = [
        (
            given("{fbg1_min_nm = 1500.0, fbg1_max_nm = 1530.0}, {fbg1_min_nm = 1557.0, fbg1_max_nm = 1600.0}"),
            "hardware.fbg.pads[0].fbg1_max_nm",
            "must exceed 1531.28 nm",
        ),
        (given("{fbg1_min_nm = 1500.0, fbg1_max_nm = 1533.0}"), "hardware.fbg.pads", "the layout has 2"),
        (
            given("{fbg1_min_nm = 1500.0, fbg1_max_nm = 1536.0}, {fbg1_min_nm = 1557.0, fbg1_max_nm = 1600.0}"),
            "hardware.fbg.pads[0].fbg1_min_nm",
            "overlaps hardware.fbg.fbg1_min_nm's",
        ),
        (
            given(
                "{channel = 2, fbg1_min_nm = 1500.0, fbg1_max_nm = 1533.0}, {fbg1_min_nm = 1557.0, fbg1_max_nm = 1600.0}",
            ),
            "hardware.fbg.pads[0].channel",
            "array.pads[0].channel = 1",
        ),
        (
            "array.pads=[{arc_m = 0.012, lambda1_nm = 1531.0}]".to_string(),
            "hardware.fbg.fbg1_min_nm",
            "takes in pad 1's FBG1 peak",
        ),
    ];
    for (set, key, reason) in cases {
        let (k, r) = refusal(&[&set]);
        assert_eq!(k, key, "--set {set}: {r}");
        assert!(r.contains(reason), "--set {set}: {r}");
    }
    // The windows derived for hammer-array.toml, given, load.
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/hammer-array.toml");
    let set: tendril_config::Override =
        given("{fbg1_min_nm = 1500.0, fbg1_max_nm = 1533.0}, {fbg1_min_nm = 1557.0, fbg1_max_nm = 1600.0}")
            .parse()
            .unwrap();
    let s: tendril_run::scenario::PickPlaceScenario = tendril_config::load(&path, &[set]).unwrap();
    assert_eq!(s.hardware.fbg.pads.len(), 2);
}
