//! The README's five-minute tour, run as typed: every command line of its code blocks, through
//! `sh`, with `tendril` found on the PATH as the README says (`cargo xtask main` installs it into
//! a folder on the PATH; here a folder holding the binary this build made comes first on the
//! PATH), from a folder laid out like a fresh clone (its `scenarios/` and `models/`).
//!
//! A line is run as a reader types it, its optional parts in brackets left out, unless it is a
//! template (`A|B` choices, HOST and the like) or needs what a test machine lacks; each of those is named below with its reason and the
//! test that covers it instead, so a new tour line is either run or explained.

use std::path::Path;
use std::process::Command;

const README: &str = include_str!("../README.md");

/// The tour's lines this test does not run, by their start, and why.
const NOT_RUN: [(&str, &str); 7] = [
    (
        "cargo install --path . --locked --features",
        "a release build; its text is checked against the missing-feature error",
    ),
    ("tendril view", "needs a display (tests/view.rs, under Xvfb when installed)"),
    ("tendril serve", "runs until stopped (tests/real_time.rs)"),
    ("tendril run scenarios/crimper.toml --hardware real", "needs the lab's UR5e, servos and interrogator"),
    ("tendril run scenarios/crimper.toml --hardware ros2", "needs the lab's ROS 2 drivers (python/tests/test_ros2.py)"),
    ("cargo xtask urcl", "needs a checkout of UR's client library (docs/cell/urcl.md)"),
    ("tendril chart placement", "960 runs; its quick form runs in tests/chart_placement.rs"),
];

/// The tour's command lines: from its heading to the next, each code block's lines without their
/// comments.
fn tour_lines() -> Vec<String> {
    let start = README.find("## A five-minute tour").expect("the README has its tour");
    let rest = &README[start + 3..];
    let tour = &rest[..rest.find("\n## ").unwrap_or(rest.len())];
    let mut lines = Vec::new();
    let mut in_block = false;
    for line in tour.lines() {
        if line.starts_with("```") {
            in_block = !in_block;
            continue;
        }
        if in_block {
            let command = line.split(" #").next().unwrap_or("").trim();
            if !command.is_empty() && !command.starts_with('#') {
                lines.push(command.to_string());
            }
        }
    }
    lines
}

/// The command a reader types for `line`: its optional parts in brackets left out; `None` for a
/// template to fill in (`A|B` choices, HOST, PATH-TO-... and the like).
fn as_typed(line: &str) -> Option<String> {
    let placeholder = |w: &str| w.len() > 1 && w.chars().all(|c| c.is_ascii_uppercase() || c == '-');
    let mut typed = String::new();
    let mut depth = 0;
    for c in line.chars() {
        match c {
            '[' => depth += 1,
            ']' => depth -= 1,
            _ if depth == 0 => typed.push(c),
            _ => {}
        }
    }
    let typed = typed.split_whitespace().collect::<Vec<_>>().join(" ");
    (!typed.contains('|') && !typed.split_whitespace().any(placeholder)).then_some(typed)
}

#[test]
fn the_tour_runs_as_typed() {
    let lines = tour_lines();
    assert!(lines.len() >= 15, "the tour's command lines: {lines:#?}");
    let dir = tempfile::tempdir().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for folder in ["scenarios", "models"] {
        std::os::unix::fs::symlink(root.join(folder), dir.path().join(folder)).unwrap();
    }
    let bin = dir.path().join("bin");
    std::fs::create_dir(&bin).unwrap();
    std::os::unix::fs::symlink(env!("CARGO_BIN_EXE_tendril"), bin.join("tendril")).unwrap();
    let path = std::env::join_paths(
        std::iter::once(bin).chain(std::env::split_paths(&std::env::var_os("PATH").unwrap_or_default())),
    )
    .unwrap();

    let mut ran = Vec::new();
    for line in &lines {
        let Some(line) = as_typed(line) else { continue };
        if NOT_RUN.iter().any(|(start, _)| line.starts_with(start)) {
            continue;
        }
        let out = Command::new("sh").arg("-c").arg(&line).current_dir(dir.path()).env("PATH", &path).output().unwrap();
        assert!(out.status.success(), "`{line}` failed ({}):\n{}", out.status, String::from_utf8_lossy(&out.stderr));
        ran.push(line);
    }
    // Running a pick-and-place, plotting and rendering it, the sweep and its heatmaps at least.
    for must in
        ["tendril run scenarios/hammer.toml --out out/hammer", "tendril render out/hammer", "tendril plot out/gains"]
    {
        assert!(ran.iter().any(|r| r == must), "`{must}` was not run; ran: {ran:#?}");
    }
    assert!(dir.path().join("out/hammer/video.mp4").is_file());
    // Every line this test leaves out is still in the tour (a stale entry would hide nothing).
    for (start, why) in NOT_RUN {
        assert!(lines.iter().any(|l| l.starts_with(start)), "no tour line starts with `{start}` ({why})");
    }
}

#[test]
fn a_reader_types_the_tours_lines_without_their_optional_parts() {
    assert_eq!(
        as_typed("tendril view scenarios/hammer.toml [--speed 2]").as_deref(),
        Some("tendril view scenarios/hammer.toml")
    );
    assert_eq!(as_typed("tendril reproduce sensor|gripper|all [--json FILE]"), None);
    assert_eq!(as_typed("tendril run x.toml --hardware real --ur HOST"), None);
    assert_eq!(
        as_typed("tendril run x.toml --set controller.kp=40").as_deref(),
        Some("tendril run x.toml --set controller.kp=40")
    );
}

#[test]
fn the_tours_install_line_is_the_one_a_missing_part_prints() {
    let install = tour_lines()
        .into_iter()
        .find(|l| l.starts_with("cargo install"))
        .expect("the tour installs the optional parts");
    for feature in [tendril::features::Feature::Video, tendril::features::Feature::Viewer] {
        let said = feature.missing("tendril x").to_string();
        let command = said.split("with: ").nth(1).expect("the error ends with the command");
        let base = command.trim_end_matches(feature.name());
        assert!(install.starts_with(base), "README: `{install}`; the error: `{command}`");
        let features = install[base.len()..].split(',').collect::<Vec<_>>();
        assert!(features.contains(&feature.name()), "README: `{install}` leaves out {}", feature.name());
    }
}
