//! The virtual HYPERION as a streaming client sees it: a 5 s peak stream with consecutive serial
//! numbers and a new sample in every frame, the streaming divider honoured, and the commands
//! Luna's `hyperion.py` calls answered.

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::time::{Duration, Instant};
use tendril_codec::Decoded;
use tendril_hyperion::{PeakFrame, Request, Response, decode_stream_frame};
use tendril_serve::{ServeConfig, start};

use crate::common::{one_at_a_time, short_lift};

/// Every frame the stream sends for `seconds`.
fn stream_for(addr: SocketAddr, seconds: f64) -> Vec<PeakFrame> {
    let mut socket = TcpStream::connect(addr).unwrap();
    socket.set_read_timeout(Some(Duration::from_millis(200))).unwrap();
    let (mut buf, mut chunk, mut frames) = (Vec::new(), [0u8; 16384], Vec::new());
    let end = Instant::now() + Duration::from_secs_f64(seconds);
    while Instant::now() < end {
        match socket.read(&mut chunk) {
            Ok(0) => panic!("the stream closed"),
            Ok(n) => buf.extend_from_slice(&chunk[..n]),
            Err(e) if matches!(e.kind(), std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut) => {}
            Err(e) => panic!("stream read: {e}"),
        }
        loop {
            match decode_stream_frame(&buf) {
                Decoded::NeedMore => break,
                Decoded::Frame { packet, consumed } => {
                    frames.push(packet);
                    buf.drain(..consumed);
                }
                Decoded::Invalid { error, .. } => panic!("bad frame: {error}"),
            }
        }
    }
    frames
}

fn command(addr: SocketAddr, command: &str, argument: &str) -> Response {
    let mut socket = TcpStream::connect(addr).unwrap();
    socket.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
    socket.write_all(&Request::new(command, argument).encode().unwrap()).unwrap();
    let (mut buf, mut chunk) = (Vec::new(), [0u8; 65536]);
    loop {
        let n = socket.read(&mut chunk).unwrap();
        assert!(n > 0, "closed before replying to {command}");
        buf.extend_from_slice(&chunk[..n]);
        if let Decoded::Frame { packet, .. } = Response::decode(&buf) {
            return packet;
        }
    }
}

#[test]
fn a_five_second_peak_stream_has_consecutive_serials_and_a_new_sample_in_each_frame() {
    let _turn = one_at_a_time();
    let serve = start(&short_lift(&[]), &ServeConfig::loopback().with_port_base(21830)).unwrap();
    let frames = stream_for(serve.addrs[3], 5.0);
    let channel = serve.hardware.fbg.channel;
    // A loaded machine may run the twin slower than real time; it never skips a scan.
    assert!(frames.len() > 1000, "{} frames in 5 s", frames.len());
    let gaps: Vec<(u64, u64)> = frames
        .windows(2)
        .map(|w| (w[0].header.serial_number, w[1].header.serial_number))
        .filter(|(a, b)| b - a != 1)
        .collect();
    assert!(gaps.is_empty(), "serial gaps {gaps:?} in {} frames", frames.len());
    // Each frame is a new scan, 1 ms after the one before, with a fresh sample: the noise (3 pm at
    // 1 pm resolution) leaves both peaks where they were in a few frames in a hundred at most
    // (before, 4 frames in 5 repeated the one before).
    let ns = |f: &PeakFrame| u64::from(f.header.timestamp_s) * 1_000_000_000 + u64::from(f.header.timestamp_ns);
    for w in frames.windows(2) {
        let step = ns(&w[1]) as i64 - ns(&w[0]) as i64;
        assert!((step - 1_000_000).abs() < 1000, "timestamps {} then {}", ns(&w[0]), ns(&w[1]));
    }
    let peaks = |f: &PeakFrame| f.channel(channel).unwrap().to_vec();
    let repeats = frames.windows(2).filter(|w| peaks(&w[0]) == peaks(&w[1])).count();
    println!("{} frames in 5 s, {repeats} with the same peaks as the frame before", frames.len());
    assert!(repeats * 10 < frames.len(), "{repeats} of {} frames repeat the one before", frames.len());
    assert!(serve.running());
    serve.stop().unwrap();
}

#[test]
fn the_streaming_divider_sends_every_tenth_scan_and_lunas_commands_are_answered() {
    let _turn = one_at_a_time();
    let serve = start(&short_lift(&[]), &ServeConfig::loopback().with_port_base(21840)).unwrap();
    let commands = serve.addrs[2];
    assert_eq!(command(commands, "#SetPeakDataStreamingDivider", "10").status, 0);
    let frames = stream_for(serve.addrs[3], 1.0);
    assert!(frames.len() > 20, "{} frames in 1 s at divider 10", frames.len());
    for w in frames.windows(2) {
        assert_eq!(w[1].header.serial_number - w[0].header.serial_number, 10);
    }
    assert!(frames.iter().all(|f| f.header.serial_number % 10 == 0));
    // What Luna's client asks besides peaks.
    for (cmd, arg) in [
        ("#GetFPGAVersion", ""),
        ("#GetInstrumentName", ""),
        ("#GetAvailableDetectionSettings", ""),
        ("#GetAllChannelDetectionSettingIds", ""),
        ("#GetChannelDetectionSettingId", "1"),
        ("#getDetectionSetting", "0"),
        ("#GetPowerCalibrationInfo", ""),
        ("#getActiveFullSpectrumDutChannelNumbers", ""),
    ] {
        let r = command(commands, cmd, arg);
        assert_eq!(r.status, 0, "{cmd}: {}", r.message);
        assert!(!r.content.is_empty(), "{cmd}");
    }
    // The spectrum of the FBG channel has its brightest sample at FBG1 or FBG2's peak.
    let channel = serve.hardware.fbg.channel;
    assert_eq!(command(commands, "#setActiveFullSpectrumDutChannelNumbers", &channel.to_string()).status, 0);
    let spectrum = command(commands, "#GetSpectrum", "").content;
    let twin = serve.state.lock().unwrap().status.wavelengths;
    let f64_at = |i: usize| f64::from_le_bytes(spectrum[i..i + 8].try_into().unwrap());
    let points = u32::from_le_bytes(spectrum[40..44].try_into().unwrap()) as usize;
    assert_eq!(spectrum.len(), 48 + 2 * points);
    let sample = |i: usize| u16::from_le_bytes([spectrum[48 + 2 * i], spectrum[49 + 2 * i]]);
    let brightest = (0..points).max_by_key(|&i| sample(i)).unwrap();
    let nm = f64_at(24) + brightest as f64 * f64_at(32);
    assert!(
        (nm - twin.fbg1_nm).abs() < 0.05 || (nm - twin.fbg2_nm).abs() < 0.05,
        "brightest at {nm} nm, FBGs at {twin:?}"
    );
    serve.stop().unwrap();
}
