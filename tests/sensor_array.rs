//! A sensor array along the finger (`[array]`, issue 40): the single pad is today's run to the
//! byte, bad layouts are refused on their key with the reason, and an array's pads are read,
//! estimated and written to the trace.

use std::path::{Path, PathBuf};
use std::process::Command;
use tendril_config::{Override, ScenarioError};
use tendril_run::scenario::PickPlaceScenario;

fn scenario(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios").join(name)
}

fn run(args: &[&str], out: &Path) -> (String, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_tendril"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .arg("run")
        .args(args)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    (std::fs::read_to_string(out.join("trace.csv")).unwrap(), String::from_utf8_lossy(&o.stdout).into())
}

/// FNV-1a, 64 bits: a fingerprint of a file's bytes without a dependency.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3))
}

/// The hammer's trace, seed 1: without an array the run is the single pad's, byte for byte. First
/// recorded as main wrote it before the array existed (1823ba7); recorded again for the switch to
/// the half-link default (the same trace as tests/fixtures/section_v_half_link.json's hammer-on).
/// A change that moves the default run on purpose records the new fingerprint here and says why.
const HAMMER_TRACE_FNV1A: u64 = 0xdae1_8a6d_3070_b6b5;

#[test]
fn the_single_pad_run_is_todays_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    let (trace, _) = run(&["scenarios/hammer.toml"], dir.path());
    assert!(trace.starts_with("time_s,phase,true_force_n,fbg1_nm,fbg2_nm,force_n,"), "{}", &trace[..80]);
    assert!(!trace.lines().next().unwrap().contains("pad1"), "no array columns without an array");
    assert_eq!(fnv1a(trace.as_bytes()), HAMMER_TRACE_FNV1A, "the hammer's trace moved ({} bytes)", trace.len());
    let recorded = std::fs::read_to_string(dir.path().join("scenario.toml")).unwrap();
    assert!(!recorded.contains("[array]"), "the recorded scenario has no [array] without one");
}

fn load(file: &Path, sets: &[&str]) -> Result<PickPlaceScenario, ScenarioError> {
    let o: Vec<Override> = sets.iter().map(|s| s.parse().unwrap()).collect();
    tendril_config::load(file, &o)
}

/// The key and reason a layout is refused with.
fn refusal(sets: &[&str]) -> (String, String) {
    match load(&scenario("hammer.toml"), sets) {
        Ok(_) => panic!("{sets:?} was accepted"),
        Err(ScenarioError::Invalid { key, reason, .. }) => (key, reason),
        Err(e) => panic!("{sets:?}: {e}"),
    }
}

#[test]
fn bad_layouts_are_refused_on_their_key_with_the_reason() {
    for (set, key, reason) in [
        // Windows that meet on one fibre: pad 0's strain grating moves over 1539.8-1546.3 nm.
        ("array.pads=[{arc_m=0.03,lambda1_nm=1543.0}]", "array.pads[0].lambda1_nm", "sensor.lambda1_nm"),
        // Out of the interrogator's band.
        ("array.pads=[{arc_m=0.03,lambda1_nm=1597.0}]", "array.pads[0].lambda1_nm", "band"),
        // Casings overlapping pad 0's (61.25 mm) or each other's.
        ("array.pads=[{arc_m=0.065,lambda1_nm=1525.0}]", "array.pads[0].arc_m", "finger.pad_position_m"),
        (
            "array.pads=[{arc_m=0.03,lambda1_nm=1525.0},{arc_m=0.035,lambda1_nm=1560.0}]",
            "array.pads[1].arc_m",
            "array.pads[0].arc_m",
        ),
        // Off the strip, or over the tip's anchor.
        ("array.pads=[{arc_m=0.002,lambda1_nm=1525.0}]", "array.pads[0].arc_m", "on the strip"),
        ("array.pads=[{arc_m=0.135,lambda1_nm=1525.0}]", "array.pads[0].arc_m", "on the strip"),
        // A shared reference on another fibre.
        ("array.pads=[{arc_m=0.03,channel=2,lambda1_nm=1525.0}]", "array.pads[0].lambda2_nm", "channel"),
        // More than eight pads.
        (
            "array.pads=[{arc_m=0.01,lambda1_nm=1505},{arc_m=0.023,lambda1_nm=1512},{arc_m=0.036,lambda1_nm=1519},\
             {arc_m=0.049,lambda1_nm=1526},{arc_m=0.075,lambda1_nm=1555},{arc_m=0.088,lambda1_nm=1562},\
             {arc_m=0.101,lambda1_nm=1569},{arc_m=0.114,lambda1_nm=1576}]",
            "array.pads",
            "at most 7",
        ),
    ] {
        let (k, r) = refusal(&[set]);
        assert_eq!(k, key, "--set {set}: {r}");
        assert!(r.contains(reason), "--set {set}: {r}");
    }
}

