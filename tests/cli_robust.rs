//! The command line under a hostile user (issue 18): operator stops by signal, write errors,
//! exit codes, unbounded arguments and names that would escape `out/`.

use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use crate::common::cli::{stderr, tendril, tendril_command};

/// Short moves (the grasp is set per test).
const SHORT: [&str; 8] =
    ["--set", "task.lift_s=1", "--set", "task.transfer_s=1", "--set", "task.lower_s=1", "--set", "task.release_s=0.5"];

/// Starts `cmd`, sends `signal` after `after`, and waits (at most 60 s) for it to end.
fn signal_after(cmd: &mut Command, signal: i32, after: Duration) -> Output {
    let child = cmd.stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().expect("tendril runs");
    std::thread::sleep(after);
    // SAFETY: plain kill(2) of the child we spawned, which has not been reaped yet.
    unsafe { libc::kill(child.id() as libc::pid_t, signal) };
    let started = Instant::now();
    let pid = child.id();
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(child.wait_with_output());
    });
    match rx.recv_timeout(Duration::from_secs(60)) {
        Ok(out) => {
            assert!(started.elapsed() < Duration::from_secs(10), "the stop took {:?}", started.elapsed());
            out.unwrap()
        }
        Err(_) => {
            // SAFETY: as above.
            unsafe { libc::kill(pid as libc::pid_t, libc::SIGKILL) };
            panic!("no clean stop within 60 s of the signal");
        }
    }
}

/// Every line of a trace has the header's cells and the file ends with a newline.
fn assert_whole_rows(trace: &Path) {
    let text = std::fs::read_to_string(trace).unwrap();
    assert!(text.ends_with('\n'), "torn last row");
    let cells = text.lines().next().map_or(0, |header| header.split(',').count());
    assert!(cells >= 16, "a header of {cells} cells");
    assert!(text.lines().all(|l| l.split(',').count() == cells), "a row is not whole");
    assert!(text.lines().count() > 10, "rows before the stop are kept");
}

#[test]
fn sigterm_and_sighup_stop_a_run_like_ctrl_c() {
    for (signal, code, name) in
        [(libc::SIGTERM, 143, "SIGTERM"), (libc::SIGHUP, 129, "SIGHUP"), (libc::SIGINT, 130, "SIGINT")]
    {
        let dir = tempfile::tempdir().unwrap();
        // A 10-minute grasp: only the signal ends it.
        let out = signal_after(
            tendril_command()
                .args(["run", "scenarios/crimper.toml", "--set", "task.grasp_s=600", "--out"])
                .arg(dir.path()),
            signal,
            Duration::from_millis(1500),
        );
        assert_eq!(out.status.code(), Some(code), "{name}: {}", stderr(&out));
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.path().join("summary.json")).unwrap()).unwrap();
        assert_eq!(summary["outcome"], "error");
        assert!(summary["error"].as_str().unwrap().contains(&format!("stopped by {name}")), "{summary}");
        assert_whole_rows(&dir.path().join("trace.csv"));
    }
}

#[test]
fn sigterm_stops_a_sweep_keeping_every_finished_row_whole() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = dir.path().join("sweep.toml");
    let scenario = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/crimper.toml");
    std::fs::write(
        &sweep,
        format!(
            "scenarios = ['{}']\n[grid]\nseed = [1, 2, 3, 4, 5, 6, 7, 8]\n'task.grasp_s' = [120.0]\n",
            scenario.display()
        ),
    )
    .unwrap();
    let out_dir = dir.path().join("out");
    let out = signal_after(
        tendril_command().args(["sweep", sweep.to_str().unwrap(), "--threads", "1", "--out"]).arg(&out_dir),
        libc::SIGTERM,
        Duration::from_millis(2500),
    );
    assert_eq!(out.status.code(), Some(143), "{}", stderr(&out));
    let results = out_dir.join("results.csv");
    let scan = tendril::sweep::durable::scan(&std::fs::read(&results).unwrap(), &results).unwrap();
    assert_eq!(scan.torn_tail, None);
    assert!(scan.rows.len() < 8, "stopped early: {} rows", scan.rows.len());
    assert!(scan.rows.iter().all(|r| r.cells.iter().any(|c| c == "held" || c == "dropped")), "no interrupted run kept");
}

