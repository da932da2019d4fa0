//! A virtual si255 streaming the sensor's two peaks, mapped to FBG1 and FBG2 by window:
//! `cargo run -p tendril-hyperion --example peaks`.

use tendril_codec::Decoded;
use tendril_hyperion::{
    FbgWindows, InterrogatorConfig, PeakFrame, PeakHeader, VirtualInterrogator, decode_stream_frame,
};

fn main() {
    let mut si255 = VirtualInterrogator::new(InterrogatorConfig::default()).unwrap();
    for k in 1..=3u64 {
        // The instrument's scan k: two peaks on channel 1 (the sensor's fibre).
        let frame = PeakFrame {
            header: PeakHeader { serial_number: k, ..PeakHeader::default() },
            channels: vec![vec![1540.0 + 0.1 * k as f64, 1550.0], vec![], vec![], vec![]],
        };
        si255.set_peaks(frame).unwrap();
    }
    let (bytes, _) = si255.stream_after(None).unwrap();
    let windows = FbgWindows::default();
    let mut at = 0;
    while let Decoded::Frame { packet, consumed } = decode_stream_frame(&bytes[at..]) {
        at += consumed;
        let w = windows.map(&packet).unwrap();
        println!("scan {}: FBG1 {:.3} nm, FBG2 {:.3} nm", packet.header.serial_number, w.fbg1_nm, w.fbg2_nm);
    }
}
