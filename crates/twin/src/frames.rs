//! `frames.bin`: the MuJoCo state of a run at a fixed rate of cell time, what `tendril render`
//! needs to redraw the run afterwards.
//!
//! Little-endian throughout. A 48-byte header:
//!
//! | bytes | field |
//! |---|---|
//! | 0..8 | magic `TNDRLFRM` |
//! | 8..12 | format version (u32, 1) |
//! | 12..28 | `nq`, `nv`, `nu`, `na` of the scene's model (u32 each) |
//! | 28..36 | recording rate \[frames per second of cell time\] (f64) |
//! | 36..44 | physics timestep \[s\] (f64) |
//! | 44..48 | reserved (0) |
//!
//! then one record per frame: the cell time \[s\] (f64), then `qpos`, `qvel`, `ctrl` and `act`
//! in MuJoCo's layout (`nq + nv + nu + na` f32). f32 keeps the file small (a 30 s run at 30
//! frames/s with the default 32-link finger is ≈ 0.5 MB) and is far finer than a pixel.
//! The frame count follows from the file's length.

use std::path::Path;

// The state is the physics's (a run hands it out); the frames file records it.
pub use crate::physics::Snapshot;

/// The file's name in a run directory.
pub const FRAMES_FILE: &str = "frames.bin";

/// Frames per second of cell time a run records.
pub const RECORD_FPS: f64 = 30.0;

const MAGIC: &[u8; 8] = b"TNDRLFRM";
const VERSION: u32 = 1;
const HEADER_LEN: usize = 48;

/// Sizes of the state vectors of a model (MuJoCo's `nq`, `nv`, `nu`, `na`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StateSizes {
    /// Generalised positions.
    pub nq: usize,
    /// Generalised velocities.
    pub nv: usize,
    /// Actuator controls.
    pub nu: usize,
    /// Actuator activations.
    pub na: usize,
}

impl StateSizes {
    /// Values per frame.
    pub fn total(&self) -> usize {
        self.nq + self.nv + self.nu + self.na
    }
}

/// Why a frames file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum FramesError {
    /// The file could not be read or written.
    #[error("{file}: {cause}")]
    Io {
        /// The file.
        file: String,
        /// The I/O error.
        cause: std::io::Error,
    },
    /// The file is not a frames file of this version, or is cut short.
    #[error("{file}: not a tendril frames file: {what}")]
    Malformed {
        /// The file.
        file: String,
        /// What is wrong.
        what: String,
    },
}

/// The recorded states of a run (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct FrameLog {
    /// State vector sizes.
    pub sizes: StateSizes,
    /// Recording rate \[frames per second of cell time\].
    pub fps: f64,
    /// Physics timestep \[s\].
    pub timestep_s: f64,
    /// Cell time of each frame \[s\], increasing.
    pub times: Vec<f64>,
    /// The frames' values, `sizes.total()` per frame: qpos, qvel, ctrl, act.
    pub values: Vec<f32>,
}

impl FrameLog {
    /// An empty log.
    pub fn new(sizes: StateSizes, fps: f64, timestep_s: f64) -> FrameLog {
        FrameLog { sizes, fps, timestep_s, times: Vec::new(), values: Vec::new() }
    }

    /// Number of frames.
    pub fn len(&self) -> usize {
        self.times.len()
    }

    /// Whether there is no frame.
    pub fn is_empty(&self) -> bool {
        self.times.is_empty()
    }

    /// The values of frame `i` (qpos, qvel, ctrl, act); `None` out of range.
    pub fn frame(&self, i: usize) -> Option<&[f32]> {
        let n = self.sizes.total();
        self.values.get(i * n..(i + 1) * n)
    }

    /// Appends a frame; a snapshot of the wrong sizes is ignored (it cannot come from this model).
    pub fn push(&mut self, time_s: f64, s: &Snapshot) {
        let sizes = StateSizes { nq: s.qpos.len(), nv: s.qvel.len(), nu: s.ctrl.len(), na: s.act.len() };
        if sizes != self.sizes {
            return;
        }
        self.times.push(time_s);
        for v in [&s.qpos, &s.qvel, &s.ctrl, &s.act] {
            self.values.extend(v.iter().map(|&x| x as f32));
        }
    }

