//! A sans-IO virtual HYPERION si255: answers command requests and builds streamed peak frames.
//!
//! Content formats follow Luna's `hyperion.py` (how it unpacks each reply). The success message
//! texts and the error status value (1) are ours: the API shows a non-zero status is an error
//! whose message is the text, not which numbers or texts the instrument uses.

use super::HyperionError;
use super::message::{Request, Response};
use super::peaks::PeakFrame;
use crate::cell::real::protocol::Decoded;

/// What the virtual instrument reports.
#[derive(Debug, Clone, PartialEq)]
pub struct InterrogatorConfig {
    /// Serial number (6 ASCII characters starting "HIA" on real units).
    pub serial_number: String,
    /// Firmware version string (ours).
    pub firmware_version: String,
    /// DUT channels (1, 4, 8 or 16).
    pub channel_count: u32,
    /// Most peaks reported per channel.
    pub max_peaks_per_channel: u32,
    /// Laser scan speeds offered, Hz (hardware.md guesses about 1 kHz).
    pub available_scan_speeds_hz: Vec<i32>,
}

impl Default for InterrogatorConfig {
    fn default() -> Self {
        Self {
            serial_number: "HIA000".to_string(),
            firmware_version: "tendril-virtual".to_string(),
            channel_count: 4,
            max_peaks_per_channel: 16,
            available_scan_speeds_hz: vec![1000],
        }
    }
}

/// The virtual instrument's state.
#[derive(Debug, Clone)]
pub struct VirtualInterrogator {
    config: InterrogatorConfig,
    scan_speed_hz: u32,
    peaks: PeakFrame,
    streaming: bool,
    streaming_divider: u32,
    utc: [u16; 6],
}

impl VirtualInterrogator {
    /// A ready instrument with no peaks yet; fails on a channel count the si255 does not have.
    pub fn new(config: InterrogatorConfig) -> Result<Self, HyperionError> {
        if ![1, 4, 8, 16].contains(&config.channel_count) {
            return Err(HyperionError::BadConfig(format!(
                "channel count {} is not 1, 4, 8 or 16",
                config.channel_count
            )));
        }
        let scan_speed_hz = config
            .available_scan_speeds_hz
            .first()
            .and_then(|&s| u32::try_from(s).ok())
            .filter(|&s| s > 0)
            .ok_or_else(|| HyperionError::BadConfig("no positive laser scan speed".to_string()))?;
        let peaks = PeakFrame { channels: vec![Vec::new(); config.channel_count as usize], ..PeakFrame::default() };
        Ok(Self { config, scan_speed_hz, peaks, streaming: true, streaming_divider: 1, utc: [2026, 1, 1, 0, 0, 0] })
    }

    /// Replaces the latest scan (from the FBG forward model). Channels beyond the instrument's
    /// count are an error; missing ones are reported empty.
    pub fn set_peaks(&mut self, mut frame: PeakFrame) -> Result<(), HyperionError> {
        let n = self.config.channel_count as usize;
        if frame.channels.len() > n {
            return Err(HyperionError::BadConfig(format!(
                "{} channels on a {n}-channel instrument",
                frame.channels.len()
            )));
        }
        let max = self.config.max_peaks_per_channel as usize;
        if let Some(c) = frame.channels.iter().position(|p| p.len() > max) {
            return Err(HyperionError::BadConfig(format!("channel {} has more than {max} peaks", c + 1)));
        }
        frame.channels.resize(n, Vec::new());
        self.peaks = frame;
        Ok(())
    }

    /// The latest scan.
    pub fn peaks(&self) -> &PeakFrame {
        &self.peaks
    }

    /// Sets the instrument clock reported by `#GetInstrumentUtcDateTime` (year, month, day, h, min, s).
    pub fn set_utc(&mut self, utc: [u16; 6]) {
        self.utc = utc;
    }

    /// Current laser scan speed, Hz.
    pub fn scan_speed_hz(&self) -> u32 {
        self.scan_speed_hz
    }

    /// Whether the peak stream (51972) is on, and every how many scans it sends a frame.
    pub fn streaming(&self) -> (bool, u32) {
        (self.streaming, self.streaming_divider)
    }

    /// The bytes of one streamed peak frame (8-byte response header, then the peak content).
    pub fn stream_frame(&self) -> Result<Vec<u8>, HyperionError> {
        Response::ok("", self.peaks.encode()?).encode()
    }

    /// Takes complete requests off the front of `buf` (removing them) and returns the reply bytes.
    /// An error means the stream is unusable (oversized or non-ASCII request): close the connection.
    pub fn feed(&mut self, buf: &mut Vec<u8>) -> Result<Vec<u8>, HyperionError> {
        let mut out = Vec::new();
        loop {
            match Request::decode(buf) {
                Decoded::NeedMore => return Ok(out),
                Decoded::Frame { packet, consumed } => {
                    buf.drain(..consumed);
                    out.extend_from_slice(&self.handle(&packet).encode()?);
                }
                Decoded::Invalid { error, consumed } => {
                    buf.drain(..consumed);
                    return Err(error);
                }
            }
        }
    }

