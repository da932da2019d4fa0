//! Objects from files alone: a user's object model and scenario in a folder of their own, no Rust
//! touched, run with and without feedback; shipped-style lookup by name beside the scenarios'
//! folder; and broken object files refused before anything runs, naming the file and what is wrong.

use std::path::Path;

use crate::common::cli::{stderr, tendril};

/// A 250 g dowel on a round foot: the grip a 12.5 mm capsule of beech in a TPU wrap (μ 1.1).
const DOWEL: &str = r#"<mujoco model="dowel">
  <worldbody>
    <body name="object" pos="0 0 0">
      <freejoint name="object"/>
      <site name="object_wrap" pos="0 0 0.1"/>
      <geom name="object_base" type="cylinder" size="0.04 0.01" pos="0 0 0.01" mass="0.15"
            contype="0" conaffinity="4" priority="1" friction="0.8 0.005 0.0001"/>
      <geom name="object_grip" type="capsule" fromto="0 0 0.04 0 0 0.2" size="0.0125" mass="0.1"
            contype="0" conaffinity="10" priority="1" friction="1.1 0.005 0.0001"/>
    </body>
  </worldbody>
</mujoco>
"#;

const SCENARIO: &str = "name = \"dowel\"\nsetpoint_n = 0.8\n[object]\nfile = \"objects/dowel.xml\"\n";

/// A lab folder: `scenario.toml` and `objects/dowel.xml` (with `object` replaced as given).
fn lab(object: &str) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("objects")).unwrap();
    std::fs::write(dir.path().join("objects/dowel.xml"), object).unwrap();
    std::fs::write(dir.path().join("scenario.toml"), SCENARIO).unwrap();
    dir
}

fn run(scenario: &Path, out: &Path, extra: &[&str]) -> (std::process::Output, serde_json::Value) {
    let mut args = vec!["run", scenario.to_str().unwrap(), "--out", out.to_str().unwrap()];
    args.extend(extra);
    let o = tendril(&args);
    let summary = std::fs::read_to_string(out.join("summary.json"))
        .map_or(serde_json::Value::Null, |t| serde_json::from_str(&t).unwrap());
    (o, summary)
}

