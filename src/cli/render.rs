//! `tendril render`.

use crate::render::{RenderOptions, render_run};
use std::path::PathBuf;
use std::process::ExitCode;
use tendril_twin::physics::follow_camera::DEFAULT_VIEWPOINT;

/// Arguments of `tendril render`.
#[derive(Debug, clap::Args)]
pub struct RenderArgs {
    /// A run directory written by `tendril run` (frames.bin, scenario.toml, trace.csv).
    run_dir: PathBuf,
    /// The video file to write [default: RUN_DIR/video.mp4].
    #[arg(long)]
    out: Option<PathBuf>,
    /// Frames per second of video.
    #[arg(long, default_value_t = 30.0)]
    fps: f64,
    /// Width of the picture [px] (even).
    #[arg(long, default_value_t = 640)]
    width: u32,
    /// Height of the rendered scene [px] (even); the force panel adds a third below.
    #[arg(long, default_value_t = 480)]
    height: u32,
    /// Cell seconds per video second (2: twice as fast as the cell ran).
    #[arg(long, default_value_t = 1.0)]
    speed: f64,
    /// The camera: `tracking` follows the object through every phase, `fixed` stays aimed at its
    /// start, `hand` looks along the tool from the hand, or the name of a camera in the scene's
    /// model (`follow`: the model's camera on the arm's base link, aimed at the object, as
    /// MuJoCo's viewers show it).
    #[arg(long, default_value = "tracking")]
    camera: String,
    /// Tracking and fixed camera: distance from the object [m].
    #[arg(long, default_value_t = DEFAULT_VIEWPOINT.distance_m)]
    distance: f64,
    /// Tracking and fixed camera: azimuth [°].
    #[arg(long, default_value_t = DEFAULT_VIEWPOINT.azimuth_deg, allow_negative_numbers = true)]
    azimuth: f64,
    /// Tracking and fixed camera: elevation [°] (negative looks down).
    #[arg(long, default_value_t = DEFAULT_VIEWPOINT.elevation_deg, allow_negative_numbers = true)]
    elevation: f64,
    /// Leave out the force panel under the picture.
    #[arg(long)]
    no_panel: bool,
    /// Also write the picture at this cell time [s] as a PNG (beside the video, `.png`).
    #[arg(long)]
    still: Option<f64>,
}

/// `tendril render`: a run's recorded frames as an MP4 video.
pub fn run(a: RenderArgs) -> anyhow::Result<ExitCode> {
    let opts = RenderOptions {
        out: a.out.clone().unwrap_or_else(|| a.run_dir.join("video.mp4")),
        fps: a.fps,
        width: a.width,
        height: a.height,
        speed: a.speed,
        camera: tendril_render::Camera::parse(&a.camera),
        distance_m: a.distance,
        azimuth_deg: a.azimuth,
        elevation_deg: a.elevation,
        panel: !a.no_panel,
        still_s: a.still,
    };
    render_and_report(&a.run_dir, &opts)?;
    Ok(ExitCode::SUCCESS)
}

/// Renders `run_dir` with `opts` and prints what was written and how fast (also `tendril run
/// --video`).
pub(super) fn render_and_report(run_dir: &std::path::Path, opts: &RenderOptions) -> anyhow::Result<()> {
    let stats = render_run(run_dir, opts)?;
    super::emit(&format!(
        "wrote {} ({} frames, {}x{}, {:.1} s of cell time, {:.0} kB) in {:.1} s: {:.1} frames/s, {:.2} cell s per s\n",
        opts.out.display(),
        stats.frames,
        stats.size.0,
        stats.size.1,
        stats.cell_s,
        stats.bytes as f64 / 1000.0,
        stats.wall_s,
        stats.frames_per_s(),
        stats.cell_s_per_s()
    ));
    Ok(())
}
