//! A sans-IO virtual HYPERION si255: answers command requests and builds streamed peak frames.
//!
//! Content formats follow Luna's `hyperion.py` (how it unpacks each reply). The success message
//! texts and the error status value (1) are ours: the API shows a non-zero status is an error
//! whose message is the text, not which numbers or texts the instrument uses.
//!
//! Every scan handed to [`VirtualInterrogator::set_peaks`] is kept in a [`ScanBacklog`], so the
//! peak stream sends each one ([`VirtualInterrogator::stream_after`]), every n-th with
//! `#SetPeakDataStreamingDivider n`.

use super::HyperionError;
use super::message::{Request, Response};
use super::peaks::PeakFrame;
use super::spectrum::{DetectionSetting, Spectra, power_calibration};
use super::stream::ScanBacklog;
use tendril_codec::Decoded;
use tendril_fbg::{SpectralConfig, line_spectrum};

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
    /// Laser scan speeds offered, Hz (docs/facts.md#hyperion-scan-rate guesses about 1 kHz).
    pub available_scan_speeds_hz: Vec<i32>,
    /// FPGA version string (ours).
    pub fpga_version: String,
    /// The instrument's name at power-up (settable with `#SetInstrumentName`).
    pub instrument_name: String,
    /// The spectral line model and wavelength grid `#GetSpectrum` serves (the scenario's
    /// `[interrogator.spectral]`).
    pub spectral: SpectralConfig,
}

impl Default for InterrogatorConfig {
    fn default() -> Self {
        Self {
            serial_number: "HIA000".to_string(),
            firmware_version: "tendril-virtual".to_string(),
            channel_count: 4,
            max_peaks_per_channel: 16,
            available_scan_speeds_hz: vec![1000],
            fpga_version: "tendril-virtual".to_string(),
            instrument_name: "si255 (tendril virtual)".to_string(),
            spectral: SpectralConfig::default(),
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
    instrument_name: String,
    detection_settings: Vec<DetectionSetting>,
    channel_detection_ids: Vec<u8>,
    spectrum_channels: Vec<u32>,
    backlog: ScanBacklog,
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
        let channels = config.channel_count;
        Ok(Self {
            instrument_name: config.instrument_name.clone(),
            config,
            scan_speed_hz,
            peaks,
            streaming: true,
            streaming_divider: 1,
            utc: [2026, 1, 1, 0, 0, 0],
            detection_settings: vec![DetectionSetting::virtual_default()],
            channel_detection_ids: vec![0; channels as usize],
            spectrum_channels: (1..=channels).collect(),
            backlog: ScanBacklog::new(),
        })
    }

    /// Takes the latest scan (from the FBG forward model): `#GetPeaks` reports it and the stream
    /// sends it. Channels beyond the instrument's count are an error; missing ones are reported
    /// empty.
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
        self.backlog.push(frame.clone());
        self.peaks = frame;
        Ok(())
    }

    /// The stream's bytes for every scan after the one numbered `sent` (from the newest scan on
    /// when `None`: a new connection starts with the current scan), divider applied, and the serial
    /// number to pass next time. Streaming off sends nothing and skips those scans.
    pub fn stream_after(&self, sent: Option<u64>) -> Result<(Vec<u8>, Option<u64>), HyperionError> {
        let latest = self.backlog.latest_serial();
        if !self.streaming || latest.is_none() {
            return Ok((Vec::new(), latest.or(sent)));
        }
        let from = sent.or(latest.map(|l| l.saturating_sub(1)));
        let mut out = Vec::new();
        for scan in self.backlog.to_stream(from, self.streaming_divider) {
            out.extend_from_slice(&Response::ok("", scan.encode()?).encode()?);
        }
        Ok((out, latest))
    }

