//! `cargo xtask layers`: the workspace's rules, checked (docs/architecture.md gives them with
//! their reasons):
//!
//! 1. every crate sits in a layer of [`LAYERS`], and depends (normal, build or dev) only on crates
//!    of layers below its own;
//! 2. the crates of [`LIGHT`] pull in none of [`HEAVY`] (`cargo tree -p NAME -e normal`): they
//!    build and test without MuJoCo, rapier, tokio, OpenH264 or a GUI;
//! 3. no crate's modules import each other in a loop ([`crate::modules`]).
//!
//! Each broken rule is reported with what breaks it (the edge, the package, the files and the
//! names that tie a loop); the task fails if any is.

use crate::modules;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The layers, bottom first. A crate may depend only on crates of layers below its own.
pub const LAYERS: &[&[&str]] = &[
    // Leaves: configuration, the arm's geometry, the protocols' shared framing.
    &["tendril-codec", "tendril-config", "tendril-ur5e"],
    // The sensor model and the sans-IO protocols.
    &["tendril-fbg", "tendril-rtde", "tendril-dynamixel", "tendril-ros2msg"],
    &["tendril-hyperion", "tendril-urscript"],
    // The seam.
    &["tendril-cell"],
    // Above the seam: the control side, the twin, the real devices' drivers.
    &["tendril-control", "tendril-twin", "tendril-drivers", "tendril-ros2"],
    // One run on any cell; pictures of the twin's scene.
    &["tendril-run", "tendril-render"],
    // The virtual devices, the charts.
    &["tendril-serve", "tendril-plot"],
    // The two front ends: the command line (and what only it does), the Python package.
    &["tendril", "tendril-python"],
];

/// Crates that must build without any of [`HEAVY`].
pub const LIGHT: &[&str] = &[
    "tendril-codec",
    "tendril-config",
    "tendril-ur5e",
    "tendril-fbg",
    "tendril-rtde",
    "tendril-dynamixel",
    "tendril-ros2msg",
    "tendril-hyperion",
    "tendril-urscript",
    "tendril-cell",
    "tendril-control",
];

/// How many layers, from the bottom, hold the crates made to be used on their own
/// (configuration, kinematics, the sensor model, the protocols, URScript).
const PUBLISHED_LAYERS: usize = 3;

/// The crates made to be used on their own: `cargo xtask publish-check` packages and builds each
/// as crates.io would (`cargo publish --dry-run`).
pub fn published() -> impl Iterator<Item = &'static str> {
    LAYERS[..PUBLISHED_LAYERS].iter().flat_map(|layer| layer.iter().copied())
}

/// What the light crates must not pull in: the physics engines, the async runtime, the video
/// encoder, the windowing.
pub const HEAVY: &[&str] = &["mujoco-rs", "rapier3d-f64", "tokio", "openh264", "winit"];

/// The layer of `krate`, if it has one.
pub fn layer_of(krate: &str) -> Option<usize> {
    LAYERS.iter().position(|l| l.contains(&krate))
}

/// Rule 1 on a graph of (package, its dependencies on workspace packages): the broken edges.
pub fn crate_graph_errors(packages: &[(String, Vec<String>)]) -> Vec<String> {
    let mut errors = Vec::new();
    for (name, deps) in packages {
        let Some(mine) = layer_of(name) else {
            errors.push(format!("{name}: in no layer (xtask/src/layers.rs, LAYERS)"));
            continue;
        };
        for dep in deps {
            match layer_of(dep) {
                Some(theirs) if theirs < mine => {}
                Some(theirs) => {
                    errors.push(format!("{name} -> {dep}: {dep} is in layer {theirs}, not below {name}'s layer {mine}"))
                }
                None => errors.push(format!("{name} -> {dep}: {dep} is in no layer")),
            }
        }
    }
    errors
}

/// Rule 2 on the package names `cargo tree` printed for `krate`: the heavy ones.
pub fn heavy_errors(krate: &str, tree: &[String]) -> Vec<String> {
    tree.iter()
        .filter(|p| HEAVY.contains(&p.as_str()))
        .map(|p| format!("{krate} pulls in {p} (cargo tree -p {krate} -e normal)"))
        .collect()
}

/// Rule 3 for one crate's `src` folder: each loop, with the imports that tie it.
pub fn module_loop_errors(krate: &str, files: &[(PathBuf, String)]) -> Vec<String> {
    let g = modules::graph(files);
    modules::loops(&g)
        .into_iter()
        .map(|edges| {
            let ties: Vec<String> = edges
                .iter()
                .map(|e| {
                    let names: Vec<&str> =
                        e.names.iter().map(|n| if n.is_empty() { "(the module)" } else { n }).collect();
                    format!("  {} -> {}: {}", e.from.display(), e.to.display(), names.join(", "))
                })
                .collect();
            format!("{krate}: modules import each other in a loop:\n{}", ties.join("\n"))
        })
        .collect()
}