    /// The file's bytes.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut b = Vec::with_capacity(HEADER_LEN + self.len() * (8 + 4 * self.sizes.total()));
        b.extend_from_slice(MAGIC);
        b.extend_from_slice(&VERSION.to_le_bytes());
        for n in [self.sizes.nq, self.sizes.nv, self.sizes.nu, self.sizes.na] {
            b.extend_from_slice(&(n as u32).to_le_bytes());
        }
        b.extend_from_slice(&self.fps.to_le_bytes());
        b.extend_from_slice(&self.timestep_s.to_le_bytes());
        b.extend_from_slice(&[0; 4]);
        let n = self.sizes.total();
        for (i, t) in self.times.iter().enumerate() {
            b.extend_from_slice(&t.to_le_bytes());
            for v in &self.values[i * n..(i + 1) * n] {
                b.extend_from_slice(&v.to_le_bytes());
            }
        }
        b
    }

    /// Parses a file's bytes; `file` names it in errors.
    pub fn from_bytes(b: &[u8], file: &str) -> Result<FrameLog, FramesError> {
        let bad = |what: String| FramesError::Malformed { file: file.to_string(), what };
        if b.len() < HEADER_LEN || &b[..8] != MAGIC {
            return Err(bad("no `TNDRLFRM` header".into()));
        }
        let u32_at = |at: usize| u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]]);
        let f64_at = |at: usize| {
            let mut x = [0; 8];
            x.copy_from_slice(&b[at..at + 8]);
            f64::from_le_bytes(x)
        };
        let version = u32_at(8);
        if version != VERSION {
            return Err(bad(format!("format version {version}, this tendril reads {VERSION}")));
        }
        let sizes = StateSizes {
            nq: u32_at(12) as usize,
            nv: u32_at(16) as usize,
            nu: u32_at(20) as usize,
            na: u32_at(24) as usize,
        };
        let (fps, timestep_s) = (f64_at(28), f64_at(36));
        if !(fps.is_finite() && fps > 0.0 && timestep_s.is_finite() && timestep_s > 0.0) {
            return Err(bad(format!("rate {fps} frames/s or timestep {timestep_s} s is not a positive number")));
        }
        if sizes.nq == 0 || sizes.total() > 1 << 20 {
            return Err(bad(format!("implausible state sizes {sizes:?}")));
        }
        let n = sizes.total();
        let record = 8 + 4 * n;
        let body = &b[HEADER_LEN..];
        if !body.len().is_multiple_of(record) {
            return Err(bad(format!(
                "{} bytes of frames are not a whole number of {record}-byte frames (a cut-off file?)",
                body.len()
            )));
        }
        let mut log = FrameLog::new(sizes, fps, timestep_s);
        for r in body.chunks_exact(record) {
            let mut t = [0; 8];
            t.copy_from_slice(&r[..8]);
            let t = f64::from_le_bytes(t);
            if !t.is_finite() || log.times.last().is_some_and(|&last| last >= t) {
                return Err(bad(format!("frame {}: time {t} is not finite or not increasing", log.len())));
            }
            log.times.push(t);
            log.values.extend(r[8..].chunks_exact(4).map(|v| f32::from_le_bytes([v[0], v[1], v[2], v[3]])));
        }
        Ok(log)
    }

    /// Reads a frames file. A missing file is an error that says how to get one.
    pub fn read(path: &Path) -> Result<FrameLog, FramesError> {
        let file = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|cause| match cause.kind() {
            std::io::ErrorKind::NotFound => FramesError::Io {
                file: file.clone(),
                cause: std::io::Error::new(
                    cause.kind(),
                    "no such file: this run recorded no frames (a run on the real cell, or made by an \
                     older tendril); repeat it with `tendril run RUN_DIR/scenario.toml --out RUN_DIR`",
                ),
            },
            _ => FramesError::Io { file: file.clone(), cause },
        })?;
        FrameLog::from_bytes(&bytes, &file)
    }

    /// Writes the file atomically (a failure leaves no half file).
    pub fn write(&self, path: &Path) -> Result<(), FramesError> {
        tendril_config::write_atomically(path, &self.to_bytes())
            .map_err(|(file, cause)| FramesError::Io { file: file.display().to_string(), cause })
    }
}

