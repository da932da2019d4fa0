//! `tendril render` end to end: a short run rendered headless (EGL) at a small size, the MP4
//! decoded back (mp4 reader + OpenH264 decoder) and the pictures checked: the frame count for the
//! duration and rate, pictures that change while the arm moves, the object rising in the lift.
//!
//! No skipping: a machine without a working EGL (Mesa's llvmpipe suffices) fails this test, with
//! the renderer's message.

use std::io::Cursor;
use std::path::Path;

use crate::common::cli::{stderr, tendril};
use tendril_twin::frames::{FRAMES_FILE, FrameLog};

const WIDTH: usize = 160;
const HEIGHT: usize = 120;
const FPS: f64 = 10.0;

/// Decodes every picture of the MP4 file at `path` to RGB (width × height × 3 bytes each), and
/// gives the picture size.
fn decode(path: &Path) -> (Vec<Vec<u8>>, usize, usize) {
    let bytes = std::fs::read(path).unwrap();
    let size = bytes.len() as u64;
    let mut mp4 = mp4::Mp4Reader::read_header(Cursor::new(bytes), size).expect("an MP4 file");
    let (id, width, height, count, sps, pps) = {
        let track =
            mp4.tracks().values().find(|t| t.media_type().ok() == Some(mp4::MediaType::H264)).expect("an H.264 track");
        (
            track.track_id(),
            track.width() as usize,
            track.height() as usize,
            track.sample_count(),
            track.sequence_parameter_set().unwrap().to_vec(),
            track.picture_parameter_set().unwrap().to_vec(),
        )
    };
    let mut decoder = openh264::decoder::Decoder::new().unwrap();
    let mut pictures = Vec::new();
    for i in 1..=count {
        let sample = mp4.read_sample(id, i).unwrap().expect("every sample is there");
        // Length-prefixed units to Annex B, the parameter sets before the first picture.
        let mut annex_b = Vec::new();
        if i == 1 {
            for set in [&sps, &pps] {
                annex_b.extend([0, 0, 0, 1]);
                annex_b.extend(set.iter());
            }
        }
        let mut rest = &sample.bytes[..];
        while rest.len() >= 4 {
            let n = u32::from_be_bytes([rest[0], rest[1], rest[2], rest[3]]) as usize;
            annex_b.extend([0, 0, 0, 1]);
            annex_b.extend(&rest[4..4 + n]);
            rest = &rest[4 + n..];
        }
        let picture = decoder.decode(&annex_b).unwrap().expect("one picture per sample");
        let mut rgb = vec![0; width * height * 3];
        picture.write_rgb8(&mut rgb);
        pictures.push(rgb);
    }
    (pictures, width, height)
}

/// Mean absolute difference of the scene part (above the force panel) of two pictures.
fn scene_difference(a: &[u8], b: &[u8]) -> f64 {
    let n = WIDTH * HEIGHT * 3;
    a[..n].iter().zip(&b[..n]).map(|(x, y)| f64::from(x.abs_diff(*y))).sum::<f64>() / n as f64
}

/// Whether a pixel is of the crimper's red handle (rgba 0.8 0.1 0.1), lit or in shade.
fn is_red(p: &[u8], at: usize) -> bool {
    let (r, g, b) = (i32::from(p[at]), i32::from(p[at + 1]), i32::from(p[at + 2]));
    r > 90 && r > 2 * g + 30 && r > 2 * b + 30
}

/// Number of the object's red pixels in the scene part of a picture.
fn red_pixels(p: &[u8]) -> usize {
    (0..WIDTH * HEIGHT).filter(|&i| is_red(p, i * 3)).count()
}

/// The task's phases in the run's `trace.csv`, each with its first and last row's time \[s\].
fn phase_spans(run_dir: &Path) -> Vec<(String, f64, f64)> {
    let trace = std::fs::read_to_string(run_dir.join("trace.csv")).unwrap();
    let header: Vec<&str> = trace.lines().next().unwrap().split(',').collect();
    let (time, phase) =
        (header.iter().position(|c| *c == "time_s").unwrap(), header.iter().position(|c| *c == "phase").unwrap());
    let mut spans: Vec<(String, f64, f64)> = Vec::new();
    for line in trace.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let t: f64 = f[time].parse().unwrap();
        match spans.last_mut() {
            Some(last) if last.0 == f[phase] => last.2 = t,
            _ => spans.push((f[phase].to_string(), t, t)),
        }
    }
    spans
}

