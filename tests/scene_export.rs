//! `tendril scene`: the assembled scene as one MJCF that MuJoCo's own tools open, with the start
//! state as keyframe `start`. MuJoCo's Python package (installed by `cargo xtask test` into
//! `vendor/venv`, `TENDRIL_PYTHON`) compiles it and steps it from the keyframe: the object stands
//! still. Under a plain `cargo test` the Python half says loudly that it is skipped.

use std::process::Command;

use crate::common::cli::{stderr, tendril};

fn export(dir: &std::path::Path, scenario: &str, extra: &[&str]) -> std::path::PathBuf {
    let out = dir.join(format!("{}.xml", scenario.replace(['/', '.'], "_")));
    let mut args = vec!["scene", scenario, "--out", out.to_str().unwrap()];
    args.extend(extra);
    let o = tendril(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    out
}

#[test]
fn every_shipped_object_exports_a_complete_scene_with_its_start_keyframe() {
    let dir = tempfile::tempdir().unwrap();
    for object in ["crimper", "hammer", "shampoo"] {
        let path = export(dir.path(), &format!("scenarios/{object}.toml"), &[]);
        let xml = std::fs::read_to_string(&path).unwrap();
        assert!(!xml.contains("${"), "{object}: a template field is left unfilled");
        assert!(xml.contains("<key name=\"start\""), "{object}: no start keyframe");
        // The object stands on the table where the run starts it, not at the origin.
        assert!(!xml.contains("<body name=\"object\" pos=\"0 0 0\""), "{object}: object left at the origin");
        // MuJoCo (through the library) compiles it on its own.
        let model = mujoco_rs::prelude::MjModel::from_xml(&path).unwrap_or_else(|e| panic!("{object}: {e:?}"));
        assert_eq!(model.ffi().nkey, 1);
    }
}

#[test]
fn a_produce_item_exports_its_flex_where_the_run_starts_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = export(dir.path(), "scenarios/cherry-tomato.toml", &["--set", "produce.poisson=0.4"]);
    let xml = std::fs::read_to_string(&path).unwrap();
    assert!(xml.contains("<body name=\"produce_frame\" pos=") && xml.contains("<flexcomp name=\"produce\""));
    // The scenario's override is in the flex's elasticity, and MuJoCo compiles the whole.
    assert!(xml.contains("poisson=\"0.4\""), "the override is not in the flex");
    let model = mujoco_rs::prelude::MjModel::from_xml(&path).unwrap();
    assert_eq!((model.ffi().nflex, model.ffi().nkey), (1, 1));
}

#[test]
fn a_friction_override_is_written_into_the_exported_grip() {
    let dir = tempfile::tempdir().unwrap();
    let path = export(dir.path(), "scenarios/crimper.toml", &["--set", "object.friction=1.3"]);
    let xml = std::fs::read_to_string(path).unwrap();
    let grip = &xml[xml.find("<geom name=\"object_grip\"").unwrap()..];
    let tag = &grip[..grip.find('>').unwrap()];
    assert!(tag.contains("friction=\"1.3 "), "{tag}");
}

#[test]
fn the_solver_key_chooses_mujocos_solver_and_an_unknown_one_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let option = |path: std::path::PathBuf| {
        let xml = std::fs::read_to_string(path).unwrap();
        let at = xml.find("<option ").unwrap();
        xml[at..at + xml[at..].find('>').unwrap()].to_string()
    };
    assert!(option(export(dir.path(), "scenarios/crimper.toml", &[])).contains("solver=\"Newton\""));
    let cg = export(dir.path(), "scenarios/shampoo.toml", &["--set", "physics.solver=\"cg\""]);
    assert!(option(cg.clone()).contains("solver=\"CG\""));
    assert_eq!(mujoco_rs::prelude::MjModel::from_xml(&cg).unwrap().ffi().opt.solver, 1, "mjSOL_CG");
    let o = tendril(&["scene", "scenarios/crimper.toml", "--set", "physics.solver=\"lu\""]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("physics.solver"), "{}", stderr(&o));
}

#[test]
fn a_bad_scenario_is_an_error_naming_the_key_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("scene.xml");
    let o = tendril(&["scene", "scenarios/crimper.toml", "--set", "finger.segments=1", "--out", out.to_str().unwrap()]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("finger.segments"), "{}", stderr(&o));
    assert!(!out.exists());
}

#[test]
fn mujoco_python_opens_the_scene_and_the_object_stays_put() {
    let Some(python) = std::env::var("TENDRIL_PYTHON").ok().filter(|p| !p.is_empty()) else {
        eprintln!("SKIPPED: TENDRIL_PYTHON is not set; run `cargo xtask test` to install mujoco for Python");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let script = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/clients/scene_at_rest.py");
    for object in ["crimper", "hammer", "shampoo"] {
        let path = export(dir.path(), &format!("scenarios/{object}.toml"), &[]);
        let out = Command::new(&python).arg(&script).arg(&path).output().expect("python runs");
        assert!(out.status.success(), "{object}: {}", String::from_utf8_lossy(&out.stderr));
        let r: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(r["nkey"], 1, "{r}");
        assert_eq!(r["keyframe_matches"], true, "{r}");
        assert_eq!(r["finite"], true, "{r}");
        // Soft contacts settle by micrometres; a scene that put the object below the table threw it
        // metres in this second.
        let moved = r["object_moved_m"].as_f64().unwrap();
        assert!(moved < 1e-3, "{object}: the object moved {moved} m in the first second: {r}");
    }
}

/// The finger, pad, arm and table are read at run time from `physics.models_dir`: an edit to a copy
/// of models/ shows in the scene without a rebuild, and a folder without the parts is an error
/// naming the file.
#[test]
fn the_scene_parts_are_read_from_the_models_folder_at_run_time() {
    let dir = tempfile::tempdir().unwrap();
    let models = dir.path().join("models");
    std::fs::create_dir_all(&models).unwrap();
    let shipped = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("models");
    for part in ["finger.xml", "finger_segment.xml", "sensor_pad.xml", "ur5e.xml", "table.xml"] {
        std::fs::copy(shipped.join(part), models.join(part)).unwrap();
    }
    let finger = std::fs::read_to_string(models.join("finger.xml")).unwrap();
    let edited = finger.replace("size=\"0.005 0.035 0.012\"", "size=\"0.005 0.030 0.012\"");
    assert_ne!(finger, edited, "the palm's size is where the test expects it");
    std::fs::write(models.join("finger.xml"), edited).unwrap();
    let set = format!("physics.models_dir=\"{}\"", models.display());
    let path = export(dir.path(), "scenarios/crimper.toml", &["--set", &set]);
    assert!(std::fs::read_to_string(path).unwrap().contains("size=\"0.005 0.030 0.012\""));
    std::fs::remove_file(models.join("table.xml")).unwrap();
    let o = tendril(&[
        "scene",
        "scenarios/crimper.toml",
        "--set",
        &set,
        "--out",
        dir.path().join("x.xml").to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("table.xml"), "{}", stderr(&o));
}