/// Records a [`FrameLog`] while a run steps: offered the state after every physics step, it keeps
/// the first state at or after each frame instant (`k / fps`, within half a step).
#[derive(Debug, Clone)]
pub struct FrameRecorder {
    log: Option<FrameLog>,
    fps: f64,
    next_s: f64,
}

impl FrameRecorder {
    /// A recorder at `fps` frames per second of cell time.
    pub fn new(fps: f64) -> FrameRecorder {
        FrameRecorder { log: None, fps, next_s: 0.0 }
    }

    /// Whether the state at `time_s` is due (call [`FrameRecorder::record`] then); cheap.
    pub fn due(&self, time_s: f64, timestep_s: f64) -> bool {
        time_s >= self.next_s - 0.5 * timestep_s
    }

    /// Records the state at `time_s` if due. A backend without a MuJoCo state
    /// (`snapshot` gives `None`) records nothing.
    pub fn record(&mut self, time_s: f64, timestep_s: f64, snapshot: Option<Snapshot>) {
        if !self.due(time_s, timestep_s) {
            return;
        }
        let Some(s) = snapshot else { return };
        let sizes = StateSizes { nq: s.qpos.len(), nv: s.qvel.len(), nu: s.ctrl.len(), na: s.act.len() };
        let log = self.log.get_or_insert_with(|| FrameLog::new(sizes, self.fps, timestep_s));
        log.push(time_s, &s);
        // The next instant after this one (a step longer than a frame skips instants, never repeats one).
        let period = 1.0 / self.fps;
        while self.next_s - 0.5 * timestep_s <= time_s {
            self.next_s += period;
        }
    }

    /// Records `physics`'s state if due (see [`FrameRecorder::record`]).
    pub fn offer(&mut self, physics: &dyn crate::physics::Physics) {
        let (t, dt) = (physics.time(), physics.timestep());
        if self.due(t, dt) {
            self.record(t, dt, physics.snapshot());
        }
    }

    /// The frames recorded so far (`None` if none).
    pub fn take(&mut self) -> Option<FrameLog> {
        self.log.take()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn snap(x: f64) -> Snapshot {
        Snapshot { qpos: vec![x, 2.0 * x], qvel: vec![-x], ctrl: vec![0.5], act: vec![] }
    }

    #[test]
    fn records_one_frame_per_instant_and_reads_back() {
        let mut r = FrameRecorder::new(30.0);
        let dt = 0.002;
        for k in 0..=1000 {
            let t = k as f64 * dt;
            if r.due(t, dt) {
                r.record(t, dt, Some(snap(t)));
            }
        }
        let log = r.take().unwrap();
        // 2 s at 30 frames/s: instants 0, 1/30, ..., 60/30.
        assert_eq!(log.len(), 61);
        for (k, t) in log.times.iter().enumerate() {
            assert!((t - k as f64 / 30.0).abs() <= dt, "frame {k} at {t}");
        }
        let back = FrameLog::from_bytes(&log.to_bytes(), "x").unwrap();
        assert_eq!(back, log);
        assert_eq!(back.frame(1).unwrap()[2], -(log.times[1] as f32));
        let mut cut = log.to_bytes();
        cut.pop();
        assert!(FrameLog::from_bytes(&cut, "x").unwrap_err().to_string().contains("cut-off"));
        assert!(FrameLog::from_bytes(b"nonsense", "f.bin").unwrap_err().to_string().starts_with("f.bin: "));
    }
}
