//! Every input bounded, checked before anything runs, with the right key named (issue 18): the
//! values the hostile-user pass found accepted, hanging, or reported on the wrong key, through the
//! library's own load path (parse, `--set`, deserialise, validate).

use std::path::{Path, PathBuf};
use tendril_config::{Override, ScenarioError};
use tendril_run::scenario::PickPlaceScenario;

fn crimper() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/crimper.toml")
}

fn load(sets: &[&str]) -> Result<PickPlaceScenario, ScenarioError> {
    let o: Vec<Override> = sets.iter().map(|s| s.parse().unwrap()).collect();
    tendril_config::load(&crimper(), &o)
}

/// The key a failure names.
fn key_of(sets: &[&str]) -> String {
    match load(sets) {
        Ok(_) => panic!("{sets:?} was accepted"),
        Err(ScenarioError::Invalid { key, file, .. }) => {
            assert_eq!(file, crimper());
            key
        }
        Err(e) => panic!("{sets:?}: {e}"),
    }
}

#[test]
fn values_that_hung_or_were_accepted_are_refused_on_their_own_key() {
    for (set, key) in [
        ("task.grasp_s=1e9", "task.grasp_s"),
        ("task.grasp_s=3601", "task.grasp_s"),
        ("interrogator.sample_rate_hz=1e9", "interrogator.sample_rate_hz"),
        ("interrogator.sample_rate_hz=20000", "interrogator.sample_rate_hz"),
        ("controller.kp=1e300", "controller.kp"),
        ("controller.kp=20000", "controller.kp"),
        ("physics.contact_dampratio=1e300", "physics.contact_dampratio"),
        ("physics.contact_dampratio=1000", "physics.contact_dampratio"),
        ("physics.max_penetration_m=1e300", "physics.max_penetration_m"),
        ("physics.max_penetration_m=1", "physics.max_penetration_m"),
        ("physics.iterations=100000", "physics.iterations"),
        ("task.wrap_contact_n=1e300", "task.wrap_contact_n"),
        ("task.wrap_contact_n=5", "task.wrap_contact_n"),
        ("slip.lost_hold_s=1e9", "slip.lost_hold_s"),
        ("slip.lost_hold_s=100", "slip.lost_hold_s"),
        ("object.position_m=[1e9,1e9]", "object.position_m"),
        ("object.position_m=[2.0,0.0]", "object.position_m"),
        ("task.growth_speed_m_s=1e-6", "task.growth_speed_m_s"),
        ("task.limits.max_speed_deg_s=0.001", "task.limits"),
        // Wrong key named before: the cross-check read the bad value first.
        ("estimator.range_n=nan", "estimator.range_n"),
        ("estimator.range_n=500", "estimator.range_n"),
        ("interrogator.sample_rate_hz=nan", "interrogator.sample_rate_hz"),
        ("interrogator.sample_rate_hz=0.5", "interrogator.sample_rate_hz"),
        ("physics.iterations=9223372036854775807", "physics.iterations"),
    ] {
        assert_eq!(key_of(&[set]), key, "--set {set}");
    }
    // The cross-checks still name their own key when the pieces are valid.
    assert_eq!(key_of(&["setpoint_n=4.69"]), "setpoint_n");
    assert_eq!(key_of(&["interrogator.sample_rate_hz=50", "control_rate_hz=100"]), "control_rate_hz");
}

#[test]
fn the_defaults_and_the_shipped_scenarios_stay_valid() {
    for name in ["crimper", "hammer", "shampoo", "short-lift"] {
        let file = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("scenarios/{name}.toml"));
        let r: Result<PickPlaceScenario, _> = tendril_config::load(&file, &[]);
        assert!(r.is_ok(), "{name}: {:?}", r.err());
    }
    // The other engineer's ranges: timesteps down to 1e-4 s, up to 60 finger segments.
    assert!(load(&["physics.timestep_s=1e-4", "finger.segments=60"]).is_ok());
}

#[test]
fn a_graded_finger_finer_than_its_bound_names_the_refinement_and_the_way_out() {
    // 128 links on the default 8x finer base stretch: 1024 base links, past the 512 bound.
    assert_eq!(key_of(&["finger.segments=128"]), "finger.base_refinement");
    let err = load(&["finger.segments=128"]).unwrap_err().to_string();
    assert!(err.contains("128 x 8 = 1024") && err.contains("base_refinement = 1"), "{err}");
    assert!(load(&["finger.segments=128", "finger.base_refinement=1"]).is_ok());
}

#[test]
fn a_fine_zone_must_start_on_the_strip_before_the_pad() {
    for bad in ["-0.01", "0.06", "nan"] {
        assert_eq!(key_of(&[&format!("finger.fine_from_m={bad}")]), "finger.fine_from_m", "{bad}");
    }
    let err = load(&["finger.fine_from_m=0.06"]).unwrap_err().to_string();
    assert!(err.contains("before the pad's casing") && err.contains("0.05525"), "{err}");
    assert!(load(&["finger.fine_from_m=0.0175"]).is_ok());
}

