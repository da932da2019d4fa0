//! `tendril chart placement` as a user calls it, on the CI-sized plan (`--quick`: the paper's pad
//! and the three-pad array, the crimper, no disturbance and the knock, feedback on, seed 1): the
//! files it writes, that its summary is its own runs, the recommendation it prints, and that
//! `tendril plot` redraws its chart.

use std::collections::HashMap;
use std::path::Path;

use crate::common::cli::{stderr, tendril};

fn read(path: &Path) -> Vec<HashMap<String, String>> {
    crate::common::table::read_rows(path)
}

#[test]
fn the_quick_study_compares_layouts_and_recommends_one() {
    let dir = tempfile::tempdir().unwrap();
    let out = tendril(&[
        "chart",
        "placement",
        "--quick",
        "--scenario",
        "scenarios/crimper.toml",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    for f in ["placement.csv", "placement_summary.csv", "placement.png", "placement.svg"] {
        assert!(dir.path().join(f).is_file(), "{f} missing; {}", stderr(&out));
    }
    let runs = read(&dir.path().join("placement.csv"));
    assert_eq!(runs.len(), 2 * 2, "layouts × disturbance sets");
    let summary = read(&dir.path().join("placement_summary.csv"));
    assert_eq!(summary.len(), 4);
    for s in &summary {
        let group: Vec<_> =
            runs.iter().filter(|r| r["layout"] == s["layout"] && r["disturbance"] == s["disturbance"]).collect();
        let held = group.iter().filter(|r| r["outcome"] == "held").count();
        assert_eq!(s["held"], held.to_string(), "{s:?}");
        assert_eq!(s["runs"], group.len().to_string(), "{s:?}");
    }
    // The array's layout costs two gratings more than the paper's pad and reads its pads.
    let array = summary.iter().find(|s| s["layout"].starts_with("3:")).unwrap();
    assert_eq!(array["gratings"], "4");
    let paper = summary.iter().find(|s| s["layout"].starts_with("1:")).unwrap();
    assert_eq!(paper["gratings"], "2");
    // Undisturbed, both hold the crimper; knocked, neither does (the controllers study's finding).
    for s in &summary {
        assert_eq!(s["held"], if s["disturbance"] == "none" { "1" } else { "0" }, "{s:?}");
    }
    let printed = String::from_utf8_lossy(&out.stdout);
    assert!(printed.starts_with("recommended: 1: paper"), "{printed}");

    let redrawn = tempfile::tempdir().unwrap();
    let plot = tendril(&[
        "plot",
        dir.path().join("placement_summary.csv").to_str().unwrap(),
        "--out",
        redrawn.path().to_str().unwrap(),
    ]);
    assert!(plot.status.success(), "{}", stderr(&plot));
    assert!(redrawn.path().join("placement.png").is_file());
}