/// Renders `run_dir` with `camera` at the test's size and rate, without the force panel, and
/// decodes the pictures.
fn render_with(run_dir: &Path, camera: &str, video: &Path) -> Vec<Vec<u8>> {
    let (w, h, fps) = (WIDTH.to_string(), HEIGHT.to_string(), FPS.to_string());
    let run = run_dir.to_str().unwrap();
    let args = ["render", run, "--out", video.to_str().unwrap(), "--width", &w, "--height", &h, "--fps", &fps];
    let render = tendril(&[&args[..], &["--no-panel", "--camera", camera]].concat());
    assert!(render.status.success(), "tendril render --camera {camera} failed: {}", stderr(&render));
    decode(video).0
}

/// Mean row of the object's red pixels in the scene part (`None` if there are too few).
fn red_row(p: &[u8]) -> Option<f64> {
    let (mut sum, mut n) = (0.0, 0);
    for row in 0..HEIGHT {
        for col in 0..WIDTH {
            if is_red(p, (row * WIDTH + col) * 3) {
                sum += row as f64;
                n += 1;
            }
        }
    }
    (n >= 20).then(|| sum / f64::from(n))
}

#[test]
fn a_run_renders_to_a_video_that_shows_the_lift() {
    let dir = tempfile::tempdir().unwrap();
    let run_dir = dir.path().join("run");
    let run = tendril(&["run", "scenarios/short-lift.toml", "--out", run_dir.to_str().unwrap()]);
    assert!(run.status.success(), "run failed: {}", stderr(&run));
    let frames = FrameLog::read(&run_dir.join(FRAMES_FILE)).unwrap();
    let video = dir.path().join("lift.mp4");
    let (w, h, fps) = (WIDTH.to_string(), HEIGHT.to_string(), FPS.to_string());
    let render = tendril(&[
        "render",
        run_dir.to_str().unwrap(),
        "--out",
        video.to_str().unwrap(),
        "--width",
        &w,
        "--height",
        &h,
        "--fps",
        &fps,
        // The object rises in a fixed camera's picture (the tracking camera follows it up).
        "--camera",
        "fixed",
    ]);
    assert!(
        render.status.success(),
        "tendril render failed (this test needs EGL, e.g. Mesa's libEGL with llvmpipe): {}",
        stderr(&render)
    );

    let (pictures, width, height) = decode(&video);
    assert_eq!(width, WIDTH);
    assert!(height > HEIGHT, "the force panel is under the picture: {height} rows");
    let last = *frames.times.last().unwrap();
    assert_eq!(pictures.len(), tendril::render::frame_count(last, FPS, 1.0), "{last} s at {FPS} frames/s");

    // The lift, from the trace: the phase column's first and last `lift` rows.
    let trace = std::fs::read_to_string(run_dir.join("trace.csv")).unwrap();
    let header: Vec<&str> = trace.lines().next().unwrap().split(',').collect();
    let (time, phase) =
        (header.iter().position(|c| *c == "time_s").unwrap(), header.iter().position(|c| *c == "phase").unwrap());
    let lift: Vec<f64> = trace
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect::<Vec<_>>())
        .filter(|f| f[phase] == "lift")
        .map(|f| f[time].parse().unwrap())
        .collect();
    let (start, end) = (lift[0], *lift.last().unwrap());
    let (first, final_) = ((start * FPS).ceil() as usize, (end * FPS).floor() as usize);
    assert!(final_ > first + 5, "the lift lasts {} frames", final_ - first);

    // Consecutive pictures differ while the arm lifts.
    for k in first + 1..=final_ - 1 {
        let d = scene_difference(&pictures[k], &pictures[k + 1]);
        assert!(d > 0.05, "frames {k} and {} (t = {:.1} s, lifting) are alike: {d}", k + 1, k as f64 / FPS);
    }
    // The object (red) rises in the picture: its pixels' mean row goes up by a few pixels.
    let (before, after) = (red_row(&pictures[first]).unwrap(), red_row(&pictures[final_]).unwrap());
    assert!(after < before - 3.0, "the object did not rise in the picture: row {before:.1} -> {after:.1}");
}