/// Runs the three checks on the workspace at `root`; the errors, empty when every rule holds.
pub fn check(root: &Path, cargo: &dyn Fn() -> Command) -> Result<Vec<String>, String> {
    let packages = workspace_packages(root, cargo)?;
    let mut errors =
        crate_graph_errors(&packages.iter().map(|p| (p.name.clone(), p.workspace_deps.clone())).collect::<Vec<_>>());
    for krate in LIGHT {
        let out = cargo()
            .current_dir(root)
            .args(["tree", "--quiet", "-p", krate, "-e", "normal", "--prefix", "none", "--format", "{p}"])
            .output()
            .map_err(|e| format!("cargo tree: {e}"))?;
        if !out.status.success() {
            return Err(format!("cargo tree -p {krate}: {}", String::from_utf8_lossy(&out.stderr)));
        }
        let names: Vec<String> = String::from_utf8_lossy(&out.stdout)
            .lines()
            .filter_map(|l| l.split_whitespace().next().map(str::to_string))
            .collect();
        errors.extend(heavy_errors(krate, &names));
    }
    for p in &packages {
        let files = modules::read_tree(&p.dir.join("src")).map_err(|e| format!("{}: {e}", p.dir.display()))?;
        errors.extend(module_loop_errors(&p.name, &files));
    }
    Ok(errors)
}

/// A workspace package: name, folder, and its dependencies on other workspace packages.
struct Package {
    name: String,
    dir: PathBuf,
    workspace_deps: Vec<String>,
}

/// The workspace's packages but xtask, from `cargo metadata`.
fn workspace_packages(root: &Path, cargo: &dyn Fn() -> Command) -> Result<Vec<Package>, String> {
    let out = cargo()
        .current_dir(root)
        .args(["metadata", "--format-version", "1", "--no-deps", "--offline"])
        .output()
        .map_err(|e| format!("cargo metadata: {e}"))?;
    if !out.status.success() {
        return Err(format!("cargo metadata: {}", String::from_utf8_lossy(&out.stderr)));
    }
    let meta: serde_json::Value = serde_json::from_slice(&out.stdout).map_err(|e| format!("cargo metadata: {e}"))?;
    let packages = meta["packages"].as_array().ok_or("cargo metadata: no packages")?;
    let names: Vec<&str> = packages.iter().filter_map(|p| p["name"].as_str()).collect();
    Ok(packages
        .iter()
        .filter(|p| p["name"] != "xtask")
        .map(|p| {
            let manifest = PathBuf::from(p["manifest_path"].as_str().unwrap_or_default());
            let mut workspace_deps: Vec<String> = p["dependencies"]
                .as_array()
                .into_iter()
                .flatten()
                .filter_map(|d| d["name"].as_str())
                .filter(|d| names.contains(d))
                .map(str::to_string)
                .collect();
            workspace_deps.sort();
            workspace_deps.dedup();
            Package {
                name: p["name"].as_str().unwrap_or_default().to_string(),
                dir: manifest.parent().map(Path::to_path_buf).unwrap_or_default(),
                workspace_deps,
            }
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_edge_up_or_sideways_is_named() {
        let g = |deps: &[(&str, &[&str])]| {
            deps.iter().map(|(p, d)| (p.to_string(), d.iter().map(|s| s.to_string()).collect())).collect::<Vec<_>>()
        };
        assert!(crate_graph_errors(&g(&[("tendril-run", &["tendril-twin", "tendril-cell"])])).is_empty());
        // A deliberate bad import: the sensor model reaching up into the twin.
        let errors = crate_graph_errors(&g(&[("tendril-fbg", &["tendril-twin"])]));
        assert_eq!(
            errors,
            ["tendril-fbg -> tendril-twin: tendril-twin is in layer 4, not below tendril-fbg's layer 1"]
        );
        // Sideways, within a layer: the twin on the control side.
        assert!(crate_graph_errors(&g(&[("tendril-twin", &["tendril-control"])]))[0].contains("not below"));
        assert!(crate_graph_errors(&g(&[("tendril-new", &[])]))[0].contains("in no layer"));
    }

    #[test]
    fn a_heavy_dependency_of_a_light_crate_is_named() {
        let tree = ["tendril-rtde", "tendril-codec", "tokio", "thiserror"].map(String::from);
        assert_eq!(
            heavy_errors("tendril-rtde", &tree),
            ["tendril-rtde pulls in tokio (cargo tree -p tendril-rtde -e normal)"]
        );
    }

    #[test]
    fn a_module_loop_is_reported_with_its_files_and_names() {
        let files = vec![
            (PathBuf::from("lib.rs"), "pub mod state;\npub mod fields;\n".to_string()),
            (PathBuf::from("state.rs"), "use super::fields::REGISTER_COUNT;\npub struct RobotOutputs;\n".to_string()),
            (
                PathBuf::from("fields.rs"),
                "use crate::state::RobotOutputs;\npub const REGISTER_COUNT: usize = 48;\n".to_string(),
            ),
        ];
        let errors = module_loop_errors("tendril-rtde", &files);
        assert_eq!(
            errors,
            [
                "tendril-rtde: modules import each other in a loop:\n  fields.rs -> state.rs: RobotOutputs\n  state.rs -> fields.rs: REGISTER_COUNT"
            ]
        );
    }
}
