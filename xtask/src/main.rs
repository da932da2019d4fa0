//! `cargo xtask <task>`: the project's set-up, with nothing to install by hand.
//!
//! MuJoCo must exist before `mujoco-rs` builds, so these tasks live in a separate package that
//! does not depend on it: `cargo xtask` fetches the library from PyPI first, then runs cargo.
//!
//! - `cargo xtask fetch`: unpack MuJoCo 3.17.0 from the PyPI wheel into `vendor/mujoco/lib`.
//! - `cargo xtask main`: fetch, install `tendril` (`cargo install --path . --locked`, reusing the
//!   workspace's release build), then run the main job (`tendril reproduce ...`).
//! - `cargo xtask test`: fetch, install the Python protocol clients into `vendor/venv`, build the
//!   workspace's tests (every feature), then the Python package into that venv; then
//!   run the whole test suite with `TENDRIL_PYTHON` pointing at that venv, and the Python
//!   package's tests (`python/tests`, pytest).
//! - `cargo xtask layers`: check the workspace's rules (the crates' layers, the light crates'
//!   dependencies, no module loops; [`layers`]).
//! - `cargo xtask book`: build the book in `docs/` into `target/book` with mdBook, installed
//!   first (the pinned version, from crates.io) into `vendor/mdbook`.
//! - `cargo xtask publish-check`: `cargo publish --dry-run` of the crates made to be used on their
//!   own ([`layers::published`]): each is packaged and built from its package alone.
//! - `cargo xtask urcl PATH-TO-LIBRARY`: Universal Robots' client library's examples against
//!   `tendril serve` ([`urcl`]).

mod layers;
mod modules;
mod rtde_trace;
mod urcl;

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

const MUJOCO_VERSION: &str = "3.17.0";

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (task, rest) = match args.split_first() {
        Some((t, r)) => (t.as_str(), r),
        None => ("help", &[][..]),
    };
    let result = match task {
        "fetch" => fetch_mujoco().map(|_| ()),
        "main" => fetch_mujoco().and_then(|_| run_main(rest)),
        "test" => fetch_mujoco().and_then(|_| run_tests(rest)),
        "layers" => check_layers(),
        "book" => build_book(rest),
        "publish-check" => publish_check(rest),
        "urcl" => fetch_mujoco().and_then(|_| urcl_check(rest)),
        _ => {
            eprintln!("usage: cargo xtask <fetch|main|test|layers|book|publish-check|urcl> [extra cargo args]");
            return ExitCode::from(2);
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("xtask {task}: {e}");
            ExitCode::FAILURE
        }
    }
}

fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("xtask lives in the workspace").to_path_buf()
}

