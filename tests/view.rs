//! `tendril view` from the command line: without a display it says so in one line and exits
//! non-zero (no panic), a display without a server the same, bad input errors before any window;
//! under Xvfb (when installed) a bounded session opens, steps the twin and saves a non-blank
//! screenshot. Without Xvfb that last test prints that it skipped and passes.

use std::path::Path;
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use crate::common::cli::{stderr, tendril_command};

const SHORT_LIFT: &str = crate::common::SHORT_LIFT;

/// `tendril view ARGS` with `display` as its only display (`None`: no display at all), killed
/// after `limit`.
fn view(args: &[&str], display: Option<&str>, limit: Duration) -> (Output, Duration) {
    let mut c = tendril_command();
    c.arg("view").args(args).env_remove("WAYLAND_DISPLAY").env_remove("DISPLAY");
    if let Some(d) = display {
        c.env("DISPLAY", d);
    }
    let started = Instant::now();
    let mut child = c.stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().expect("the binary runs");
    while child.try_wait().unwrap().is_none() {
        if started.elapsed() > limit {
            child.kill().unwrap();
            panic!("tendril view {args:?} still running after {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    (child.wait_with_output().unwrap(), started.elapsed())
}

/// Asserts a failure with exactly one line on standard error, which it returns.
fn one_line_failure(out: &Output) -> String {
    let err = stderr(out);
    assert!(!out.status.success(), "must fail; stderr: {err}");
    assert_eq!(err.lines().count(), 1, "one line on stderr, got:\n{err}");
    assert!(!err.contains("panicked") && !err.contains("backtrace"), "{err}");
    err
}

#[test]
fn without_a_display_it_says_so_in_one_line() {
    let (out, took) = view(&[SHORT_LIFT], None, Duration::from_secs(30));
    let err = one_line_failure(&out);
    assert!(err.starts_with("tendril: no display"), "{err}");
    assert!(err.contains("DISPLAY") && err.contains("WAYLAND_DISPLAY"), "names the variables: {err}");
    assert!(took < Duration::from_secs(10), "quick: {took:?}");
    assert!(out.stdout.is_empty());
}

#[test]
fn a_display_without_a_server_fails_in_one_line() {
    // A display number nothing listens on.
    let Some(n) = (90..200).find(|n| free_display(*n)) else {
        eprintln!("skipped: no free X display number");
        return;
    };
    let display = format!(":{n}");
    let (out, _) = view(&[SHORT_LIFT, "--seconds", "2"], Some(&display), Duration::from_secs(60));
    let err = one_line_failure(&out);
    assert!(err.contains(&format!("cannot open the viewer window on the X display {display}")), "{err}");
}

#[test]
fn bad_input_errors_before_any_window() {
    // The scenario is checked first: the key is named, not the missing display.
    let (out, _) = view(&[SHORT_LIFT, "--set", "physics.no_such_key=1"], None, Duration::from_secs(30));
    let err = one_line_failure(&out);
    assert!(err.contains("no_such_key") && !err.contains("display"), "{err}");
    let (out, _) = view(&["scenarios/no-such-scenario.toml"], None, Duration::from_secs(30));
    let err = one_line_failure(&out);
    assert!(err.contains("no-such-scenario.toml") && !err.contains("display"), "{err}");
    // A rapier scene has no MuJoCo state to show.
    let (out, _) = view(&[SHORT_LIFT, "--set", "physics.backend=\"rapier\""], None, Duration::from_secs(30));
    let err = one_line_failure(&out);
    assert!(err.contains("physics.backend = \"rapier\"") && err.contains("mujoco"), "{err}");
    // The screenshot's folder is checked before the window opens.
    let (out, _) = view(&[SHORT_LIFT, "--screenshot", "no/such/folder/shot.png"], None, Duration::from_secs(30));
    let err = one_line_failure(&out);
    assert!(err.contains("--screenshot no/such/folder/shot.png: no/such/folder: no such folder"), "{err}");
    for speed in ["0", "-2", "nan", "fast"] {
        let (out, _) = view(&[SHORT_LIFT, &format!("--speed={speed}")], None, Duration::from_secs(30));
        assert!(!out.status.success() && stderr(&out).contains("--speed"), "{speed}: {}", stderr(&out));
    }
}

/// Whether X display `n` has neither a socket nor a lock file.
fn free_display(n: u32) -> bool {
    !Path::new(&format!("/tmp/.X11-unix/X{n}")).exists() && !Path::new(&format!("/tmp/.X{n}-lock")).exists()
}

/// Xvfb on display `n`, killed when dropped.
struct Xvfb(Child);

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

#[test]
fn under_xvfb_a_bounded_session_steps_and_saves_a_screenshot() {
    let Ok(found) = Command::new("which").arg("Xvfb").output() else {
        eprintln!("skipped: `which` is missing, so Xvfb cannot be looked for");
        return;
    };
    if !found.status.success() {
        eprintln!("skipped: Xvfb is not installed (the live viewer needs a display)");
        return;
    }
    let n = (100..300).find(|n| free_display(*n)).expect("a free X display number");
    let server = Xvfb(
        Command::new("Xvfb")
            .args([&format!(":{n}"), "-screen", "0", "1280x800x24", "-nolisten", "tcp"])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("Xvfb starts"),
    );
    let socket = format!("/tmp/.X11-unix/X{n}");
    let started = Instant::now();
    while !Path::new(&socket).exists() {
        assert!(started.elapsed() < Duration::from_secs(10), "Xvfb did not come up on :{n}");
        std::thread::sleep(Duration::from_millis(50));
    }
    let dir = tempfile::tempdir().unwrap();
    let shot = dir.path().join("shot.png");
    let (out, _) = view(
        &[SHORT_LIFT, "--seconds", "6", "--speed", "2", "--screenshot", shot.to_str().unwrap()],
        Some(&format!(":{n}")),
        Duration::from_secs(120),
    );
    drop(server);
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(out.status.success(), "stdout: {text}\nstderr: {}", stderr(&out));
    // "viewed ...: task ..., X s of cell time in Y s (N ticks, M frames); wrote ..."
    let number_before = |word: &str| -> f64 {
        let head = &text[..text.find(word).unwrap_or_else(|| panic!("{word:?} in {text}"))];
        head.trim_end().rsplit([' ', '(']).next().unwrap().parse().unwrap()
    };
    assert!(number_before(" ticks") > 50.0, "stepped: {text}");
    assert!(number_before(" frames") > 10.0, "drew: {text}");
    assert!(number_before(" s of cell time") > 1.0, "{text}");

    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&shot).expect("the screenshot")));
    let mut reader = decoder.read_info().unwrap();
    let mut pixels = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut pixels).unwrap();
    let pixels = &pixels[..info.buffer_size()];
    assert!(info.width >= 320 && info.height >= 200, "{}x{}", info.width, info.height);
    // Not blank: many distinct colours (the scene, the panel), not one fill.
    let mut colours: Vec<&[u8]> = pixels.chunks_exact(info.color_type.samples()).collect();
    colours.sort_unstable();
    colours.dedup();
    assert!(colours.len() > 50, "a blank picture: {} colours", colours.len());
}

