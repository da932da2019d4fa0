//! Content of `#GetSpectrum`, `#GetPowerCalibrationInfo` and the peak detection settings commands.
//!
//! Layouts from how Luna's `hyperion.py` unpacks them (native alignment on x86, little-endian):
//!
//! - spectrum: a 48-byte header `u16 header length, u16 version, u32 reserved, u64 serial number,
//!   u32 timestamp s, u32 timestamp ns, f64 start wavelength (nm), f64 wavelength increment (nm),
//!   u32 points, u16 channels, u16 active channel bits`, then `channels × points` u16 samples,
//!   channel by channel;
//! - power calibration: an i32 offset and an i32 scale per channel; dBm = sample / scale + offset;
//! - a detection setting: `u8 id, u8 name length, name, u8 description length, description,
//!   u16 boxcar length (pm), u16 difference filter length (pm), u16 lockout (pm), u16 NTV period
//!   (pm), i32 threshold, u8 mode (0 valley, 1 peak)`.
//!
//! The power calibration values and the detection preset are ours (the instrument's are not
//! published); the spectrum is the twin's line model ([`tendril_fbg::line_spectrum`]).

use super::HyperionError;

/// Header length of the spectrum content.
pub const SPECTRUM_HEADER_LEN: usize = 48;
/// Power calibration offset \[dB\]: sample 0 is −70 dBm.
pub const POWER_CAL_OFFSET_DB: i32 = -70;
/// Power calibration scale \[samples/dB\].
pub const POWER_CAL_SCALE: i32 = 500;
/// Reflected power at full reflection \[dBm\]: the source's power at the receiver (ours).
pub const FULL_REFLECTION_DBM: f64 = 0.0;
/// The floor of the reflected power \[dBm\] (no grating at that wavelength).
pub const NOISE_FLOOR_DBM: f64 = -60.0;

/// One acquired set of spectra.
#[derive(Debug, Clone, PartialEq)]
pub struct Spectra {
    /// Scan serial number.
    pub serial_number: u64,
    /// Timestamp, whole seconds and nanoseconds.
    pub timestamp: (u32, u32),
    /// First wavelength \[nm\].
    pub start_nm: f64,
    /// Wavelength step \[nm\].
    pub step_nm: f64,
    /// Reflectivity \[-\] per grid point, per active channel (1-based channel numbers, ascending).
    pub channels: Vec<(u32, Vec<f64>)>,
}

/// A reflectivity as a raw spectrum sample under the power calibration.
pub fn reflectivity_to_sample(reflectivity: f64) -> u16 {
    let dbm = if reflectivity > 0.0 {
        (FULL_REFLECTION_DBM + 10.0 * reflectivity.log10()).max(NOISE_FLOOR_DBM)
    } else {
        NOISE_FLOOR_DBM
    };
    let sample = (dbm - f64::from(POWER_CAL_OFFSET_DB)) * f64::from(POWER_CAL_SCALE);
    sample.round().clamp(0.0, f64::from(u16::MAX)) as u16
}

impl Spectra {
    /// The `#GetSpectrum` content.
    pub fn encode(&self) -> Result<Vec<u8>, HyperionError> {
        let points = self.channels.first().map_or(0, |(_, r)| r.len());
        if self.channels.iter().any(|(_, r)| r.len() != points) {
            return Err(HyperionError::BadConfig("spectra of unequal length".into()));
        }
        let mut bits = 0u16;
        for (c, _) in &self.channels {
            if !(1..=16).contains(c) {
                return Err(HyperionError::BadConfig(format!("channel {c} is not 1..16")));
            }
            bits |= 1 << (c - 1);
        }
        let too_long = |n| HyperionError::TooLong(n);
        let mut out = Vec::with_capacity(SPECTRUM_HEADER_LEN + 2 * points * self.channels.len());
        out.extend_from_slice(&(SPECTRUM_HEADER_LEN as u16).to_le_bytes());
        out.extend_from_slice(&1u16.to_le_bytes()); // version
        out.extend_from_slice(&0u32.to_le_bytes()); // reserved
        out.extend_from_slice(&self.serial_number.to_le_bytes());
        out.extend_from_slice(&self.timestamp.0.to_le_bytes());
        out.extend_from_slice(&self.timestamp.1.to_le_bytes());
        out.extend_from_slice(&self.start_nm.to_le_bytes());
        out.extend_from_slice(&self.step_nm.to_le_bytes());
        out.extend_from_slice(&u32::try_from(points).map_err(|_| too_long(points))?.to_le_bytes());
        out.extend_from_slice(&(self.channels.len() as u16).to_le_bytes());
        out.extend_from_slice(&bits.to_le_bytes());
        for (_, reflectivity) in &self.channels {
            for &r in reflectivity {
                out.extend_from_slice(&reflectivity_to_sample(r).to_le_bytes());
            }
        }
        Ok(out)
    }
}