/// Returns the folder that holds `libmujoco.so`, fetching the wheel if needed.
/// A `MUJOCO_DYNAMIC_LINK_DIR` already in the environment (set by the user, not by our
/// `.cargo/config.toml`, which cargo only applies to the processes it starts) is used as is.
fn fetch_mujoco() -> Result<PathBuf, String> {
    let root = workspace_root();
    let lib_dir = root.join("vendor/mujoco/lib");
    if let Ok(dir) = std::env::var("MUJOCO_DYNAMIC_LINK_DIR") {
        let dir = PathBuf::from(dir);
        if dir != lib_dir {
            return if dir.join("libmujoco.so").is_file() {
                Ok(dir)
            } else {
                Err(format!("MUJOCO_DYNAMIC_LINK_DIR={} holds no libmujoco.so", dir.display()))
            };
        }
    }
    let stamp = lib_dir.join(format!("libmujoco.so.{MUJOCO_VERSION}"));
    if stamp.is_file() && lib_dir.join("libmujoco.so").exists() {
        return Ok(lib_dir);
    }
    let wheel_dir = root.join("vendor/wheels");
    eprintln!("xtask: fetching mujoco=={MUJOCO_VERSION} from PyPI (the wheel carries libmujoco.so)");
    run(Command::new(python())
        .args(["-m", "pip", "download", "--quiet", "--no-deps", "--only-binary=:all:"])
        .arg(format!("mujoco=={MUJOCO_VERSION}"))
        .arg("--dest")
        .arg(&wheel_dir))?;
    let wheel = std::fs::read_dir(&wheel_dir)
        .map_err(|e| format!("{}: {e}", wheel_dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .find(|p| {
            let name = p.file_name().unwrap_or_default().to_string_lossy();
            name.starts_with(&format!("mujoco-{MUJOCO_VERSION}-")) && name.ends_with(".whl")
        })
        .ok_or("pip downloaded no mujoco wheel")?;
    // A wheel is a zip; Python's zipfile unpacks it without any extra tool on the machine.
    const UNPACK: &str = "import sys, zipfile, os\n\
         z = zipfile.ZipFile(sys.argv[1]); out = sys.argv[2]; os.makedirs(out, exist_ok=True)\n\
         for n in z.namelist():\n\
         \x20   if not n.endswith('/') and (n.startswith('mujoco/libmujoco.so') or n.startswith('mujoco/plugin/')):\n\
         \x20       dest = os.path.join(out, n[len('mujoco/'):])\n\
         \x20       os.makedirs(os.path.dirname(dest), exist_ok=True)\n\
         \x20       open(dest, 'wb').write(z.read(n))\n";
    run(Command::new(python()).arg("-c").arg(UNPACK).arg(&wheel).arg(&lib_dir))?;
    if !stamp.is_file() {
        return Err(format!("the wheel {} holds no libmujoco.so.{MUJOCO_VERSION}", wheel.display()));
    }
    let link = lib_dir.join("libmujoco.so");
    let _ = std::fs::remove_file(&link);
    std::os::unix::fs::symlink(format!("libmujoco.so.{MUJOCO_VERSION}"), &link)
        .map_err(|e| format!("{}: {e}", link.display()))?;
    eprintln!("xtask: MuJoCo {MUJOCO_VERSION} is in {}", lib_dir.display());
    Ok(lib_dir)
}

fn python() -> String {
    std::env::var("PYTHON").unwrap_or_else(|_| "python3".into())
}

fn cargo() -> Command {
    let mut c = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
    c.current_dir(workspace_root());
    c
}

/// mdBook's version: the book's `book.toml` and pages are written for it.
const MDBOOK_VERSION: &str = "0.5.4";

/// Builds `docs/` with mdBook, installing it into `vendor/mdbook` first when it is not there
/// (without its `serve` and `watch` features: a build needs neither, and they would pull in tokio
/// and a file watcher). Installed unoptimised (`--debug`): on a 2-core machine it builds in 41 s
/// instead of 88 s, and then writes the same book in 2.1 s instead of 0.4 s. The book's links are
/// checked by `tests/docs_links.rs`.
fn build_book(extra: &[String]) -> Result<(), String> {
    let root = workspace_root();
    let prefix = root.join("vendor/mdbook");
    let mdbook = prefix.join("bin/mdbook");
    let installed = Command::new(&mdbook).arg("--version").output().ok().map(|o| o.stdout);
    if installed.as_deref() != Some(format!("mdbook v{MDBOOK_VERSION}\n").as_bytes()) {
        run(cargo()
            .args(["install", "mdbook", "--locked", "--debug", "--no-default-features", "--features", "search"])
            .args(["--version", MDBOOK_VERSION, "--root"])
            .arg(&prefix))?;
    }
    run(Command::new(&mdbook).args(["build", "docs"]).args(extra).current_dir(&root))
}

/// The main job: install `tendril`, then reproduce the paper's results with the twin.
fn run_main(extra: &[String]) -> Result<(), String> {
    install_tendril()?;
    let mut reproduce = cargo();
    reproduce.args(["run", "--release", "--quiet", "--bin", "tendril", "--", "reproduce", "all"]).args(extra);
    run(&mut reproduce)
}

/// `cargo install --path . --locked`: builds `tendril` in the workspace's target folder (the
/// release build `cargo run --release` uses, so the main job builds once) and copies it to the
/// folder cargo installs binaries into, so the README's `tendril ...` commands run as typed.
/// Says where it went, and how to put that folder on the PATH when it is not there.
fn install_tendril() -> Result<(), String> {
    run(cargo().args(["install", "--path", ".", "--locked", "--quiet"]))?;
    let bin = install_bin_dir();
    let on_path = std::env::var_os("PATH").is_some_and(|p| std::env::split_paths(&p).any(|d| d == bin));
    eprintln!("xtask: installed tendril as {}", bin.join("tendril").display());
    if !on_path {
        eprintln!("xtask: {} is not on your PATH; add it with", bin.display());
        eprintln!("    export PATH=\"{}:$PATH\"", bin.display());
    }
    Ok(())
}

/// Where `cargo install` puts binaries: `$CARGO_INSTALL_ROOT/bin`, else `$CARGO_HOME/bin`, else
/// `~/.cargo/bin` (cargo's own order; an `install.root` in a cargo config is not read here).
fn install_bin_dir() -> PathBuf {
    let var = |name| std::env::var_os(name).filter(|v| !v.is_empty()).map(PathBuf::from);
    let root = var("CARGO_INSTALL_ROOT")
        .or_else(|| var("CARGO_HOME"))
        .or_else(|| var("HOME").map(|h| h.join(".cargo")))
        .unwrap_or_else(|| PathBuf::from(".cargo"));
    root.join("bin")
}

/// The whole test suite (what `.ci/run` runs): the workspace's tests, then the Python package's.
///
/// The Python extension builds after the Rust tests, in the same profile and target folder: the
/// crates they share (all but those whose features the tests' `--all-features` changes) compile
/// once (docs/guide/install.md, "Where CI's time goes"). Nothing runs until both are built, so
/// the real-time tests meet an idle machine.
fn run_tests(extra: &[String]) -> Result<(), String> {
    let python = python_clients()?;
    python_test_tools(&python)?;
    // The Python extension (a cdylib built by maturin, below) has no Rust tests of its own. Every
    // feature: the optional parts `cargo xtask main` leaves out (the viewer, the video) are tested too.
    let workspace = ["test", "--workspace", "--exclude", "tendril-python", "--all-features"];
    let rust_tests = || {
        let mut c = cargo();
        c.args(workspace).arg("--all-targets").args(extra).env("TENDRIL_PYTHON", &python);
        c
    };
    timed("the Rust tests: build", || run(rust_tests().arg("--no-run")))?;
    timed("the Python extension: build and install", || python_extension(&python))?;
    timed("the Rust tests: run", || run(&mut rust_tests()))?;
    // The crates' READMEs are their docs, and their samples are doctests (`--all-targets` runs none).
    timed("the doctests", || run(cargo().args(workspace).arg("--doc").args(extra).env("TENDRIL_PYTHON", &python)))?;
    timed("the Python package's tests (pytest)", || python_package_tests(&python))
}

/// Runs `step`, then says how long it took, so a CI log shows where its time goes.
fn timed(what: &str, step: impl FnOnce() -> Result<(), String>) -> Result<(), String> {
    let started = std::time::Instant::now();
    let result = step();
    eprintln!("xtask: {what}: {:.0} s", started.elapsed().as_secs_f64());
    result
}

/// What the Python package's tests need beside the package's own dependencies (numpy and
/// mujoco, already in the venv): pytest, Gymnasium for the environment, pandas for
/// `Run.to_pandas`, and maturin, the build backend. Pinned, like the clients.
const PYTHON_TEST_TOOLS: [&str; 4] = ["pytest==9.2.0", "gymnasium==1.4.0", "pandas==3.1.1", "maturin==1.16.0"];

/// Installs [`PYTHON_TEST_TOOLS`] into `vendor/venv` once.
fn python_test_tools(python: &Path) -> Result<(), String> {
    let venv = workspace_root().join("vendor/venv");
    let stamp = venv.join(format!("tendril-python-tests-{}", PYTHON_TEST_TOOLS.join("-")));
    if !stamp.is_file() {
        eprintln!("xtask: installing {} into {}", PYTHON_TEST_TOOLS.join(", "), venv.display());
        run(Command::new(python)
            .args(["-m", "pip", "install", "--quiet", "--only-binary=:all:"])
            .args(PYTHON_TEST_TOOLS))?;
        std::fs::write(&stamp, "").map_err(|e| format!("{}: {e}", stamp.display()))?;
    }
    Ok(())
}

/// The workspace's target folder (`CARGO_TARGET_DIR` when set).
fn target_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| workspace_root().join("target"), PathBuf::from)
}

