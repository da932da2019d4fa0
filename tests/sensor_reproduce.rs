//! `tendril reproduce sensor --json`: every row passes and the JSON has the documented shape.

use std::process::Command;

#[test]
fn reproduce_sensor_passes_and_writes_json() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("rows.json");
    let out = Command::new(env!("CARGO_BIN_EXE_tendril"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(["reproduce", "sensor", "--json"])
        .arg(&json)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "exit {:?}\n{stdout}\n{}", out.status, String::from_utf8_lossy(&out.stderr));
    assert!(stdout.contains("| quantity"), "{stdout}");
    let rows: Vec<serde_json::Value> = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert!(rows.len() >= 15, "{} rows", rows.len());
    for row in &rows {
        let obj = row.as_object().unwrap();
        let mut keys: Vec<&str> = obj.keys().map(String::as_str).collect();
        keys.sort();
        assert_eq!(keys, ["paper", "pass", "quantity", "tolerance", "twin"]);
        assert_eq!(obj["pass"], serde_json::Value::Bool(true), "{row}");
    }
    for needle in ["sensitivity", "K_T1", "K_T2", "max hysteresis", "compensated RMSE", "load-cell comparison"] {
        assert!(rows.iter().any(|r| r["quantity"].as_str().unwrap().contains(needle)), "no row for {needle}");
    }
}

#[test]
fn unknown_family_is_an_error() {
    let out = Command::new(env!("CARGO_BIN_EXE_tendril"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(["reproduce", "nothing"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("unknown"));
}