#[test]
fn run_and_sweep_share_their_exit_codes() {
    let dir = tempfile::tempdir().unwrap();
    // Explicit Euler at 40 ms diverges: the run ends with outcome "error", files written.
    let diverge =
        ["--set", "physics.integrator=\"euler\"", "--set", "physics.timestep_s=0.04", "--set", "task.grasp_s=3"];
    let mut args = vec!["run", "scenarios/crimper.toml", "--out", dir.path().to_str().unwrap()];
    args.extend(diverge);
    args.extend(SHORT);
    let out = tendril(&args);
    assert_eq!(out.status.code(), Some(3), "{}", stderr(&out));

    let sweep = dir.path().join("sweep.toml");
    let scenario = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/crimper.toml");
    std::fs::write(
        &sweep,
        format!(
            "scenarios = ['{}']\n[grid]\n'physics.integrator' = ['euler']\n'physics.timestep_s' = [0.04]\n'task.grasp_s' = [3.0]\n",
            scenario.display()
        ),
    )
    .unwrap();
    let out = tendril(&["sweep", sweep.to_str().unwrap(), "--out", dir.path().join("s").to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(3), "a sweep with a diverging run: {}", stderr(&out));
}

#[test]
fn write_errors_are_reported_and_exit_non_zero() {
    let full = Path::new("/dev/full");
    if !full.exists() {
        eprintln!("NOTE: no /dev/full here");
        return;
    }
    let out = tendril_command()
        .args(["bench", "scenarios/bench-force-calibration.toml"])
        .stdout(std::fs::File::create(full).unwrap())
        .output()
        .unwrap();
    assert!(!out.status.success() && stderr(&out).contains("standard output"), "{}", stderr(&out));

    // trace.csv on a full device, summary.json on a good one: both attempted, the trace's failure reported.
    let dir = tempfile::tempdir().unwrap();
    std::os::unix::fs::symlink(full, dir.path().join("trace.csv")).unwrap();
    let mut args =
        vec!["run", "scenarios/crimper.toml", "--set", "task.grasp_s=3", "--out", dir.path().to_str().unwrap()];
    args.extend(SHORT);
    let out = tendril(&args);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(stderr(&out).contains("trace.csv: cannot write"), "{}", stderr(&out));
    assert!(dir.path().join("summary.json").exists(), "summary.json still written");
}

#[test]
fn unbounded_arguments_are_refused_at_once() {
    for args in [
        vec!["sweep", "scenarios/sweep-gains.toml", "--threads", "100000"],
        vec!["sweep", "scenarios/sweep-gains.toml", "--threads", "0"],
        vec!["chart", "gain-map", "--threads", "100000"],
        vec!["chart", "convergence", "--finest-step", "0.001"],
        vec!["chart", "convergence", "--finest-step", "0"],
        vec!["chart", "convergence", "--finest-step", "nan"],
        vec!["chart", "convergence", "--quick", "--finest-step", "0.0003"],
        vec!["serve", "scenarios/crimper.toml", "--seconds", "nan"],
        vec!["serve", "scenarios/crimper.toml", "--seconds", "-1"],
        vec!["latency", "--rate-hz", "0.001", "--seconds", "1"],
        vec!["latency", "--rate-hz", "100", "--seconds", "0.01"],
    ] {
        let started = Instant::now();
        let out = tendril(&args);
        assert!(!out.status.success(), "{args:?} accepted");
        assert!(started.elapsed() < Duration::from_secs(5), "{args:?} took {:?}", started.elapsed());
    }
}

/// A `--set` a study would not apply is refused before anything runs, naming what to do instead:
/// on a study that sets no keys, and on a key the speed-accuracy grid sets in every run itself.
#[test]
fn a_set_a_study_would_ignore_is_refused_by_name() {
    for (args, says) in [
        (vec!["chart", "stability", "--set", "finger.segments=7"], "--set applies to `chart convergence`"),
        (vec!["chart", "speed-accuracy", "--set", "physics.cone=pyramidal"], "--set physics.cone: the speed-accuracy"),
        (vec!["chart", "speed-accuracy", "--set", "physics.timestep_s=0.003"], "must be one of the study's steps"),
    ] {
        let started = Instant::now();
        let out = tendril(&args);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {}", stderr(&out));
        assert!(stderr(&out).contains(says), "{args:?}: {}", stderr(&out));
        assert!(started.elapsed() < Duration::from_secs(5), "{args:?} took {:?}", started.elapsed());
    }
}

/// The gain map's grid and overrides come from the command line: the grid given is the grid run,
/// and a gain or an override the bounds refuse is named before anything runs.
#[test]
fn the_gain_map_runs_the_grid_and_overrides_it_is_given() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().to_str().unwrap();
    let mut args = vec![
        "chart",
        "gain-map",
        "--scenario",
        "scenarios/crimper.toml",
        "--kp",
        "10,20",
        "--ki",
        "0.05",
        "--threads",
        "2",
        "--out",
        out_dir,
        "--set",
        "task.grasp_s=1",
        "--set",
        "task.minimum_durations=false",
    ];
    args.extend(SHORT);
    let out = tendril(&args);
    assert!(out.status.success(), "{}", stderr(&out));
    let csv = std::fs::read_to_string(dir.path().join("gain_map.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    assert_eq!(rows.len(), 2, "{csv}");
    assert!(rows[0].starts_with("crimper,10,0.05,") && rows[1].starts_with("crimper,20,0.05,"), "{csv}");
    let refused = tendril(&["chart", "gain-map", "--kp=-1", "--out", out_dir]);
    assert!(!refused.status.success());
    assert!(stderr(&refused).contains("controller.kp"), "{}", stderr(&refused));
    let refused = tendril(&["chart", "gain-map", "--set", "task.grasp_s=-1", "--out", out_dir]);
    assert!(!refused.status.success());
    assert!(stderr(&refused).contains("task.grasp_s"), "{}", stderr(&refused));
}

/// A missing file is named once with its reason, not with the reason repeated as its cause.
#[test]
fn a_missing_scenario_says_why_once() {
    let out = tendril(&["run", "no/such/scenario.toml"]);
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(err.contains("no/such/scenario.toml: cannot read"), "{err}");
    assert_eq!(err.matches("No such file or directory").count(), 1, "{err}");
}

#[test]
fn a_scenario_name_cannot_write_outside_out() {
    let dir = tempfile::tempdir().unwrap();
    let work = dir.path().join("a/b");
    std::fs::create_dir_all(&work).unwrap();
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/crimper.toml")).unwrap();
    for name in ["../../escaped_by_name", "/tmp/absolute_by_name"] {
        let scenario = work.join("s.toml");
        std::fs::write(&scenario, text.replacen("name = \"crimper\"", &format!("name = \"{name}\""), 1)).unwrap();
        let mut args = vec!["run", scenario.to_str().unwrap(), "--set", "task.grasp_s=3"];
        args.extend(SHORT);
        let out = Command::new(env!("CARGO_BIN_EXE_tendril")).current_dir(&work).args(&args).output().unwrap();
        assert!(out.status.success(), "{}", stderr(&out));
        let made: Vec<_> = std::fs::read_dir(work.join("out")).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(made.len(), 1, "{made:?}");
        assert!(work.join("out").join(&made[0]).join("summary.json").exists());
        std::fs::remove_dir_all(work.join("out")).unwrap();
    }
    assert!(!dir.path().join("escaped_by_name").exists());
    assert!(!Path::new("/tmp/absolute_by_name/summary.json").exists());
}

#[test]
fn serve_stops_cleanly_on_sigterm() {
    // Six free consecutive ports (serve takes N..N+5): bound and released by the OS's choice of the first.
    let base = (0..50)
        .find_map(|_| {
            let l = std::net::TcpListener::bind("127.0.0.1:0").ok()?;
            let p = l.local_addr().ok()?.port();
            drop(l);
            (p < 65000 && (1..7).all(|i| std::net::TcpListener::bind(("127.0.0.1", p + i)).is_ok())).then_some(p)
        })
        .expect("free ports");
    let out = signal_after(
        tendril_command().args([
            "serve",
            "scenarios/short-lift.toml",
            "--seconds",
            "60",
            "--port-base",
            &base.to_string(),
        ]),
        libc::SIGTERM,
        Duration::from_millis(2000),
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(String::from_utf8_lossy(&out.stdout).contains("twin ran"), "the status is reported");
    assert!(stderr(&out).contains("SIGTERM: stopping cleanly"), "{}", stderr(&out));
}

/// A disk that fills mid-sweep (here a file-size limit, `ulimit -f`, with SIGXFSZ ignored so the
/// write fails as on a full disk): a clear error, exit 1, the results file cut back to its whole
/// rows; once there is room, `--resume` runs the rest and every row is whole.
#[test]
fn a_full_disk_mid_sweep_loses_nothing_and_resume_completes_it() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = dir.path().join("sweep.toml");
    let scenario = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/crimper.toml");
    std::fs::write(
        &sweep,
        format!(
            "scenarios = ['{}']\n[grid]\nseed = [1, 2, 3, 4, 5, 6]\n'task.grasp_s' = [3.0]\n'task.lift_s' = [1.0]\n\
             'task.transfer_s' = [1.0]\n'task.lower_s' = [1.0]\n",
            scenario.display()
        ),
    )
    .unwrap();
    let out_dir = dir.path().join("out");
    // 2.5 KiB: the header (about 1.1 KiB) and a few rows (about 0.4 KiB each) fit, the sweep's
    // six do not.
    let limited = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "trap '' XFSZ; ulimit -f 5; exec '{}' sweep '{}' --out '{}' --threads 1",
            env!("CARGO_BIN_EXE_tendril"),
            sweep.display(),
            out_dir.display()
        ))
        .output()
        .unwrap();
    assert_eq!(limited.status.code(), Some(1), "{}", stderr(&limited));
    assert!(stderr(&limited).contains("results.csv"), "{}", stderr(&limited));
    let results = out_dir.join("results.csv");
    let scan = tendril::sweep::durable::scan(&std::fs::read(&results).unwrap(), &results).unwrap();
    assert_eq!(scan.torn_tail, None, "cut back to its whole rows");
    assert!(scan.rows.len() < 6, "the limit was reached");

    let out = tendril(&["sweep", sweep.to_str().unwrap(), "--out", out_dir.to_str().unwrap(), "--resume"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let scan = tendril::sweep::durable::scan(&std::fs::read(&results).unwrap(), &results).unwrap();
    let mut ids: Vec<usize> = scan.rows.iter().map(|r| r.run_id).collect();
    ids.sort();
    assert_eq!(ids, [0, 1, 2, 3, 4, 5], "no run lost, none twice");
}

/// A disk that fills during a run (a 16 KiB file-size limit, SIGXFSZ ignored): the trace's
/// failure is reported (exit 1), the trace is cut back to its whole rows, summary.json is written
/// and says why the run ended.
#[test]
fn a_full_disk_during_a_run_keeps_whole_trace_rows_and_reports_it() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("out");
    let scenario = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/crimper.toml");
    let out = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "trap '' XFSZ; ulimit -f 32; exec '{}' run '{}' --set task.grasp_s=3 --out '{}'",
            env!("CARGO_BIN_EXE_tendril"),
            scenario.display(),
            out_dir.display()
        ))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(stderr(&out).contains("trace.csv: cannot write"), "{}", stderr(&out));
    assert_whole_rows(&out_dir.join("trace.csv"));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["outcome"], "error");
    assert!(summary["error"].as_str().unwrap().contains("trace"), "{summary}");
}
