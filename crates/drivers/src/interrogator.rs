//! HYPERION si255 driver: identity over the command port (51971), peaks from the stream (51972).
//!
//! A reader task decodes streamed peak frames, maps them to every pad's FBG1/FBG2 by wavelength
//! window (pad 0's and a sensor array's further pads', [`FbgWindows::map_all`]) and keeps the
//! latest sample with its arrival time and serial number; gaps in the serial numbers are counted
//! (the watchdog in [`super::cell`] judges staleness by arrival time). A frame that does not map
//! (a peak missing from its window, or two in one) is skipped, and why is kept for the error the
//! cell reports if no mapped frame follows.

use super::tcp;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use tendril_codec::Decoded;
use tendril_fbg::array::ArrayPeaks;
use tendril_fbg::signals::Wavelengths;
use tendril_hyperion::{FbgWindows, PeakSequence, Request, Response, SequenceCheck, decode_stream_frame};
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::TcpStream;

const TIMEOUT: Duration = Duration::from_secs(3);

/// What the instrument says about itself.
#[derive(Debug, Clone, PartialEq)]
pub struct Identity {
    /// Serial number ("HIA...").
    pub serial_number: String,
    /// DUT channel count.
    pub channel_count: u32,
}

/// One mapped scan: pad 0's wavelengths and the further pads'.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PadSample {
    /// Pad 0's FBG1/FBG2.
    pub first: Wavelengths,
    /// The further pads' (empty without a sensor array).
    pub array: ArrayPeaks,
}

/// The stream reader's view.
#[derive(Debug, Default)]
pub struct PeakFeed {
    /// Latest mapped sample, its arrival time and scan serial number.
    pub latest: Option<(PadSample, Instant, u64)>,
    /// Why the latest frame could not be mapped (a peak missing from its window, or two in one),
    /// until a frame maps again.
    pub unmapped: Option<String>,
    /// Scans missed according to the serial numbers.
    pub missed_scans: u64,
    /// Why the stream ended, if it did.
    pub closed: Option<String>,
}

fn err(cause: impl std::fmt::Display) -> String {
    format!("HYPERION: {cause}")
}

/// Sends one command on a fresh command connection and returns the reply content.
pub async fn command(addr: &str, command: &str, argument: &str) -> Result<Vec<u8>, String> {
    let mut s = tcp::connect(addr, TIMEOUT).await.map_err(err)?;
    s.write_all(&Request::new(command, argument).encode().map_err(err)?).await.map_err(err)?;
    let mut buf = Vec::new();
    let mut chunk = [0u8; 4096];
    loop {
        match Response::decode(&buf) {
            Decoded::Frame { packet, .. } => return packet.into_result().map_err(err),
            Decoded::Invalid { error, .. } => return Err(err(error)),
            Decoded::NeedMore => {}
        }
        let n = tokio::time::timeout(TIMEOUT, s.read(&mut chunk))
            .await
            .map_err(|_| err(format!("{command}: no reply")))?
            .map_err(err)?;
        if n == 0 {
            return Err(err(format!("{command}: connection closed")));
        }
        buf.extend_from_slice(&chunk[..n]);
    }
}

/// Reads the serial number and the channel count; checks every window's channel exists.
pub async fn identify(addr: &str, windows: &FbgWindows) -> Result<Identity, String> {
    let serial = command(addr, "#GetSerialNumber", "").await?;
    let count = command(addr, "#GetDutChannelCount", "").await?;
    let channel_count = count
        .get(..4)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .ok_or_else(|| err("channel count reply is not a u32"))?;
    let channels = std::iter::once(windows.channel).chain(windows.pad_windows().iter().map(|p| p.channel));
    for channel in channels {
        if channel == 0 || channel as u32 > channel_count {
            return Err(err(format!("FBG channel {channel} not on a {channel_count}-channel instrument")));
        }
    }
    Ok(Identity { serial_number: String::from_utf8_lossy(&serial).trim().to_string(), channel_count })
}

/// Connects to the peak stream and spawns its reader task.
pub async fn stream(
    addr: &str,
    windows: FbgWindows,
) -> Result<(Arc<Mutex<PeakFeed>>, tokio::task::JoinHandle<()>), String> {
    let s = tcp::connect(addr, TIMEOUT).await.map_err(err)?;
    let feed = Arc::new(Mutex::new(PeakFeed::default()));
    let task = tokio::spawn(read_stream(s, windows, feed.clone()));
    Ok((feed, task))
}

async fn read_stream(mut s: TcpStream, windows: FbgWindows, feed: Arc<Mutex<PeakFeed>>) {
    let mut buf = Vec::new();
    let mut chunk = vec![0u8; 64 * 1024];
    let mut sequence = PeakSequence::default();
    let why = 'outer: loop {
        loop {
            match decode_stream_frame(&buf) {
                Decoded::NeedMore => break,
                Decoded::Invalid { error, .. } => break 'outer error.to_string(),
                Decoded::Frame { packet, consumed } => {
                    buf.drain(..consumed);
                    let serial = packet.header.serial_number;
                    let check = sequence.observe(serial);
                    let mapped = windows.map_all(&packet);
                    let mut f = feed.lock().unwrap_or_else(|p| p.into_inner());
                    if let SequenceCheck::Gap { missed } = check {
                        f.missed_scans += missed;
                    }
                    match mapped {
                        Ok((first, array)) => {
                            f.latest = Some((PadSample { first, array }, Instant::now(), serial));
                            f.unmapped = None;
                        }
                        // A frame without every grating is skipped: the watchdog notices if it
                        // lasts, and reports why.
                        Err(why) => f.unmapped = Some(format!("scan {serial}: {why}")),
                    }
                }
            }
        }
        match s.read(&mut chunk).await {
            Ok(0) => break "stream closed".to_string(),
            Ok(n) => buf.extend_from_slice(&chunk[..n]),
            Err(e) => break e.to_string(),
        }
    };
    feed.lock().unwrap_or_else(|p| p.into_inner()).closed = Some(err(why));
}