    /// The spectra of the active full-spectrum channels for the latest scan: each channel's peaks
    /// drawn as the twin's grating lines on its wavelength grid.
    pub fn spectra(&self) -> Spectra {
        let spectral = &self.config.spectral;
        let channels = self
            .spectrum_channels
            .iter()
            .map(|&c| (c, line_spectrum(spectral, self.peaks.channel(c as usize).unwrap_or(&[])).1))
            .collect();
        let h = &self.peaks.header;
        Spectra {
            serial_number: h.serial_number,
            timestamp: (h.timestamp_s, h.timestamp_ns),
            start_nm: spectral.start_nm,
            step_nm: spectral.step_pm / 1000.0,
            channels,
        }
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
            "#getfpgaversion" => Response::ok("FPGA version", self.config.fpga_version.as_bytes().to_vec()),
            "#getinstrumentname" => Response::ok("Instrument name", self.instrument_name.as_bytes().to_vec()),
            "#setinstrumentname" if !arg.is_empty() && arg.len() <= 64 => {
                self.instrument_name = arg.to_string();
                Response::ok("Instrument name set", Vec::new())
            }
            "#setinstrumentname" => Response::error(&format!("Invalid instrument name: {arg}")),
            "#getavailabledetectionsettings" => {
                let records: Result<Vec<Vec<u8>>, _> = self.detection_settings.iter().map(|d| d.encode()).collect();
                match records {
                    Ok(r) => Response::ok("Detection settings", r.concat()),
                    Err(e) => Response::error(&e.to_string()),
                }
            }
            "#getdetectionsetting" => match self.detection_setting(arg).map(DetectionSetting::encode) {
                Some(Ok(record)) => Response::ok("Detection setting", record),
                _ => Response::error(&format!("Invalid detection setting id: {arg}")),
            },
            "#getallchanneldetectionsettingids" => {
                Response::ok("Channel detection setting ids", self.channel_detection_ids.clone())
            }
            "#getchanneldetectionsettingid" => match self.channel_index(arg) {
                Some(i) => Response::ok(
                    "Channel detection setting id",
                    u16::from(self.channel_detection_ids[i]).to_le_bytes().to_vec(),
                ),
                None => Response::error(&format!("Invalid channel: {arg}")),
            },
            "#setchanneldetectionsettingid" => {
                let mut words = arg.split_whitespace();
                let channel = words.next().and_then(|c| self.channel_index(c));
                let setting = words.next().and_then(|id| self.detection_setting(id)).map(|d| d.id);
                match (channel, setting, words.next()) {
                    (Some(i), Some(id), None) => {
                        self.channel_detection_ids[i] = id;
                        Response::ok("Channel detection setting id set", Vec::new())
                    }
                    _ => Response::error(&format!("Invalid channel or detection setting id: {arg}")),
                }
            }
            "#getpowercalibrationinfo" => {
                Response::ok("Power calibration", power_calibration(self.config.channel_count))
            }
            "#getactivefullspectrumdutchannelnumbers" => Response::ok(
                "Active full spectrum channels",
                self.spectrum_channels.iter().flat_map(|&c| (c as i32).to_le_bytes()).collect(),
            ),
            "#setactivefullspectrumdutchannelnumbers" => {
                let channels: Option<Vec<u32>> =
                    arg.split_whitespace().map(|c| self.channel_index(c).map(|i| i as u32 + 1)).collect();
                match channels {
                    Some(mut c) if !c.is_empty() => {
                        c.sort_unstable();
                        c.dedup();
                        self.spectrum_channels = c;
                        Response::ok("Active full spectrum channels set", Vec::new())
                    }
                    _ => Response::error(&format!("Invalid channel list: {arg}")),
                }
            }
            "#getspectrum" => match self.spectra().encode() {
                Ok(content) => Response::ok("Spectrum", content),
                Err(e) => Response::error(&e.to_string()),
            },
            _ => Response::error(&format!("Unknown command: {}", request.command)),
        }
    }

    /// The 0-based index of the 1-based channel number `text`, if the instrument has it.
    fn channel_index(&self, text: &str) -> Option<usize> {
        let c = text.trim().parse::<u32>().ok()?;
        (1..=self.config.channel_count).contains(&c).then(|| c as usize - 1)
    }

    /// The detection preset with id `text`.
    fn detection_setting(&self, text: &str) -> Option<&DetectionSetting> {
        let id = text.trim().parse::<u8>().ok()?;
        self.detection_settings.iter().find(|d| d.id == id)
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

    fn scan(serial: u64, nm: f64) -> PeakFrame {
        PeakFrame {
            header: crate::PeakHeader { serial_number: serial, ..Default::default() },
            channels: vec![vec![nm, 1550.0]],
        }
    }

    fn streamed(bytes: &[u8]) -> Vec<u64> {
        let mut at = 0;
        let mut serials = Vec::new();
        while let Decoded::Frame { packet, consumed } = crate::decode_stream_frame(&bytes[at..]) {
            serials.push(packet.header.serial_number);
            at += consumed;
        }
        assert_eq!(at, bytes.len());
        serials
    }

    #[test]
    fn the_stream_sends_every_scan_once_and_honours_the_divider() {
        let mut dev = VirtualInterrogator::new(InterrogatorConfig::default()).unwrap();
        assert_eq!(dev.stream_after(None).unwrap(), (Vec::new(), None), "no scan yet");
        dev.set_peaks(scan(1, 1540.0)).unwrap();
        let (bytes, sent) = dev.stream_after(None).unwrap();
        assert_eq!((streamed(&bytes), sent), (vec![1], Some(1)), "a new reader starts at the newest scan");
        (2..=4).for_each(|k| dev.set_peaks(scan(k, 1540.0)).unwrap());
        let (bytes, sent) = dev.stream_after(sent).unwrap();
        assert_eq!((streamed(&bytes), sent), (vec![2, 3, 4], Some(4)), "no scan skipped, none twice");
        assert_eq!(ask(&mut dev, "#SetPeakDataStreamingDivider", "10").status, 0);
        (5..=25).for_each(|k| dev.set_peaks(scan(k, 1540.0)).unwrap());
        assert_eq!(streamed(&dev.stream_after(sent).unwrap().0), vec![10, 20]);
        ask(&mut dev, "#DisablePeakDataStreaming", "");
        dev.set_peaks(scan(30, 1540.0)).unwrap();
        assert_eq!(dev.stream_after(Some(25)).unwrap(), (Vec::new(), Some(30)), "off: skipped, not queued");
    }

    #[test]
    fn identity_and_detection_setting_commands_of_lunas_client() {
        let mut dev = VirtualInterrogator::new(InterrogatorConfig::default()).unwrap();
        assert_eq!(ask(&mut dev, "#GetFPGAVersion", "").content, b"tendril-virtual");
        assert_eq!(ask(&mut dev, "#SetInstrumentName", "bench").status, 0);
        assert_eq!(ask(&mut dev, "#GetInstrumentName", "").content, b"bench");
        let record = DetectionSetting::virtual_default().encode().unwrap();
        assert_eq!(ask(&mut dev, "#GetAvailableDetectionSettings", "").content, record);
        assert_eq!(ask(&mut dev, "#getDetectionSetting", "0").content, record);
        assert_ne!(ask(&mut dev, "#getDetectionSetting", "9").status, 0);
        assert_eq!(ask(&mut dev, "#GetAllChannelDetectionSettingIds", "").content, vec![0; 4]);
        assert_eq!(ask(&mut dev, "#GetChannelDetectionSettingId", "4").content, 0u16.to_le_bytes());
        assert_ne!(ask(&mut dev, "#GetChannelDetectionSettingId", "5").status, 0);
        assert_eq!(ask(&mut dev, "#SetChannelDetectionSettingID", "2 0").status, 0);
        assert_ne!(ask(&mut dev, "#SetChannelDetectionSettingID", "2 7").status, 0);
    }

    #[test]
    fn get_spectrum_draws_the_latest_peaks_as_grating_lines() {
        let mut dev = VirtualInterrogator::new(InterrogatorConfig::default()).unwrap();
        dev.set_peaks(scan(9, 1542.0)).unwrap();
        assert_eq!(ask(&mut dev, "#setActiveFullSpectrumDutChannelNumbers", "1 ").status, 0);
        assert_ne!(ask(&mut dev, "#setActiveFullSpectrumDutChannelNumbers", "0 1").status, 0);
        assert_eq!(ask(&mut dev, "#getActiveFullSpectrumDutChannelNumbers", "").content, 1i32.to_le_bytes());
        let content = ask(&mut dev, "#GetSpectrum", "").into_result().unwrap();
        let points = u32::from_le_bytes(content[40..44].try_into().unwrap()) as usize;
        assert_eq!(content.len(), 48 + 2 * points);
        assert_eq!(&content[8..16], &9u64.to_le_bytes());
        let sample = |i: usize| u16::from_le_bytes([content[48 + 2 * i], content[49 + 2 * i]]);
        let start = f64::from_le_bytes(content[24..32].try_into().unwrap());
        let step = f64::from_le_bytes(content[32..40].try_into().unwrap());
        // Below the channel split (1547.8 nm) the brightest sample is FBG1's line.
        let below_split = ((1547.8 - start) / step) as usize;
        let brightest = (0..below_split).max_by_key(|&i| sample(i)).unwrap();
        assert!((start + brightest as f64 * step - 1542.0).abs() < 0.006, "the line at the FBG1 peak");
        assert_eq!(sample(brightest), 33010, "40 % reflectivity");
        assert_eq!(ask(&mut dev, "#GetPowerCalibrationInfo", "").content.len(), 4 * 8);
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
