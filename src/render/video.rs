//! H.264 in MP4, without ffmpeg: Cisco's OpenH264 (the `openh264` crate builds it from source)
//! encodes RGB frames, the `mp4` crate writes the container. The encoder's Annex-B output is
//! split into NAL units; the parameter sets go into the track's `avcC` box and every picture's
//! units into one length-prefixed sample, as MP4 players (browsers) expect.

use mp4::{AvcConfig, FourCC, MediaConfig, Mp4Config, Mp4Sample, Mp4Writer, TrackConfig, TrackType};
use openh264::OpenH264API;
use openh264::encoder::{BitRate, Encoder, EncoderConfig, FrameRate, IntraFramePeriod, RateControlMode};
use openh264::formats::{RgbSliceU8, YUVBuffer};
use std::path::Path;

/// Media timescale of the video track \[ticks per second\].
const TIMESCALE: u32 = 90_000;

/// Encodes RGB frames of one size into an MP4 file (kept in memory until [`Mp4Encoder::finish`]).
pub struct Mp4Encoder {
    encoder: Encoder,
    width: u32,
    height: u32,
    fps: f64,
    sps: Option<Vec<u8>>,
    pps: Option<Vec<u8>>,
    /// Each picture's length-prefixed NAL units and whether it is a key frame.
    samples: Vec<(Vec<u8>, bool)>,
    yuv: YUVBuffer,
}

impl Mp4Encoder {
    /// An encoder for `width` × `height` (even) pictures at `fps`.
    pub fn new(width: u32, height: u32, fps: f64) -> anyhow::Result<Mp4Encoder> {
        // About 0.15 bit per pixel: sharp edges on flat surfaces, a few MB per minute at 640x640.
        let bps = ((f64::from(width) * f64::from(height) * fps * 0.15) as u32).clamp(200_000, 20_000_000);
        let config = EncoderConfig::new()
            .bitrate(BitRate::from_bps(bps))
            .max_frame_rate(FrameRate::from_hz(fps as f32))
            .rate_control_mode(RateControlMode::Off)
            // Every picture is a sample: the frame count and timing stay what the caller asked for.
            .skip_frames(false)
            // A key frame every 2 s, so a browser can seek.
            .intra_frame_period(IntraFramePeriod::from_num_frames((2.0 * fps).round().max(1.0) as u32));
        let encoder = Encoder::with_api_config(OpenH264API::from_source(), config)
            .map_err(|e| anyhow::anyhow!("cannot start the H.264 encoder: {e}"))?;
        Ok(Mp4Encoder {
            encoder,
            width,
            height,
            fps,
            sps: None,
            pps: None,
            samples: Vec::new(),
            yuv: YUVBuffer::new(width as usize, height as usize),
        })
    }

    /// Encodes one picture: `rgb` holds width × height × 3 bytes, rows top to bottom.
    pub fn add_frame(&mut self, rgb: &[u8]) -> anyhow::Result<()> {
        let (w, h) = (self.width as usize, self.height as usize);
        if rgb.len() != w * h * 3 {
            anyhow::bail!("a {w}x{h} frame needs {} bytes, got {}", w * h * 3, rgb.len());
        }
        self.yuv.read_rgb8(RgbSliceU8::new(rgb, (w, h)));
        let stream = self.encoder.encode(&self.yuv).map_err(|e| anyhow::anyhow!("H.264 encoding failed: {e}"))?;
        let mut sample = Vec::new();
        let mut key = false;
        for l in 0..stream.num_layers() {
            let Some(layer) = stream.layer(l) else { continue };
            for n in 0..layer.nal_count() {
                let Some(unit) = layer.nal_unit(n).map(strip_start_code) else { continue };
                let Some(&header) = unit.first() else { continue };
                match header & 0x1f {
                    7 => {
                        self.sps.get_or_insert_with(|| unit.to_vec());
                    }
                    8 => {
                        self.pps.get_or_insert_with(|| unit.to_vec());
                    }
                    kind => {
                        key |= kind == 5;
                        sample.extend_from_slice(&(unit.len() as u32).to_be_bytes());
                        sample.extend_from_slice(unit);
                    }
                }
            }
        }
        match (sample.is_empty(), self.samples.last_mut()) {
            // A skipped picture (none is asked for) repeats the previous one.
            (true, Some(_)) => self.samples.push((Vec::new(), false)),
            (true, None) => anyhow::bail!("the H.264 encoder gave nothing for the first picture"),
            (false, _) => self.samples.push((sample, key)),
        }
        Ok(())
    }