    /// Answers one command (commands are matched without regard to case).
    pub fn handle(&mut self, request: &Request) -> Response {
        let arg = request.argument.trim();
        let u32_content = |v: u32| v.to_le_bytes().to_vec();
        match request.command.to_ascii_lowercase().as_str() {
            "#getserialnumber" => Response::ok("Serial number", self.config.serial_number.as_bytes().to_vec()),
            "#getfirmwareversion" => Response::ok("Firmware version", self.config.firmware_version.as_bytes().to_vec()),
            "#isready" => Response::ok("Ready", vec![1]),
            "#getdutchannelcount" => Response::ok("Channel count", u32_content(self.config.channel_count)),
            "#getmaximumpeakcountperdutchannel" => {
                Response::ok("Maximum peak count", u32_content(self.config.max_peaks_per_channel))
            }
            "#getlaserscanspeed" => Response::ok("Laser scan speed", u32_content(self.scan_speed_hz)),
            "#getavailablelaserscanspeeds" => Response::ok(
                "Available laser scan speeds",
                self.config.available_scan_speeds_hz.iter().flat_map(|s| s.to_le_bytes()).collect(),
            ),
            "#setlaserscanspeed" => match arg.parse::<i32>() {
                Ok(speed) if speed > 0 && self.config.available_scan_speeds_hz.contains(&speed) => {
                    self.scan_speed_hz = speed as u32;
                    Response::ok("Laser scan speed set", Vec::new())
                }
                _ => Response::error(&format!("Invalid laser scan speed: {arg}")),
            },
            "#getpeaks" => match self.peaks.encode() {
                Ok(content) => Response::ok("Peaks", content),
                Err(e) => Response::error(&e.to_string()),
            },
            "#getinstrumentutcdatetime" => {
                Response::ok("UTC date and time", self.utc.iter().flat_map(|v| v.to_le_bytes()).collect())
            }
            "#enablepeakdatastreaming" => {
                self.streaming = true;
                Response::ok("Peak data streaming enabled", Vec::new())
            }
            "#disablepeakdatastreaming" => {
                self.streaming = false;
                Response::ok("Peak data streaming disabled", Vec::new())
            }
            "#setpeakdatastreamingdivider" => match arg.parse::<u32>() {
                Ok(d) if d > 0 => {
                    self.streaming_divider = d;
                    Response::ok("Peak data streaming divider set", Vec::new())
                }
                _ => Response::error(&format!("Invalid divider: {arg}")),
            },
            _ => Response::error(&format!("Unknown command: {}", request.command)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ask(dev: &mut VirtualInterrogator, command: &str, arg: &str) -> Response {
        dev.handle(&Request::new(command, arg))
    }

    #[test]
    fn identity_commands() {
        let mut dev = VirtualInterrogator::new(InterrogatorConfig::default()).unwrap();
        let serial = ask(&mut dev, "#GetSerialNumber", "").into_result().unwrap();
        assert_eq!(serial.len(), 6);
        assert!(serial.starts_with(b"HIA"));
        assert_eq!(ask(&mut dev, "#GetDutChannelCount", "").into_result().unwrap(), 4u32.to_le_bytes());
        assert_eq!(ask(&mut dev, "#isready", "").content, vec![1]);
        assert_eq!(ask(&mut dev, "#GetLaserScanSpeed", "").content, 1000u32.to_le_bytes());
        assert_eq!(ask(&mut dev, "#GetAvailableLaserScanSpeeds", "").content, 1000i32.to_le_bytes());
        assert_eq!(ask(&mut dev, "#GetInstrumentUtcDateTime", "").content.len(), 12);
    }

    #[test]
    fn get_peaks_returns_the_provided_scan() {
        let mut dev = VirtualInterrogator::new(InterrogatorConfig::default()).unwrap();
        let frame = PeakFrame { channels: vec![vec![1540.5, 1550.25]], ..PeakFrame::default() };
        dev.set_peaks(frame).unwrap();
        let content = ask(&mut dev, "#GetPeaks", "").into_result().unwrap();
        let decoded = PeakFrame::decode(&content).unwrap();
        assert_eq!(decoded.channels.len(), 4);
        assert_eq!(decoded.channel(1).unwrap(), &[1540.5, 1550.25]);
        assert!(dev.set_peaks(PeakFrame { channels: vec![vec![]; 5], ..PeakFrame::default() }).is_err());
    }

    #[test]
    fn feed_answers_pipelined_requests_in_order() {
        let mut dev = VirtualInterrogator::new(InterrogatorConfig::default()).unwrap();
        let mut buf = Request::new("#GetDutChannelCount", "").encode().unwrap();
        buf.extend_from_slice(&Request::new("#Bogus", "").encode().unwrap());
        let half = Request::new("#isready", "").encode().unwrap();
        buf.extend_from_slice(&half[..5]);
        let out = dev.feed(&mut buf).unwrap();
        assert_eq!(buf.len(), 5, "the partial request waits for the rest");
        let Decoded::Frame { packet: first, consumed } = Response::decode(&out) else { panic!("no reply") };
        assert_eq!(first.content, 4u32.to_le_bytes());
        let Decoded::Frame { packet: second, .. } = Response::decode(&out[consumed..]) else { panic!("no reply") };
        assert_ne!(second.status, 0);
    }

    #[test]
    fn unknown_command_and_bad_arguments_are_error_responses() {
        let mut dev = VirtualInterrogator::new(InterrogatorConfig::default()).unwrap();
        let r = ask(&mut dev, "#SelfDestruct", "");
        assert_ne!(r.status, 0);
        assert!(r.message.contains("#SelfDestruct"));
        assert!(r.content.is_empty());
        assert_ne!(ask(&mut dev, "#SetLaserScanSpeed", "12345").status, 0);
        assert_ne!(ask(&mut dev, "#SetPeakDataStreamingDivider", "0").status, 0);
        assert_eq!(ask(&mut dev, "#SetPeakDataStreamingDivider", "10").status, 0);
        assert_eq!(dev.streaming(), (true, 10));
        assert!(VirtualInterrogator::new(InterrogatorConfig { channel_count: 3, ..Default::default() }).is_err());
    }
}