/// The `#GetPowerCalibrationInfo` content for `channels` channels.
pub fn power_calibration(channels: u32) -> Vec<u8> {
    (0..channels).flat_map(|_| [POWER_CAL_OFFSET_DB.to_le_bytes(), POWER_CAL_SCALE.to_le_bytes()]).flatten().collect()
}

/// A peak detection preset.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DetectionSetting {
    /// Setting id (0..=127 on the instrument).
    pub id: u8,
    /// Name.
    pub name: String,
    /// Description.
    pub description: String,
    /// Boxcar filter length \[pm\].
    pub boxcar_pm: u16,
    /// Difference filter length \[pm\].
    pub diff_filter_pm: u16,
    /// Lockout length \[pm\].
    pub lockout_pm: u16,
    /// Noise threshold voltage period \[pm\].
    pub ntv_period_pm: u16,
    /// Normalised detection threshold.
    pub threshold: i32,
    /// Peaks (true) or valleys (false).
    pub peak: bool,
}

impl DetectionSetting {
    /// The one preset of the virtual instrument (values ours): peaks of lines 0.6-0.7 nm wide.
    pub fn virtual_default() -> DetectionSetting {
        DetectionSetting {
            id: 0,
            name: "tendril FBG".into(),
            description: "Peaks of 0.65 nm FBG lines (virtual instrument)".into(),
            boxcar_pm: 250,
            diff_filter_pm: 250,
            lockout_pm: 1000,
            ntv_period_pm: 10000,
            threshold: 13000,
            peak: true,
        }
    }

    /// The setting's binary record.
    pub fn encode(&self) -> Result<Vec<u8>, HyperionError> {
        let len8 = |s: &str| u8::try_from(s.len()).map_err(|_| HyperionError::TooLong(s.len()));
        let mut out = vec![self.id, len8(&self.name)?];
        out.extend_from_slice(self.name.as_bytes());
        out.push(len8(&self.description)?);
        out.extend_from_slice(self.description.as_bytes());
        for v in [self.boxcar_pm, self.diff_filter_pm, self.lockout_pm, self.ntv_period_pm] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out.extend_from_slice(&self.threshold.to_le_bytes());
        out.push(u8::from(self.peak));
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spectrum_header_is_48_bytes_then_channel_major_samples() {
        let spectra = Spectra {
            serial_number: 7,
            timestamp: (3, 500),
            start_nm: 1536.0,
            step_nm: 0.01,
            channels: vec![(1, vec![0.0, 0.4]), (3, vec![1.0, 0.0])],
        };
        let bytes = spectra.encode().unwrap();
        assert_eq!(bytes.len(), 48 + 2 * 2 * 2);
        assert_eq!(&bytes[0..2], &48u16.to_le_bytes());
        assert_eq!(&bytes[8..16], &7u64.to_le_bytes());
        assert_eq!(&bytes[24..32], &1536.0f64.to_le_bytes());
        assert_eq!(&bytes[40..44], &2u32.to_le_bytes());
        assert_eq!(&bytes[44..46], &2u16.to_le_bytes());
        assert_eq!(&bytes[46..48], &0b101u16.to_le_bytes(), "channels 1 and 3");
        let sample = |i: usize| u16::from_le_bytes([bytes[48 + 2 * i], bytes[49 + 2 * i]]);
        // dBm = sample / 500 − 70: the floor −60 dBm, 40 % ≈ −3.98 dBm, full reflection 0 dBm.
        assert_eq!(sample(0), 5000);
        assert_eq!(sample(1), 33010);
        assert_eq!(sample(2), 35000);
        assert!(Spectra { channels: vec![(17, vec![])], ..spectra }.encode().is_err());
    }

    #[test]
    fn power_calibration_and_detection_setting_records() {
        let cal = power_calibration(2);
        assert_eq!(cal.len(), 16);
        assert_eq!(&cal[8..12], &(-70i32).to_le_bytes());
        let record = DetectionSetting::virtual_default().encode().unwrap();
        let name_len = usize::from(record[1]);
        let description_len = usize::from(record[2 + name_len]);
        assert_eq!(record.len(), 2 + name_len + 1 + description_len + 13);
        assert_eq!(*record.last().unwrap(), 1, "peak mode");
    }
}
