//! Rendered videos of finished runs (`tendril render`).
//!
//! A twin run records the scene's MuJoCo state at 30 frames/s of cell time in `frames.bin`
//! ([`frames`]). Rendering rebuilds the run's scene from its `scenario.toml` exactly as
//! `tendril run` built it, sets each recorded state, calls `mj_forward` (so the contacts and their
//! forces are MuJoCo's for that state) and draws it offscreen through EGL. Under the picture goes
//! the run's force trace from `trace.csv` with a moving time cursor and the task phase
//! ([`overlay`]); the frames are encoded as H.264 in an MP4 file (`video`) a browser plays.
//!
//! - [`frames`]: the `frames.bin` format and the recorder the simulated cell feeds.
//! - [`overlay`]: the force-trace panel.
//! - `video`: H.264 (OpenH264) in MP4, with the `video` feature ([`crate::features`]).

pub mod overlay;
#[cfg(feature = "video")]
pub mod video;

use std::path::{Path, PathBuf};
use tendril_render::{Camera, SceneRenderer, View};
use tendril_run::scenario::PickPlaceScenario;
use tendril_twin::frames::{self, FRAMES_FILE, FrameLog, Snapshot};
use tendril_twin::physics::SceneModel;
use tendril_twin::physics::follow_camera::DEFAULT_VIEWPOINT;

pub use tendril_render::MAX_SIDE;

/// What to render and how.
#[derive(Debug, Clone)]
pub struct RenderOptions {
    /// The video file to write (`.mp4`).
    pub out: PathBuf,
    /// Frames per second of video.
    pub fps: f64,
    /// Width of the picture \[px\] (even).
    pub width: u32,
    /// Height of the rendered scene \[px\] (even); the force panel goes below it.
    pub height: u32,
    /// Cell seconds per video second (2: twice as fast as the cell ran).
    pub speed: f64,
    /// The camera: tracking the object (the default), fixed on its start, the hand's or one of
    /// the model's.
    pub camera: Camera,
    /// Tracking and fixed camera: distance from the object \[m\].
    pub distance_m: f64,
    /// Tracking and fixed camera: azimuth \[°\].
    pub azimuth_deg: f64,
    /// Tracking and fixed camera: elevation \[°\] (negative: from above).
    pub elevation_deg: f64,
    /// Draw the force panel under the picture.
    pub panel: bool,
    /// Also write the video frame nearest this cell time \[s\] as a PNG beside the video
    /// (`out` with extension `.png`).
    pub still_s: Option<f64>,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            out: PathBuf::from("video.mp4"),
            fps: 30.0,
            width: 640,
            height: 480,
            speed: 1.0,
            camera: Camera::Tracking,
            distance_m: DEFAULT_VIEWPOINT.distance_m,
            azimuth_deg: DEFAULT_VIEWPOINT.azimuth_deg,
            elevation_deg: DEFAULT_VIEWPOINT.elevation_deg,
            panel: true,
            still_s: None,
        }
    }
}

impl RenderOptions {
    /// Checks the options, naming the one at fault.
    pub fn check(&self) -> anyhow::Result<()> {
        let side = |name: &str, v: u32| {
            if !(16..=MAX_SIDE).contains(&v) || !v.is_multiple_of(2) {
                anyhow::bail!(
                    "--{name} {v}: must be an even number of pixels from 16 to {MAX_SIDE} (H.264 needs even sides)"
                );
            }
            Ok(())
        };
        side("width", self.width)?;
        side("height", self.height)?;
        if !(self.fps.is_finite() && self.fps > 0.0 && self.fps <= 240.0) {
            anyhow::bail!("--fps {}: must be a number of frames per second in (0, 240]", self.fps);
        }
        if !(self.speed.is_finite() && self.speed > 0.0 && self.speed <= 1000.0) {
            anyhow::bail!("--speed {}: must be a factor in (0, 1000]", self.speed);
        }
        if !(self.distance_m.is_finite() && self.distance_m > 0.0 && self.distance_m <= 100.0) {
            anyhow::bail!("--distance {}: must be a number of metres in (0, 100]", self.distance_m);
        }
        if self.still_s.is_some_and(|t| !t.is_finite()) {
            anyhow::bail!("--still must be a finite cell time in seconds");
        }
        if !self.azimuth_deg.is_finite() || !(-90.0..=90.0).contains(&self.elevation_deg) {
            anyhow::bail!("--azimuth must be finite and --elevation within [-90, 90] degrees");
        }
        Ok(())
    }