/// Builds the Python package (pyproject.toml, python/tendril) and installs it into `vendor/venv`:
/// `pip install .` (the in-tree backend, without build isolation: the venv has maturin and mujoco)
/// in the development profile and the workspace's target folder, so maturin reuses the crates the
/// Rust tests' build just compiled (Cargo.toml, `[profile.dev]`).
fn python_extension(python: &Path) -> Result<(), String> {
    run(Command::new(python)
        .args(["-m", "pip", "install", "--quiet", "--no-build-isolation", "--no-deps", "--force-reinstall", "."])
        .env("MATURIN_PEP517_ARGS", "--profile dev")
        .env("CARGO_TARGET_DIR", target_dir())
        .current_dir(workspace_root()))
}

/// `pytest python/tests` against the package [`python_extension`] installed. pytest's exit code 5 (no
/// test collected) fails the task like any other non-zero exit.
fn python_package_tests(python: &Path) -> Result<(), String> {
    run(Command::new(python)
        .args(["-m", "pytest", "-q", "python/tests"])
        // The command line the tests compare runs with: the one `cargo test` just built.
        .env("TENDRIL_BIN", target_dir().join("debug/tendril"))
        .current_dir(workspace_root()))
}

/// Independent protocol clients the tests run against the virtual devices (tests/python_clients.rs),
/// pinned: SDU `ur_rtde` (a cp311 manylinux wheel, so the venv needs Python 3.11) and ROBOTIS
/// `dynamixel-sdk` with its one dependency; MuJoCo's own Python package, which opens the scene
/// `tendril scene` exports (tests/scene_export.rs); and the ROS 2 peers of python/tests/test_ros2.py,
/// none of which needs a ROS installation: Eclipse Cyclone DDS (the DDS behind `rmw_cyclonedds`,
/// its C library in the wheel) as the lab's node, `rosbags` reading bags (sqlite3 and MCAP), and
/// Foxglove's `mcap` reader. Installed once into `vendor/venv`; returns its python.
const PYTHON_CLIENTS: [&str; 7] = [
    "ur_rtde==1.6.5",
    "dynamixel-sdk==4.1.0",
    "pyserial==3.5",
    "mujoco==3.17.0",
    "cyclonedds==11.0.1",
    "rosbags==0.11.9",
    "mcap==1.6.0",
];

