//! Bad bench scenarios and bench CSVs: a message naming the file, the key (or line) and the reason,
//! a non-zero exit, no panic.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const GOOD: &str = "
seed = 1
[force_cycles]
cycles = 1
peak_force_n = 4.0
load_time_s = 1.0
unload_time_s = 1.0
rest_s = 0.6
temperature_c = 25.0
";

fn tendril(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tendril")).args(args).output().unwrap()
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// Runs `tendril bench` on `text` and checks the failure names the file, `key` and `reason`.
fn rejects(text: &str, key: &str, reason: &str) {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "bad-scenario.toml", text);
    let out = tendril(&["bench", file.to_str().unwrap(), "--out", dir.path().join("x.csv").to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "accepted:\n{text}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(err.contains("bad-scenario.toml"), "no file name: {err}");
    assert!(err.contains(&format!("`{key}`")), "no key {key}: {err}");
    assert!(err.contains(reason), "no reason `{reason}`: {err}");
}

#[test]
fn good_scenario_runs() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "good.toml", GOOD);
    let csv = dir.path().join("out.csv");
    let out = tendril(&["bench", file.to_str().unwrap(), "--out", csv.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let out = tendril(&["calibrate", csv.to_str().unwrap()]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success() && stdout.contains("sensitivity"), "{stdout}");
}

#[test]
fn unknown_key() {
    rejects(&format!("{GOOD}\n[sensor]\nrange = 4.0\n"), "sensor.range", "unknown field");
}

#[test]
fn missing_field() {
    rejects(&GOOD.replace("cycles = 1\n", ""), "force_cycles", "missing field `cycles`");
}

#[test]
fn negative_noise() {
    rejects(&format!("{GOOD}\n[interrogator]\nnoise_pm = -3.0\n"), "interrogator.noise_pm", "must be >= 0");
}

#[test]
fn range_not_positive() {
    rejects(&format!("{GOOD}\n[sensor]\nrange_n = 0.0\n"), "sensor.range_n", "must be > 0");
}

#[test]
fn ratio_not_positive() {
    rejects(&format!("{GOOD}\n[estimator]\nr = -2.356\n"), "estimator.r", "must be > 0");
}

#[test]
fn force_profile_past_the_range() {
    rejects(
        &GOOD.replace("peak_force_n = 4.0", "peak_force_n = 6.0"),
        "force_cycles.peak_force_n",
        "past the sensor range",
    );
}

#[test]
fn bad_override_value_is_checked_like_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "bad-scenario.toml", GOOD);
    let out = tendril(&["bench", file.to_str().unwrap(), "--set", "load_cell.noise_n=-1"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("`load_cell.noise_n`"), "{err}");
}

#[test]
fn malformed_csv_names_the_line() {
    let dir = tempfile::tempdir().unwrap();
    let text = "time_s,load_cell_n,fbg1_nm,fbg2_nm,temperature_c\n0,0,1540,1550,\n0.01,0.1,15x0,1550,\n";
    let file = write(dir.path(), "bench.csv", text);
    let out = tendril(&["calibrate", file.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(err.contains("bench.csv: line 3") && err.contains("fbg1_nm"), "{err}");
}
