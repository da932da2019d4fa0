//! Paths a scenario names (`object.file`, `physics.models_dir`) are relative to the scenario file, so a scenario and the files beside
//! it move together. Resolved on the parsed table, before deserialising, so every reader of
//! scenarios (runs, sweeps, studies, `serve`) sees the same absolute paths, and the effective
//! scenario a run records points at the files it used.

use std::path::Path;

/// Resolves `[object]`'s paths against `scenario` (the file the table came from):
/// - `object.file`, when relative, is taken from the scenario's folder;
/// - `object.name` without a `file` is looked up as `models/objects/<name>.xml` beside the
///   scenario's folder (the repository's layout: `scenarios/` next to `models/`; first in
///   `physics.models_dir` when given), then in the
///   scenario's own folder's `models/`; found, it becomes `object.file`, so the model is read at run
///   time and edits take effect without a rebuild. Not found, the name stays a built-in object
///   (or an error naming it, from validation).
pub fn resolve_object(table: &mut toml::Table, scenario: &Path) {
    // Run after `resolve_models`: a models folder given (or found) is searched first.
    let models_objects = table
        .get("physics")
        .and_then(|p| p.get("models_dir"))
        .and_then(|d| d.as_str())
        .map(|d| Path::new(d).join("objects"));
    let Some(toml::Value::Table(object)) = table.get_mut("object") else { return };
    let dir = scenario.parent().unwrap_or(Path::new(""));
    if let Some(toml::Value::String(file)) = object.get("file") {
        let path = Path::new(file);
        if path.is_relative() {
            let joined = dir.join(path);
            object.insert("file".into(), toml::Value::String(joined.display().to_string()));
        }
        return;
    }
    let Some(toml::Value::String(name)) = object.get("name") else { return };
    // A name with a path separator or a dot is no shipped object's: never look outside models/.
    if name.is_empty() || name.contains(['/', '\\', '.']) {
        return;
    }
    let candidates = models_objects.into_iter().chain([dir.join("../models/objects"), dir.join("models/objects")]);
    if let Some(found) = candidates.map(|d| d.join(format!("{name}.xml"))).find(|p| p.is_file()) {
        let found = std::fs::canonicalize(&found).unwrap_or(found);
        object.insert("file".into(), toml::Value::String(found.display().to_string()));
    }
}

/// Resolves `detector.table`, when relative, against `scenario`'s folder.
pub fn resolve_detector_table(table: &mut toml::Table, scenario: &Path) {
    let Some(toml::Value::Table(detector)) = table.get_mut("detector") else { return };
    if let Some(toml::Value::String(file)) = detector.get("table")
        && Path::new(file).is_relative()
    {
        let joined = scenario.parent().unwrap_or(Path::new("")).join(file);
        let joined = std::fs::canonicalize(&joined).unwrap_or(joined);
        detector.insert("table".into(), toml::Value::String(joined.display().to_string()));
    }
}

/// Resolves `physics.models_dir` against `scenario`: a relative folder is taken from the scenario's
/// folder; none given, `models/` beside the scenario's folder is used when it holds finger.xml.
/// Only scenarios of a scene (those with an `[object]` or `[physics]` table) get one; the bench
/// scenarios have no scene.
pub fn resolve_models(table: &mut toml::Table, scenario: &Path) {
    if !(table.contains_key("object") || table.contains_key("physics")) {
        return;
    }
    let dir = scenario.parent().unwrap_or(Path::new(""));
    let physics = table.entry("physics").or_insert_with(|| toml::Value::Table(toml::Table::new()));
    let Some(physics) = physics.as_table_mut() else { return };
    match physics.get("models_dir") {
        Some(toml::Value::String(given)) if Path::new(given).is_relative() => {
            let joined = dir.join(given);
            physics.insert("models_dir".into(), toml::Value::String(joined.display().to_string()));
        }
        Some(_) => {}
        None => {
            let beside = dir.join("../models");
            if beside.join("finger.xml").is_file() {
                let beside = std::fs::canonicalize(&beside).unwrap_or(beside);
                physics.insert("models_dir".into(), toml::Value::String(beside.display().to_string()));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(text: &str) -> toml::Table {
        text.parse().unwrap()
    }

    #[test]
    fn a_relative_file_is_taken_from_the_scenario_folder() {
        let mut t = table("[object]\nfile = \"objects/mug.xml\"\n");
        resolve_object(&mut t, Path::new("/lab/scenarios/mug.toml"));
        assert_eq!(t["object"]["file"].as_str(), Some("/lab/scenarios/objects/mug.xml"));
        let mut t = table("[object]\nfile = \"/abs/mug.xml\"\n");
        resolve_object(&mut t, Path::new("/lab/scenarios/mug.toml"));
        assert_eq!(t["object"]["file"].as_str(), Some("/abs/mug.xml"));
    }

    #[test]
    fn a_name_finds_its_model_beside_the_scenarios_folder() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir_all(dir.path().join("models/objects")).unwrap();
        std::fs::create_dir_all(dir.path().join("scenarios")).unwrap();
        std::fs::write(dir.path().join("models/objects/dowel.xml"), "<mujoco/>").unwrap();
        let scenario = dir.path().join("scenarios/dowel.toml");
        let mut t = table("[object]\nname = \"dowel\"\n");
        resolve_object(&mut t, &scenario);
        let file = t["object"]["file"].as_str().unwrap();
        assert!(Path::new(file).is_file(), "{file}");
        let mut t = table("[object]\nname = \"teapot\"\n");
        resolve_object(&mut t, &scenario);
        assert!(t["object"].get("file").is_none(), "no file for an object that is not there");
        let mut t = table("[object]\nname = \"../scenarios/x\"\n");
        resolve_object(&mut t, &scenario);
        assert!(t["object"].get("file").is_none());
    }
}