    /// Number of pictures so far.
    pub fn len(&self) -> usize {
        self.samples.len()
    }

    /// Whether no picture was added.
    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }

    /// Writes the MP4 file (atomically: a failure leaves no half file) and returns its size in
    /// bytes.
    pub fn finish(self, path: &Path) -> anyhow::Result<u64> {
        let (Some(sps), Some(pps)) = (self.sps, self.pps) else {
            anyhow::bail!("the H.264 encoder gave no parameter sets (no picture encoded?)");
        };
        let mut buf = std::io::Cursor::new(Vec::new());
        let config = Mp4Config {
            major_brand: FourCC::from(*b"isom"),
            minor_version: 512,
            compatible_brands: [*b"isom", *b"iso2", *b"avc1", *b"mp41"].into_iter().map(FourCC::from).collect(),
            timescale: 1000,
        };
        let mp4_error = |e: mp4::Error| anyhow::anyhow!("{}: cannot build the MP4 file: {e}", path.display());
        let mut writer = Mp4Writer::write_start(&mut buf, &config).map_err(mp4_error)?;
        writer
            .add_track(&TrackConfig {
                track_type: TrackType::Video,
                timescale: TIMESCALE,
                language: "und".into(),
                media_conf: MediaConfig::AvcConfig(AvcConfig {
                    width: self.width as u16,
                    height: self.height as u16,
                    seq_param_set: sps,
                    pic_param_set: pps,
                }),
            })
            .map_err(mp4_error)?;
        let tick = |k: usize| (k as f64 * f64::from(TIMESCALE) / self.fps).round() as u64;
        // Each picture lasts until the next one; a skipped picture lengthens the one before it.
        let mut k = 0;
        while k < self.samples.len() {
            let mut end = k + 1;
            while end < self.samples.len() && self.samples[end].0.is_empty() {
                end += 1;
            }
            let (bytes, key) = &self.samples[k];
            let sample = Mp4Sample {
                start_time: tick(k),
                duration: (tick(end) - tick(k)) as u32,
                rendering_offset: 0,
                is_sync: *key,
                bytes: mp4::Bytes::copy_from_slice(bytes),
            };
            writer.write_sample(1, &sample).map_err(mp4_error)?;
            k = end;
        }
        writer.write_end().map_err(mp4_error)?;
        let bytes = buf.into_inner();
        tendril_config::write_atomically(path, &bytes)
            .map_err(|(file, e)| anyhow::anyhow!("{}: cannot write: {e}", file.display()))?;
        Ok(bytes.len() as u64)
    }
}

/// A NAL unit without its Annex-B start code (`00 00 01` or `00 00 00 01`).
fn strip_start_code(unit: &[u8]) -> &[u8] {
    unit.strip_prefix(&[0, 0, 0, 1]).or_else(|| unit.strip_prefix(&[0, 0, 1])).unwrap_or(unit)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn start_codes_are_stripped() {
        assert_eq!(strip_start_code(&[0, 0, 0, 1, 0x67, 1]), &[0x67, 1]);
        assert_eq!(strip_start_code(&[0, 0, 1, 0x68]), &[0x68]);
        assert_eq!(strip_start_code(&[0x65, 0]), &[0x65, 0]);
    }
}