/// In spectral mode the array's gratings share their channel's spectrum and are found in it as
/// the interrogator finds them: each pad still reads its own force.
#[test]
fn a_spectral_array_reads_every_pad_from_one_spectrum() {
    let dir = tempfile::tempdir().unwrap();
    let (trace, stdout) = run(
        &["scenarios/hammer-array.toml", "--set", "interrogator.mode=\"spectral\"", "--set", "task.grasp_s=3"],
        dir.path(),
    );
    let header: Vec<&str> = trace.lines().next().unwrap().split(',').collect();
    let at = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let grasp: Vec<Vec<f64>> = trace
        .lines()
        .filter(|l| l.contains(",grasp,"))
        .map(|l| l.split(',').map(|v| v.parse().unwrap_or(f64::NAN)).collect())
        .collect();
    assert!(grasp.len() > 100, "{stdout}");
    // Every peak found (no NaN), each pad's FBG1 in its own part of the band.
    for (col, lo, hi) in
        [("fbg1_nm", 1539.0, 1547.0), ("pad1_fbg1_nm", 1524.0, 1532.0), ("pad2_fbg1_nm", 1559.0, 1567.0)]
    {
        assert!(grasp.iter().all(|r| r[at(col)] > lo && r[at(col)] < hi), "{col}");
    }
    let last = grasp.last().unwrap();
    assert!((last[at("force_n")] - last[at("true_force_n")]).abs() < 0.3, "pad 0: {last:?}");
}

#[test]
fn the_shipped_array_scenario_loads_and_reads_three_pads() {
    let s = load(&scenario("hammer-array.toml"), &[]).unwrap();
    assert_eq!(s.array.pad_count(), 3);
    let dir = tempfile::tempdir().unwrap();
    let (trace, stdout) = run(&["scenarios/hammer-array.toml"], dir.path());
    let header: Vec<&str> = trace.lines().next().unwrap().split(',').collect();
    for col in ["pad1_true_force_n", "pad1_force_n", "pad2_fbg1_nm", "pad2_force_n", "control_force_n"] {
        assert!(header.contains(&col), "{col} missing from {header:?}");
    }
    let at = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let rows: Vec<Vec<f64>> = trace
        .lines()
        .skip(1)
        .filter(|l| l.contains(",grasp,"))
        .map(|l| l.split(',').map(|v| v.parse().unwrap_or(f64::NAN)).collect())
        .collect();
    assert!(rows.len() > 100, "{stdout}");
    // Every pad's estimate follows its own true force (eq. 8 with its own tare), within the
    // single pad's accuracy where the pad is loaded inside its range.
    for k in 1..=2 {
        let (truth, est) = (at(&format!("pad{k}_true_force_n")), at(&format!("pad{k}_force_n")));
        let inside: Vec<&Vec<f64>> = rows.iter().filter(|r| r[truth] < 4.0).collect();
        assert!(!inside.is_empty());
        let rmse = (inside.iter().map(|r| (r[est] - r[truth]).powi(2)).sum::<f64>() / inside.len() as f64).sqrt();
        assert!(rmse < 0.25, "pad {k}: estimate RMSE {rmse} N over {} grasp ticks", inside.len());
    }
    // With `control = "first"` the controller regulates pad 0's estimate.
    assert!(rows.iter().all(|r| r[at("control_force_n")] == r[at("force_n")]));
}

/// `tendril run` of the crimper with `scenarios/hammer-array.toml`'s layout (a low pad where the
/// wrap starts, one beyond pad 0) and `sets`; returns the summary.
fn crimper_with_array(sets: &[&str], out: &Path) -> serde_json::Value {
    let mut args = vec![
        "scenarios/crimper.toml",
        "--set",
        "array.pads=[{arc_m=0.012,lambda1_nm=1525.0,protrusion_m=0.0025},{arc_m=0.0775,lambda1_nm=1560.0}]",
    ];
    for s in sets {
        args.extend(["--set", s]);
    }
    run(&args, out);
    serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap()
}

/// The whole-link finger the array's cue was set on (`array.cue_transfer`): on it the cue sees the
/// knocked crimper's drop before it happens (seed 1: 0.16 s before) and stays silent through a run
/// that holds. On today's half-link default it alarms in the crimper's lift, before the knock, and
/// once in a held run (docs/studies/placement.md); the cue is not retuned for it yet, so this test
/// keeps the finger it was set on.
const WHOLE_LINK_FINGER: [&str; 4] = [
    "finger.base_joint=\"whole_link\"",
    "finger.segments=8",
    "finger.relaxation_time_s=18",
    "physics.contact_timeconst_s=0.005",
];

