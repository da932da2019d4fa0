//! Gain maps that run only the points they need (`--stride` on `tendril chart gain-map`,
//! `--refine` on `tendril sweep`): on a small grid where the crimper's loop holds steadily and
//! oscillates, every point the adaptive map reports equals the full grid's, with fewer runs.

use crate::common::cli::{stderr, tendril};
use crate::common::table::read_rows;
use std::collections::BTreeMap;
use std::path::Path;

/// Kp × Ki around the crimper's oscillating corner (a strong integral on a weak proportional
/// term; docs/studies/stability.md): both classes on one 5 × 5 grid.
const KP: &str = "2,5,10,50,200";
const KI: &str = "0,0.5,5,28.1,50";

/// (kp, ki) -> (outcome, oscillating, ran) of a gain map or a sweep's map.
type Classes = BTreeMap<(String, String), (String, String, String)>;

fn classes(csv: &Path, kp: &str, ki: &str) -> Classes {
    read_rows(csv)
        .into_iter()
        .map(|r| ((r[kp].clone(), r[ki].clone()), (r["outcome"].clone(), r["oscillating"].clone(), r["ran"].clone())))
        .collect()
}

fn gain_map(out: &Path, stride: &str) -> Classes {
    let args = ["chart", "gain-map", "--scenario", "scenarios/crimper.toml", "--kp", KP, "--ki", KI];
    let o = tendril(&[&args[..], &["--stride", stride, "--threads", "2", "--out", out.to_str().unwrap()]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    classes(&out.join("gain_map.csv"), "kp", "ki")
}

fn same_classes(a: &Classes, b: &Classes) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|((ka, va), (kb, vb))| ka == kb && va.0 == vb.0 && va.1 == vb.1)
}

#[test]
fn the_adaptive_map_equals_the_full_grid_at_every_point_with_fewer_runs() {
    let dir = tempfile::tempdir().unwrap();
    let full = gain_map(&dir.path().join("full"), "1");
    assert_eq!(full.len(), 25);
    assert!(full.values().all(|c| c.2 == "true"), "stride 1 runs every point");
    let kinds: std::collections::BTreeSet<_> = full.values().map(|c| (c.0.clone(), c.1.clone())).collect();
    assert!(kinds.len() >= 2, "the grid must hold a boundary for the test to mean anything: {kinds:?}");

    let adaptive = gain_map(&dir.path().join("adaptive"), "2");
    assert!(same_classes(&full, &adaptive), "full {full:?}\nadaptive {adaptive:?}");
    let ran = adaptive.values().filter(|c| c.2 == "true").count();
    assert!(ran < 25, "the adaptive map ran {ran} of 25 points");

    // The same map as a sweep refined over the two gains: map.csv has every point, results.csv
    // only the runs made.
    let sweep = dir.path().join("sweep.toml");
    let scenario = std::fs::canonicalize("scenarios/crimper.toml").unwrap();
    std::fs::write(
        &sweep,
        format!(
            "scenarios = [{:?}]\n[grid]\n\"controller.kp\" = [{KP}]\n\"controller.ki\" = [{KI}]\nfeedback = [true]\n",
            scenario.display().to_string()
        ),
    )
    .unwrap();
    let out = dir.path().join("sweep");
    let args = ["sweep", sweep.to_str().unwrap(), "--refine", "controller.kp,controller.ki", "--stride", "2"];
    let o = tendril(&[&args[..], &["--threads", "2", "--out", out.to_str().unwrap()]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    // Both write the gains as written here (2, 0.5, 28.1), so the keys compare as text.
    let swept = classes(&out.join("map.csv"), "controller.kp", "controller.ki");
    assert!(same_classes(&full, &swept), "full {full:?}\nswept {swept:?}");
    let rows = read_rows(&out.join("results.csv")).len();
    assert_eq!(rows, swept.values().filter(|c| c.2 == "true").count(), "results.csv holds the runs made");
    assert!(String::from_utf8_lossy(&o.stdout).contains(&format!("refined: {rows} of 25 points run")));

    // --refine needs the whole sweep: with --shard it is refused before anything runs.
    let o = tendril(&[&args[..], &["--shard", "1/2", "--out", out.to_str().unwrap()]].concat());
    assert!(!o.status.success());
    assert!(stderr(&o).contains("leave out --shard and --resume"), "{}", stderr(&o));
}
