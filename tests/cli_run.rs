//! `tendril run`, `sweep` and `merge` as a user calls them: files written, errors named, nothing
//! finished lost.

use std::path::{Path, PathBuf};
use std::process::Output;

use crate::common::cli::{stderr, tendril};

/// A short pick-and-place (grasp 3 s, moves 1 s each) so the tests take a second, not a minute.
const SHORT: [&str; 10] = [
    "--set",
    "task.grasp_s=3",
    "--set",
    "task.lift_s=1",
    "--set",
    "task.transfer_s=1",
    "--set",
    "task.lower_s=1",
    "--set",
    "task.release_s=0.5",
];

fn run_short(dir: &Path, extra: &[&str]) -> Output {
    let mut args = vec!["run", "scenarios/crimper.toml", "--out", dir.to_str().unwrap()];
    args.extend(SHORT);
    args.extend(extra);
    tendril(&args)
}

#[test]
fn run_writes_trace_and_summary_with_the_documented_fields() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_short(dir.path(), &["--seed", "7", "--feedback", "off"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("summary.json")).unwrap()).unwrap();
    for key in [
        "scenario",
        "object",
        "mass_kg",
        "feedback",
        "gains",
        "setpoint_n",
        "outcome",
        "drop_time_s",
        "drop_phase",
        "rise_time_90_s",
        "overshoot_pct",
        "max_fluctuation_pct",
        "force_rmse_n",
        "peak_force_n",
        "sim_time_s",
        "wall_time_s",
        "seed",
        "backend",
    ] {
        assert!(summary.get(key).is_some(), "summary.json lacks {key}");
    }
    assert_eq!(summary["seed"], 7);
    assert_eq!(summary["feedback"], false);
    assert_eq!(summary["gains"]["kp"], 20.0);
    assert_eq!(summary["mass_kg"], 0.351);
    let trace = std::fs::read_to_string(dir.path().join("trace.csv")).unwrap();
    let header = trace.lines().next().unwrap();
    for col in ["time_s", "phase", "true_force_n", "fbg1_nm", "fbg2_nm", "force_n", "setpoint_n", "twine_motor_rad"] {
        assert!(header.split(',').any(|c| c == col), "trace.csv lacks {col}");
    }
    // One row per 10 ms tick over the whole task.
    let rows = trace.lines().count() - 1;
    let sim = summary["sim_time_s"].as_f64().unwrap();
    assert!((rows as f64 - (sim / 0.01 + 1.0)).abs() <= 1.0, "{rows} rows for {sim} s");
}

#[test]
fn bad_keys_and_values_name_the_file_and_key_and_exit_non_zero() {
    for (set, key) in [
        ("controler.kp=1", "controler"),
        ("controller.kp=-1", "controller.kp"),
        ("object.name=anvil", "object.name"),
        ("physics.timestep_s=0", "physics.timestep_s"),
        ("setpoint_n=9", "setpoint_n"),
        ("hardware.dxl_baud=56000", "hardware.dxl_baud"),
        ("hardware.growth_id=2", "hardware.twine_id"),
        ("hardware.fbg.fbg1_max_nm=1545", "hardware.fbg.fbg1_max_nm"),
    ] {
        let out = tendril(&["run", "scenarios/crimper.toml", "--set", set]);
        let err = stderr(&out);
        assert!(!out.status.success(), "--set {set} was accepted");
        assert!(err.contains("scenarios/crimper.toml") && err.contains(&format!("`{key}`")), "{set}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
    let out = tendril(&["run", "scenarios/no-such.toml"]);
    assert!(!out.status.success() && stderr(&out).contains("no-such.toml"));
}

#[test]
fn a_diverging_run_reports_time_and_cause_and_keeps_its_trace() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_short(dir.path(), &["--set", "physics.integrator=\"euler\"", "--set", "physics.timestep_s=0.04"]);
    assert!(!out.status.success());
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["outcome"], "error");
    let error = summary["error"].as_str().unwrap();
    assert!(error.contains("physics failed at t ="), "{error}");
    let trace = std::fs::read_to_string(dir.path().join("trace.csv")).unwrap();
    assert!(trace.lines().count() > 1, "the ticks before the failure are kept");
    // The estimate column never carries NaN forward.
    assert!(trace.lines().skip(1).all(|l| l.split(',').nth(5) != Some("NaN")), "{trace}");
}