/// The crimper's task shortened (a 2 s grasp, 3 s moves), every phase kept: the transfer swings
/// the arm 60° about its base, carrying the object about 0.4 m.
const SHORT_TASK: [&str; 10] = [
    "--set",
    "task.grasp_s=2",
    "--set",
    "task.lift_s=3",
    "--set",
    "task.transfer_s=3",
    "--set",
    "task.lower_s=2",
    "--set",
    "task.release_s=1",
];

#[test]
fn the_default_and_the_follow_camera_keep_the_object_in_view_in_every_phase_and_the_fixed_one_loses_it() {
    let dir = tempfile::tempdir().unwrap();
    let run_dir = dir.path().join("run");
    let run =
        tendril(&[&["run", "scenarios/crimper.toml", "--out", run_dir.to_str().unwrap()], &SHORT_TASK[..]].concat());
    assert!(run.status.success(), "run failed: {}", stderr(&run));
    let spans = phase_spans(&run_dir);
    let names: Vec<&str> = spans.iter().map(|s| s.0.as_str()).collect();
    for phase in ["grow", "wrap", "grasp", "lift", "transfer", "lower", "release"] {
        assert!(names.contains(&phase), "the run has no {phase} phase: {names:?}");
    }

    // The default camera (tracking), and the scene's own `follow` camera (the one MuJoCo's
    // viewers reach with `]`): the handle is in the picture in every frame of every phase.
    for camera in ["tracking", "follow"] {
        let pictures = render_with(&run_dir, camera, &dir.path().join(format!("{camera}.mp4")));
        for (phase, start, end) in &spans {
            let frames = (start * FPS).ceil() as usize..=((end * FPS).floor() as usize).min(pictures.len() - 1);
            for k in frames {
                let n = red_pixels(&pictures[k]);
                assert!(n >= 40, "{camera}, {phase}, t = {:.1} s: {n} pixels of the object in view", k as f64 / FPS);
            }
        }
    }

    // The fixed camera, aimed at the object's start, loses it during the transfer.
    let fixed = render_with(&run_dir, "fixed", &dir.path().join("fixed.mp4"));
    let (_, start, end) = spans.iter().find(|s| s.0 == "transfer").unwrap();
    let lost = ((start * FPS).ceil() as usize..=(end * FPS).floor() as usize).filter(|&k| red_pixels(&fixed[k]) == 0);
    assert!(lost.count() >= 5, "the fixed camera kept the object in view through the transfer");

    // A camera the model lacks is an error naming the choices.
    let out = tendril(&["render", run_dir.to_str().unwrap(), "--camera", "ceiling"]);
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(err.contains("--camera ceiling") && err.contains("tracking, fixed, follow, hand"), "{err}");
}

#[test]
fn a_run_without_frames_is_an_error_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy("scenarios/short-lift.toml", dir.path().join("scenario.toml")).unwrap();
    let out = tendril(&["render", dir.path().to_str().unwrap()]);
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(err.contains("frames.bin: no such file"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
}

#[test]
fn run_with_video_renders_the_run_when_it_ends() {
    let dir = tempfile::tempdir().unwrap();
    let run_dir = dir.path().join("run");
    let run = tendril(&["run", "scenarios/short-lift.toml", "--out", run_dir.to_str().unwrap(), "--video"]);
    assert!(run.status.success(), "run --video failed (needs EGL): {}", stderr(&run));
    let out = String::from_utf8_lossy(&run.stdout);
    assert!(out.contains("video.mp4"), "the run says it wrote the video: {out}");
    // tendril render's defaults: 640 wide, 30 frames per second of cell time.
    let (pictures, width, _) = decode(&run_dir.join("video.mp4"));
    let last = *FrameLog::read(&run_dir.join(FRAMES_FILE)).unwrap().times.last().unwrap();
    assert_eq!(width, 640);
    assert_eq!(pictures.len(), tendril::render::frame_count(last, 30.0, 1.0));
}

#[test]
fn run_with_video_on_the_real_cell_is_refused_before_it_starts() {
    let dir = tempfile::tempdir().unwrap();
    let out = tendril(&[
        "run",
        "scenarios/short-lift.toml",
        "--hardware",
        "real",
        "--video",
        "--out",
        dir.path().join("run").to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(err.contains("--video") && err.contains("real cell records none"), "{err}");
    assert!(!dir.path().join("run").exists(), "nothing ran");
}