    /// Height of the force panel under the picture \[px\] (even; 0 without panel).
    pub fn panel_height(&self) -> u32 {
        if self.panel { (self.height / 3).max(60).next_multiple_of(2) } else { 0 }
    }
}

/// What a render produced and how fast.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderStats {
    /// Frames written.
    pub frames: usize,
    /// Video size (width, height including the panel) \[px\].
    pub size: (u32, u32),
    /// Cell time covered \[s\].
    pub cell_s: f64,
    /// Wall time of the whole render (scene build, rendering, encoding) \[s\].
    pub wall_s: f64,
    /// Bytes of the MP4 file.
    pub bytes: u64,
}

impl RenderStats {
    /// Frames of video produced per wall second.
    pub fn frames_per_s(&self) -> f64 {
        self.frames as f64 / self.wall_s.max(1e-9)
    }

    /// Cell seconds rendered per wall second.
    pub fn cell_s_per_s(&self) -> f64 {
        self.cell_s / self.wall_s.max(1e-9)
    }
}

/// Number of video frames for `cell_s` seconds of cell time at `fps` and `speed`: one at cell
/// time 0 and one every `speed / fps` cell seconds up to the last recorded instant.
pub fn frame_count(cell_s: f64, fps: f64, speed: f64) -> usize {
    (cell_s * fps / speed + 1e-6).floor() as usize + 1
}

/// Renders the run in `run_dir` (its `frames.bin`, `scenario.toml` and, for the panel,
/// `trace.csv`) to `opts.out`.
pub fn render_run(run_dir: &Path, opts: &RenderOptions) -> anyhow::Result<RenderStats> {
    let started = std::time::Instant::now();
    crate::features::Feature::Video.require("tendril render")?;
    opts.check()?;
    let log = FrameLog::read(&run_dir.join(FRAMES_FILE))?;
    if log.is_empty() {
        anyhow::bail!("{}: holds no frame", run_dir.join(FRAMES_FILE).display());
    }
    let scenario_path = run_dir.join("scenario.toml");
    if !scenario_path.is_file() {
        anyhow::bail!("{}: no such file: the run directory must hold the run's scenario.toml", scenario_path.display());
    }
    let scenario: PickPlaceScenario = tendril_config::load(&scenario_path, &[])?;
    let scene = std::sync::Arc::new(SceneModel::build(&scenario.scene_spec())?);
    let trace = if opts.panel { Some(tendril_plot::trace::read(run_dir)?) } else { None };
    let view = View {
        width: opts.width,
        height: opts.height,
        camera: opts.camera.clone(),
        distance_m: opts.distance_m,
        azimuth_deg: opts.azimuth_deg,
        elevation_deg: opts.elevation_deg,
        // Contact forces as MuJoCo draws them. A rapier run's states are drawn through the same
        // model, but MuJoCo's contact solve at rapier's penetrations is not rapier's force: left out there.
        contact_forces: scenario.scene_spec().physics.backend == tendril_twin::physics::Backend::Mujoco,
    };
    let mut renderer = SceneRenderer::new(&scene, &view)
        .map_err(|e| if e.to_string().starts_with("camera ") { anyhow::anyhow!("--{e}") } else { e })?;
    let [nq, nv, nu, na] = renderer.state_sizes();
    let sizes = frames::StateSizes { nq, nv, nu, na };
    if sizes != log.sizes {
        anyhow::bail!(
            "{}: recorded for a model with {:?}, but {} builds one with {:?}: the scenario or the models \
             changed since the run; run it again",
            run_dir.join(FRAMES_FILE).display(),
            log.sizes,
            scenario_path.display(),
            sizes
        );
    }

    let cell_s = *log.times.last().unwrap_or(&0.0);
    let n = frame_count(cell_s, opts.fps, opts.speed);
    let panel_h = opts.panel_height();
    let (w, h) = (opts.width as usize, (opts.height + panel_h) as usize);
    let mut panel = match &trace {
        Some(t) => Some(overlay::Panel::new(t, opts.width, panel_h)?),
        None => None,
    };
    let mut encoder = video::Mp4Encoder::new(opts.width, opts.height + panel_h, opts.fps)?;
    let mut picture = vec![0u8; w * h * 3];
    let still = opts.still_s.map(|s| ((s.clamp(0.0, cell_s) * opts.fps / opts.speed).round() as usize).min(n - 1));
    for k in 0..n {
        let t = (k as f64 * opts.speed / opts.fps).min(cell_s);
        let state = frame_state(&log, nearest(&log.times, t));
        let rgb = renderer.render(&state, t).map_err(|e| e.context(format!("frame {k}")))?;
        picture[..rgb.len()].copy_from_slice(rgb);
        if let Some(p) = panel.as_mut() {
            p.draw(t, &mut picture[rgb.len()..])?;
        }
        encoder.add_frame(&picture)?;
        if still == Some(k) {
            write_png(&opts.out.with_extension("png"), &picture, opts.width, opts.height + panel_h)?;
        }
    }
    let bytes = encoder.finish(&opts.out)?;
    Ok(RenderStats {
        frames: n,
        size: (opts.width, opts.height + panel_h),
        cell_s,
        wall_s: started.elapsed().as_secs_f64(),
        bytes,
    })
}

