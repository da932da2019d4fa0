//! The Section V runs (crimper, shampoo and hammer, feedback on and off, seed 1) write the same
//! `trace.csv` bytes and the same `summary.json`, but for its timing fields, as the default they
//! were last written with. `tests/fixtures/section_v_half_link.json` holds, per run, the sha256 of
//! that default's trace and its summary without the timing fields, the checkout's own folder
//! (which the summary's resolved paths name) written as `<checkout>`.
//!
//! Its history: main 67179d3 wrote it before the workspace move, which changed no answer; the
//! switch to the half-link default (`finger.base_joint = "half_link"`, 28 links, 7.5 ms contacts,
//! a 19 s creep; models/README.md, "Calibration to the paper's pick-and-place") rewrote it.
//!
//! A change that means to move the twin's answers (a new contact model, a new default) fails here;
//! its commit rewrites the fixture from the new binary's runs and says why in its message.

use std::path::Path;
use std::process::Command;

use sha2::{Digest, Sha256};

/// Fields that measure the machine, not the twin: they differ from run to run.
const TIMING_FIELDS: [&str; 4] = ["wall_time_s", "real_time_factor", "cpu_time_s", "sim_s_per_cpu_s"];

fn fixture() -> serde_json::Value {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/section_v_half_link.json");
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Runs `object` with `feedback` and seed 1 as a user does, returning its trace and summary.
fn run(object: &str, feedback: &str, out: &Path) -> (Vec<u8>, serde_json::Value) {
    let result = Command::new(env!("CARGO_BIN_EXE_tendril"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(["run", &format!("scenarios/{object}.toml"), "--seed", "1", "--feedback", feedback, "--out"])
        .arg(out)
        .output()
        .unwrap();
    assert!(result.status.success(), "{object} {feedback}: {}", String::from_utf8_lossy(&result.stderr));
    let trace = std::fs::read(out.join("trace.csv")).unwrap();
    // The object file and the models folder are resolved to absolute paths in this checkout.
    let text = std::fs::read_to_string(out.join("summary.json")).unwrap();
    let text = text.replace(concat!(env!("CARGO_MANIFEST_DIR"), "/"), "<checkout>/");
    let summary = serde_json::from_str(&text).unwrap();
    (trace, summary)
}

/// The names of the fields where `new` differs from `old`, as dotted paths.
fn differing_fields(old: &serde_json::Value, new: &serde_json::Value, path: &str, out: &mut Vec<String>) {
    match (old, new) {
        (serde_json::Value::Object(a), serde_json::Value::Object(b)) => {
            for key in a.keys().chain(b.keys().filter(|k| !a.contains_key(*k))) {
                let null = serde_json::Value::Null;
                let here = if path.is_empty() { key.clone() } else { format!("{path}.{key}") };
                differing_fields(a.get(key).unwrap_or(&null), b.get(key).unwrap_or(&null), &here, out);
            }
        }
        _ if old != new => out.push(format!("{path}: {old} then, {new} now")),
        _ => {}
    }
}

#[test]
fn section_v_runs_are_unchanged_since_the_half_link_default() {
    let expected = fixture();
    let dir = tempfile::tempdir().unwrap();
    let mut failures = Vec::new();
    for object in ["crimper", "shampoo", "hammer"] {
        for feedback in ["on", "off"] {
            let name = format!("{object}-{feedback}");
            let (trace, mut summary) = run(object, feedback, &dir.path().join(&name));
            let trace_sha256 = format!("{:x}", Sha256::digest(&trace));
            if trace_sha256 != expected[&name]["trace_sha256"] {
                failures.push(format!(
                    "{name}: trace.csv sha256 {trace_sha256}, {} in the fixture",
                    expected[&name]["trace_sha256"]
                ));
            }
            for field in TIMING_FIELDS {
                let removed = summary.as_object_mut().unwrap().remove(field);
                assert!(removed.is_some(), "{name}: summary.json has no {field}");
            }
            let mut fields = Vec::new();
            differing_fields(&expected[&name]["summary"], &summary, "", &mut fields);
            failures.extend(fields.into_iter().map(|f| format!("{name}: summary.json {f}")));
        }
    }
    assert!(failures.is_empty(), "the Section V runs moved:\n{}", failures.join("\n"));
}
