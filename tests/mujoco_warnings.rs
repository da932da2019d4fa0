//! MuJoCo's warnings go to our log and the run's summary, not to `MUJOCO_LOG.TXT` in the working
//! directory (issue 18). One test in its own binary: it changes the working directory.

#[test]
fn a_mujoco_warning_is_kept_for_the_run_and_writes_no_log_file() {
    let dir = tempfile::tempdir().unwrap();
    std::env::set_current_dir(dir.path()).unwrap();
    // SAFETY: the only test in this binary; no other thread uses MuJoCo.
    unsafe { tendril_twin::mujoco_log::install() };
    mujoco_rs::prelude::log_warning("probe warning from the test");
    assert_eq!(tendril_twin::mujoco_log::take_warnings(), ["probe warning from the test"]);
    assert!(tendril_twin::mujoco_log::take_warnings().is_empty(), "taken once");
    // Another thread's warnings are its own run's.
    std::thread::spawn(|| mujoco_rs::prelude::log_warning("on another thread")).join().unwrap();
    assert!(tendril_twin::mujoco_log::take_warnings().is_empty());
    for _ in 0..100 {
        mujoco_rs::prelude::log_warning("again");
    }
    assert_eq!(tendril_twin::mujoco_log::take_warnings().len(), tendril_twin::mujoco_log::MAX_KEPT);
    assert!(!dir.path().join("MUJOCO_LOG.TXT").exists(), "MuJoCo wrote its own log file");
}