/// The session `tendril view` steps sees every tick, stepping it with the controller leaves the
/// run as `run_task` makes it, and switching feedback off between ticks stops force control
/// during the arm's moves.
#[test]
fn a_session_stepped_tick_by_tick_is_the_run_and_switches_feedback() {
    use tendril_control::task::Phase;
    use tendril_run::runner::run_task;
    use tendril_run::session::{Action, Session};
    use tendril_twin::physics::SceneModel;

    let scenario = crate::common::short_lift(&["feedback=true"]);
    let plan = scenario.control_plan();
    let model = SceneModel::build(&scenario.scene_spec()).unwrap();
    let plain = run_task(&mut scenario.sim_cell(model.clone()), &plan);
    let mut session = Session::start(scenario.sim_cell(model.clone()), &plan, plan.controller.build(), None);
    let mut seen = 0;
    while session.step(Action::Controller).is_some() {
        seen += 1;
    }
    let (stepped, _) = session.finish();
    assert_eq!(seen, stepped.rows.len());
    assert_eq!(stepped.rows, plain.rows, "stepping tick by tick changes nothing");
    let moving = |rows: &[tendril_run::trace::TraceRow]| rows.iter().filter(|r| r.phase.arm_moving()).count();
    assert!(moving(&plain.rows) > 10 && plain.rows.iter().any(|r| r.phase.arm_moving() && r.controller_on));

    let mut session = Session::start(scenario.sim_cell(model), &plan, plan.controller.build(), None);
    while let Some(row) = session.step(Action::Controller) {
        if row.phase == Phase::Grasp {
            session.set_feedback(false);
        }
    }
    let (switched, _) = session.finish();
    assert!(moving(&switched.rows) > 10);
    assert!(switched.rows.iter().filter(|r| r.phase.arm_moving()).all(|r| !r.controller_on), "feedback off");
}