#[test]
fn the_array_cue_fires_before_a_knocked_drop_and_not_in_a_held_run() {
    let dir = tempfile::tempdir().unwrap();
    let knocked = crimper_with_array(
        &[
            WHOLE_LINK_FINGER[0],
            WHOLE_LINK_FINGER[1],
            WHOLE_LINK_FINGER[2],
            WHOLE_LINK_FINGER[3],
            "task.minimum_durations=false",
            "disturbance.push.impulse_n_s=0.3",
            "disturbance.push.duration_s=0.02",
            "disturbance.push.phase=\"transfer\"",
            "disturbance.push.offset_s=1.0",
        ],
        &dir.path().join("knocked"),
    );
    assert_eq!(knocked["outcome"], "dropped");
    let delay = knocked["array"]["cue_detection_delay_s"].as_f64().expect("the cue saw the drop");
    assert!(delay < 0.0, "the cue came {delay} s after the drop");
    let held = crimper_with_array(&WHOLE_LINK_FINGER, &dir.path().join("held"));
    assert_eq!(held["outcome"], "held");
    assert_eq!(held["array"]["cue_alarms"], 0, "{}", held["array"]);
    assert_eq!(held["array"]["pad_figures"].as_array().unwrap().len(), 3);
    // The low pad where the wrap starts reads the crimper's wrap (0.4 N mean while holding).
    let base = held["array"]["pad_figures"][1]["mean_true_n"].as_f64().unwrap();
    assert!(base > 0.1, "pad 1 carried {base} N");
}

/// The shipped array sweep runs as its comment says: 27 runs, none failing, every undisturbed run
/// held.
#[test]
fn the_array_sweep_runs() {
    let dir = tempfile::tempdir().unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_tendril"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(["sweep", "scenarios/sweep-disturbed-array.toml", "--out"])
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut r = csv::Reader::from_path(dir.path().join("results.csv")).unwrap();
    let header = r.headers().unwrap().clone();
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let (outcome, impulse) = (col("outcome"), col("disturbance.push.impulse_n_s"));
    let rows: Vec<csv::StringRecord> = r.records().map(Result::unwrap).collect();
    assert_eq!(rows.len(), 27);
    for row in &rows {
        assert_ne!(&row[outcome], "error", "{row:?}");
        if &row[impulse] == "0.0" {
            assert_eq!(&row[outcome], "held", "{row:?}");
        }
    }
}

/// A pad given its own calibration (`[[array.calibrations]]`, from a bench run on that pad) is
/// estimated with it; the others are not; a list of the wrong length is refused.
#[test]
fn a_pad_is_estimated_with_its_own_calibration() {
    let (k, r) = refusal(&["array.pads=[{arc_m=0.03,lambda1_nm=1525.0}]", "array.calibrations=[{},{}]"]);
    assert_eq!(k, "array.calibrations", "{r}");
    let dir = tempfile::tempdir().unwrap();
    let short = ["scenarios/crimper.toml", "--set", "task.grasp_s=3", "--set"];
    let layout = "array.pads=[{arc_m=0.012,lambda1_nm=1525.0,protrusion_m=0.0025},{arc_m=0.0775,lambda1_nm=1560.0}]";
    let (plain, _) = run(&[&short[..], &[layout]].concat(), &dir.path().join("plain"));
    let own = [&short[..], &[layout, "--set", "array.calibrations=[{b_pm_per_n=600.0},{}]"]].concat();
    let (calibrated, _) = run(&own, &dir.path().join("own"));
    let column = |trace: &str, name: &str| -> Vec<f64> {
        let header: Vec<&str> = trace.lines().next().unwrap().split(',').collect();
        let at = header.iter().position(|h| *h == name).unwrap();
        trace.lines().skip(1).map(|l| l.split(',').nth(at).unwrap().parse().unwrap()).collect()
    };
    assert_eq!(column(&plain, "force_n"), column(&calibrated, "force_n"), "pad 0 keeps [estimator]'s");
    assert_eq!(column(&plain, "pad2_force_n"), column(&calibrated, "pad2_force_n"), "pad 2 too");
    let (a, b) = (column(&plain, "pad1_force_n"), column(&calibrated, "pad1_force_n"));
    // A steeper b reads the same shift as less force, where the pad is loaded.
    let loaded: Vec<(f64, f64)> = a.iter().zip(&b).filter(|(x, _)| **x > 0.3).map(|(x, y)| (*x, *y)).collect();
    assert!(!loaded.is_empty() && loaded.iter().all(|(x, y)| y < x), "pad 1: {loaded:?}");
}