/// Writes an RGB picture as a PNG file.
pub(crate) fn write_png(path: &Path, rgb: &[u8], width: u32, height: u32) -> anyhow::Result<()> {
    use mujoco_rs::renderer::png;
    let failed = |e: &dyn std::fmt::Display| anyhow::anyhow!("{}: cannot write: {e}", path.display());
    let mut bytes = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut bytes, width, height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().map_err(|e| failed(&e))?;
        writer.write_image_data(rgb).map_err(|e| failed(&e))?;
    }
    tendril_config::write_atomically(path, &bytes)
        .map_err(|(file, e)| anyhow::anyhow!("{}: cannot write: {e}", file.display()))
}

/// Index of the recorded time nearest `t` (`times` increasing, not empty).
fn nearest(times: &[f64], t: f64) -> usize {
    let i = times.partition_point(|&x| x < t);
    if i == 0 {
        0
    } else if i >= times.len() || t - times[i - 1] <= times[i] - t {
        i - 1
    } else {
        i
    }
}

/// Frame `i`'s state (`log` is not empty and `i` in range: [`nearest`]'s answer).
fn frame_state(log: &FrameLog, i: usize) -> Snapshot {
    let v: Vec<f64> = log.frame(i).unwrap_or_default().iter().map(|&x| f64::from(x)).collect();
    let s = log.sizes;
    let (qpos, rest) = v.split_at(s.nq);
    let (qvel, rest) = rest.split_at(s.nv);
    let (ctrl, act) = rest.split_at(s.nu);
    Snapshot { qpos: qpos.to_vec(), qvel: qvel.to_vec(), ctrl: ctrl.to_vec(), act: act.to_vec() }
}

/// A build without the `video` feature has no encoder to make: [`render_run`] has already said
/// how to build one (the type has no value, so nothing is ever encoded without it).
#[cfg(not(feature = "video"))]
mod video {
    /// The encoder a build without OpenH264 cannot make.
    pub struct Mp4Encoder(std::convert::Infallible);

    impl Mp4Encoder {
        pub fn new(_width: u32, _height: u32, _fps: f64) -> anyhow::Result<Mp4Encoder> {
            Err(crate::features::Feature::Video.missing("tendril render"))
        }

        pub fn add_frame(&mut self, _rgb: &[u8]) -> anyhow::Result<()> {
            match self.0 {}
        }

        pub fn finish(self, _path: &std::path::Path) -> anyhow::Result<u64> {
            match self.0 {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_counts_and_nearest_frames() {
        assert_eq!(frame_count(0.0, 30.0, 1.0), 1);
        assert_eq!(frame_count(1.0, 30.0, 1.0), 31);
        assert_eq!(frame_count(15.9, 10.0, 1.0), 160);
        assert_eq!(frame_count(10.0, 10.0, 2.0), 51);
        let t = [0.0, 0.1, 0.2];
        assert_eq!(nearest(&t, -1.0), 0);
        assert_eq!(nearest(&t, 0.04), 0);
        assert_eq!(nearest(&t, 0.06), 1);
        assert_eq!(nearest(&t, 5.0), 2);
    }

    #[test]
    fn bad_options_are_named() {
        let bad = RenderOptions { width: 641, ..Default::default() };
        assert!(bad.check().unwrap_err().to_string().contains("--width 641"));
        let bad = RenderOptions { fps: f64::NAN, ..Default::default() };
        assert!(bad.check().unwrap_err().to_string().contains("--fps"));
        assert!(RenderOptions::default().check().is_ok());
    }
}