fn python_clients() -> Result<PathBuf, String> {
    let venv = workspace_root().join("vendor/venv");
    let python = venv.join("bin/python");
    let stamp = venv.join(format!("tendril-clients-{}", PYTHON_CLIENTS.join("-")));
    if stamp.is_file() && python.is_file() {
        return Ok(python);
    }
    eprintln!("xtask: installing {} into {}", PYTHON_CLIENTS.join(", "), venv.display());
    run(Command::new(self::python()).args(["-m", "venv"]).arg(&venv))?;
    run(Command::new(&python).args(["-m", "pip", "install", "--quiet", "--only-binary=:all:"]).args(PYTHON_CLIENTS))?;
    std::fs::write(&stamp, "").map_err(|e| format!("{}: {e}", stamp.display()))?;
    Ok(python)
}

/// `cargo xtask urcl`: builds `tendril` (release) and runs UR's client library's examples against it.
fn urcl_check(rest: &[String]) -> Result<(), String> {
    run(cargo().args(["build", "--release", "--quiet", "--bin", "tendril"]))?;
    urcl::run(&workspace_root(), &target_dir().join("release/tendril"), rest)
}

/// `cargo xtask layers`: every broken rule printed; fails if there is one.
fn check_layers() -> Result<(), String> {
    let errors = layers::check(&workspace_root(), &cargo)?;
    if errors.is_empty() {
        let crates: usize = layers::LAYERS.iter().map(|l| l.len()).sum();
        println!("layers: {crates} crates in {} layers, every rule holds", layers::LAYERS.len());
        return Ok(());
    }
    for e in &errors {
        eprintln!("{e}");
    }
    Err(format!("{} rule(s) broken", errors.len()))
}

/// `cargo publish --dry-run` of the published crates, verifying each from its package alone.
///
/// A multi-package dry run hands the packages to each other through a local overlay registry,
/// which cargo unpacks into `$CARGO_HOME/registry/src/-<hash of its path>/<crate>-<version>` and
/// then reuses as long as that folder exists, whatever the package now holds. Our versions stay at
/// 0.1.0 while the code changes, so a second run from the same checkout path (a CI machine that
/// keeps `~/.cargo`) would verify against the old sources. Only those overlay folders (their
/// registry has no host, so the name starts with `-`) of our own crates are removed first.
fn publish_check(rest: &[String]) -> Result<(), String> {
    let cargo_home = std::env::var_os("CARGO_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cargo")))
        .ok_or("neither CARGO_HOME nor HOME is set")?;
    let src = cargo_home.join("registry/src");
    for registry in std::fs::read_dir(&src).into_iter().flatten().flatten() {
        if !registry.file_name().to_string_lossy().starts_with('-') {
            continue;
        }
        for unpacked in std::fs::read_dir(registry.path()).into_iter().flatten().flatten() {
            let name = unpacked.file_name().to_string_lossy().into_owned();
            let ours = layers::published().any(|p| {
                name.strip_prefix(p)
                    .and_then(|v| v.strip_prefix('-'))
                    .is_some_and(|v| v.starts_with(|c: char| c.is_ascii_digit()))
            });
            if ours {
                std::fs::remove_dir_all(unpacked.path()).map_err(|e| format!("{}: {e}", unpacked.path().display()))?;
            }
        }
    }
    run(cargo().args(["publish", "--dry-run"]).args(layers::published().flat_map(|p| ["--package", p])).args(rest))
}

fn run(cmd: &mut Command) -> Result<(), String> {
    let status = cmd.status().map_err(|e| format!("cannot start {cmd:?}: {e}"))?;
    if status.success() { Ok(()) } else { Err(format!("{cmd:?} failed ({status})")) }
}