fn write_sweep(dir: &Path) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios");
    let sweep = dir.join("sweep.toml");
    std::fs::write(
        &sweep,
        format!(
            "scenarios = ['{}']\n[grid]\n'controller.kp' = [10.0, 20.0]\nseed = [1, 2]\n\
             'task.grasp_s' = [3.0]\n'task.lift_s' = [1.0]\n'task.transfer_s' = [1.0]\n'task.lower_s' = [1.0]\n",
            root.join("crimper.toml").display()
        ),
    )
    .unwrap();
    sweep
}

fn ids(results: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(results).unwrap();
    let mut ids: Vec<String> = text.lines().skip(1).map(|l| l.split(',').next().unwrap().to_string()).collect();
    ids.sort();
    ids
}

#[test]
fn sweep_resume_and_shards_merge_to_the_same_runs() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = write_sweep(dir.path());
    let sweep = sweep.to_str().unwrap();
    let full = dir.path().join("full");
    let out = tendril(&["sweep", sweep, "--out", full.to_str().unwrap(), "--threads", "2"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(ids(&full.join("results.csv")), ["0", "1", "2", "3"]);

    // A second run refuses to overwrite; --resume finds nothing left to do.
    assert!(!tendril(&["sweep", sweep, "--out", full.to_str().unwrap()]).status.success());
    let out = tendril(&["sweep", sweep, "--out", full.to_str().unwrap(), "--resume"]);
    assert!(String::from_utf8_lossy(&out.stdout).contains("0 run now"), "{}", String::from_utf8_lossy(&out.stdout));

    let sharded = dir.path().join("sharded");
    for k in ["1/2", "2/2"] {
        let out = tendril(&["sweep", sweep, "--out", sharded.to_str().unwrap(), "--shard", k, "--threads", "1"]);
        assert!(out.status.success(), "{}", stderr(&out));
    }
    let merged = dir.path().join("merged.csv");
    let out = tendril(&[
        "merge",
        "--out",
        merged.to_str().unwrap(),
        sharded.join("results-1-of-2.csv").to_str().unwrap(),
        sharded.join("results-2-of-2.csv").to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(ids(&merged), ids(&full.join("results.csv")));
}

#[test]
fn a_sweep_with_bag_keeps_each_runs_directory_and_its_bag() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = write_sweep(dir.path());
    let out_dir = dir.path().join("out");
    let out = tendril(&["sweep", sweep.to_str().unwrap(), "--out", out_dir.to_str().unwrap(), "--bag"]);
    assert!(out.status.success(), "{}", stderr(&out));
    for id in 0..4 {
        let run = out_dir.join("runs").join(id.to_string());
        let trace = std::fs::read_to_string(run.join("trace.csv")).unwrap();
        let ticks = tendril_ros2::bag::read_bag(&run.join("bag"), Some(&["/tendril/control_tick"])).unwrap();
        assert_eq!(ticks.len(), trace.lines().count() - 1, "run {id}: one control tick a trace row");
    }
}

#[test]
fn a_sweep_with_an_unknown_key_fails_before_running_anything() {
    let dir = tempfile::tempdir().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/crimper.toml");
    let sweep = dir.path().join("bad.toml");
    std::fs::write(&sweep, format!("scenarios = ['{}']\n[grid]\n'controller.kq' = [1.0]\n", root.display())).unwrap();
    let out_dir = dir.path().join("out");
    let out = tendril(&["sweep", sweep.to_str().unwrap(), "--out", out_dir.to_str().unwrap()]);
    assert!(!out.status.success());
    assert!(stderr(&out).contains("controller.kq") || stderr(&out).contains("kq"), "{}", stderr(&out));
    assert!(!out_dir.join("results.csv").exists(), "nothing ran");
}