#[test]
fn a_new_object_runs_from_files_alone() {
    let dir = lab(DOWEL);
    let scenario = dir.path().join("scenario.toml");
    let (o, held) = run(&scenario, &dir.path().join("on"), &["--feedback", "on"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(held["outcome"], "held", "with feedback at 0.8 N the dowel is carried: {held}");
    assert_eq!(held["object"], "dowel");
    assert!((held["mass_kg"].as_f64().unwrap() - 0.25).abs() < 1e-9, "mass from the file: {held}");
    // Near-zero grip friction never carries it, with feedback or without.
    for fb in ["on", "off"] {
        let (o, s) = run(
            &scenario,
            &dir.path().join(format!("slick-{fb}")),
            &["--feedback", fb, "--set", "object.friction=0.02"],
        );
        assert!(o.status.success(), "{}", stderr(&o));
        assert_eq!(s["outcome"], "dropped", "μ 0.02, feedback {fb}: {s}");
    }
    // The mass key: a ten times heavier dowel is not carried by the same grip.
    let (_, heavy) = run(&scenario, &dir.path().join("heavy"), &["--set", "object.mass_kg=2.5"]);
    assert_eq!(heavy["mass_kg"], 2.5);
    assert_eq!(heavy["outcome"], "dropped", "{heavy}");
}

#[test]
fn a_name_finds_models_objects_beside_the_scenarios_folder_and_edits_need_no_rebuild() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("models/objects")).unwrap();
    std::fs::create_dir_all(dir.path().join("scenarios")).unwrap();
    std::fs::write(dir.path().join("models/objects/dowel.xml"), DOWEL).unwrap();
    let scenario = dir.path().join("scenarios/dowel.toml");
    std::fs::write(&scenario, SCENARIO.replace("file = \"objects/dowel.xml\"", "name = \"dowel\"")).unwrap();
    let (o, s) = run(&scenario, &dir.path().join("a"), &["--set", "task.grasp_s=3"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!((s["mass_kg"].as_f64().unwrap() - 0.25).abs() < 1e-9);
    // Edit the model file: the next run reads it.
    std::fs::write(dir.path().join("models/objects/dowel.xml"), DOWEL.replace("mass=\"0.1\"", "mass=\"0.2\"")).unwrap();
    let (_, s) = run(&scenario, &dir.path().join("b"), &["--set", "task.grasp_s=3"]);
    assert!((s["mass_kg"].as_f64().unwrap() - 0.35).abs() < 1e-9, "{s}");
}

#[test]
fn broken_object_files_are_refused_naming_the_file_and_what_is_wrong() {
    let cases = [
        (DOWEL.replace("name=\"object\"", "name=\"dowel\""), "body named `object`"),
        (DOWEL.replace("<freejoint name=\"object\"/>", ""), "free joint"),
        (DOWEL.replace("name=\"object_grip\"", "name=\"shaft\""), "object_grip"),
        (DOWEL.replace("<site name=\"object_wrap\" pos=\"0 0 0.1\"/>", ""), "object_wrap"),
        (DOWEL.replace("type=\"capsule\"", "type=\"mesh\" mesh=\"nope\""), "cannot compile"),
    ];
    for (text, what) in cases {
        let dir = lab(&text);
        let out = dir.path().join("out");
        let (o, _) = run(&dir.path().join("scenario.toml"), &out, &[]);
        let err = stderr(&o);
        assert!(!o.status.success(), "{what}: accepted");
        assert!(err.contains("dowel.xml") && err.contains(what), "{what}: {err}");
        assert!(!out.join("trace.csv").exists(), "{what}: something ran");
    }
}

#[test]
fn a_missing_file_or_an_object_without_name_or_file_is_an_error_naming_the_key() {
    let dir = lab(DOWEL);
    let scenario = dir.path().join("scenario.toml");
    for (set, key) in [("object.file=\"objects/none.xml\"", "object.file"), ("object.name=\"teapot\"", "object.name")] {
        let text = SCENARIO.replace("file = \"objects/dowel.xml\"", &set.replace("object.", ""));
        std::fs::write(&scenario, text).unwrap();
        let (o, _) = run(&scenario, &dir.path().join("x"), &[]);
        assert!(!o.status.success());
        assert!(stderr(&o).contains(key), "{key}: {}", stderr(&o));
    }
    std::fs::write(&scenario, SCENARIO.replace("file = \"objects/dowel.xml\"\n", "friction = 1.0\n")).unwrap();
    let (o, _) = run(&scenario, &dir.path().join("y"), &[]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("object.name") && stderr(&o).contains("`file`"), "{}", stderr(&o));
}

#[test]
fn the_shipped_mesh_object_runs_and_a_mesh_that_does_not_load_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let bottle = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/bottle.toml");
    let (o, held) = run(&bottle, &dir.path().join("on"), &["--feedback", "on"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(held["outcome"], "held", "{held}");
    assert!((held["mass_kg"].as_f64().unwrap() - 0.23).abs() < 1e-9, "{held}");
    let (_, slick) = run(&bottle, &dir.path().join("slick"), &["--set", "object.friction=0.02"]);
    assert_eq!(slick["outcome"], "dropped", "{slick}");
    // rapier takes no meshes: refused by name before anything runs.
    let (o, _) = run(&bottle, &dir.path().join("rapier"), &["--backend", "rapier"]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("mesh geom `object_base`"), "{}", stderr(&o));
    // A user's mesh object whose mesh file is missing.
    let text =
        DOWEL.replace("<worldbody>", "<asset><mesh name=\"foot\" file=\"meshes/foot.obj\"/></asset>\n  <worldbody>");
    let lab = lab(&text.replace("type=\"cylinder\" size=\"0.04 0.01\"", "type=\"mesh\" mesh=\"foot\""));
    let (o, _) = run(&lab.path().join("scenario.toml"), &lab.path().join("out"), &[]);
    assert!(!o.status.success());
    let err = stderr(&o);
    assert!(err.contains("dowel.xml") && err.contains("foot.obj"), "{err}");
}

/// A shipped object read from models/ at run time and the copy built into the binary are the same
/// model: a scenario with no models/ beside it (the built-in copies) gives the same trace, byte for
/// byte, as the repository's (the files, found at run time).
#[test]
fn the_files_and_the_built_in_copies_give_the_same_trace() {
    let dir = tempfile::tempdir().unwrap();
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/hammer.toml");
    let alone = dir.path().join("hammer.toml");
    std::fs::copy(&repo, &alone).unwrap();
    let short = ["--feedback", "off", "--set", "task.grasp_s=4"];
    let (o, files) = run(&repo, &dir.path().join("files"), &short);
    assert!(o.status.success(), "{}", stderr(&o));
    let (o, built_in) = run(&alone, &dir.path().join("built-in"), &short);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(files["effective_scenario"]["object"]["file"].is_string(), "read from models/: {files}");
    assert!(built_in["effective_scenario"]["object"].get("file").is_none(), "built in: {built_in}");
    let trace = |d: &str| std::fs::read(dir.path().join(d).join("trace.csv")).unwrap();
    assert!(trace("files").len() > 10_000 && trace("files") == trace("built-in"));
}