#[test]
fn the_clamp_s_joint_takes_only_its_two_names() {
    let err = load(&["finger.base_joint=\"half\""]).unwrap_err().to_string();
    assert!(err.contains("finger.base_joint") && err.contains("whole_link") && err.contains("half_link"), "{err}");
    for ok in ["whole_link", "half_link"] {
        assert!(load(&[&format!("finger.base_joint=\"{ok}\"")]).is_ok(), "{ok}");
    }
}

#[test]
fn any_u64_seed_is_accepted_through_set_and_the_file() {
    assert_eq!(load(&["seed=18446744073709551615"]).unwrap().seed, u64::MAX);
    assert_eq!(load(&["seed=\"18446744073709551615\""]).unwrap().seed, u64::MAX);
    assert_eq!(key_of(&["seed=-1"]), "seed");
    assert_eq!(key_of(&["seed=18446744073709551616"]), "seed");
}

#[test]
fn a_non_utf8_scenario_names_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("bad.toml");
    std::fs::write(&file, b"name = \"x\"\nsetpoint_n = 0.6 # \xff\n").unwrap();
    let err = tendril_config::load::<PickPlaceScenario>(&file, &[]).unwrap_err();
    assert!(matches!(err, ScenarioError::Encoding { line: 2, column: 20, .. }), "{err}");
    assert!(err.to_string().contains("bad.toml: line 2, column 20"), "{err}");
}

#[test]
fn a_bad_grid_or_list_value_names_the_sweep_file_and_its_place() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = dir.path().join("sweep.toml");
    let check = |text: &str| {
        std::fs::write(&sweep, format!("scenarios = ['{}']\n{text}", crimper().display())).unwrap();
        tendril::sweep::execute::check_runs(&tendril::sweep::load_sweep(&sweep).unwrap()).unwrap_err()
    };
    let err = check("[grid]\n'controller.kp' = [20.0, 1e300]\n");
    assert!(
        matches!(&err, ScenarioError::Invalid { file, key, .. } if *file == sweep && key == "grid.\"controller.kp\""),
        "{err}"
    );
    assert!(err.to_string().contains("run 1"), "{err}");
    let err = check("[grid]\nseed = [1]\n[[list]]\nfeedback = true\n[[list]]\n'slip.lost_hold_s' = 1e9\n");
    assert!(
        matches!(&err, ScenarioError::Invalid { file, key, .. } if *file == sweep && key == "list[1].slip.lost_hold_s"),
        "{err}"
    );
}

#[test]
fn calibration_csvs_with_huge_frozen_or_gappy_values_fail_fast() {
    let dir = tempfile::tempdir().unwrap();
    let mut rows = String::from("time_s,load_cell_n,fbg1_nm,fbg2_nm,temperature_c\n");
    for i in 0..300 {
        let t = i as f64 * 0.01;
        let f = if t < 0.5 { 0.0 } else { 4.0 * ((t - 0.5) * 1.3).sin().abs() };
        rows += &format!("{t:.2},{f:.4},{:.4},1550.0,\n", 1540.0 + 0.53 * f + 0.145 * f * f);
    }
    let started = std::time::Instant::now();
    // Row 100's load-cell cell replaced: huge, beyond f64's square, or missing.
    let set_cell = |value: &str| -> String {
        let mut lines: Vec<String> = rows.lines().map(str::to_string).collect();
        let mut cells: Vec<&str> = lines[100].split(',').collect();
        cells[1] = value;
        lines[100] = cells.join(",");
        lines.join("\n") + "\n"
    };
    for (value, expect) in [("1e160", "outside"), ("1e300", "outside"), ("", "is empty"), ("nan", "not finite")] {
        let file = dir.path().join("bench.csv");
        std::fs::write(&file, set_cell(value)).unwrap();
        let err = tendril_fbg::calibration::report::calibrate_file(&file).unwrap_err().to_string();
        assert!(err.contains("bench.csv: line 101") && err.contains(expect), "{value}: {err}");
    }
    let frozen: String = rows
        .lines()
        .enumerate()
        .map(|(i, l)| if i == 0 { format!("{l}\n") } else { format!("0{}\n", &l[l.find(',').unwrap()..]) })
        .collect();
    std::fs::write(dir.path().join("frozen.csv"), frozen).unwrap();
    let err = tendril_fbg::calibration::report::calibrate_file(&dir.path().join("frozen.csv")).unwrap_err().to_string();
    assert!(err.contains("never advances"), "{err}");
    assert!(started.elapsed().as_secs_f64() < 10.0, "no spinning");
}
