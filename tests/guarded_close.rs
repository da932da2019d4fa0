//! The guarded close ends on contact, not on the interrogator's noise (`control::contact`): on the
//! short grasp-hold-lift (scenarios/short-lift.toml, the crimper) at 3, 10 and 30 pm of peak
//! noise, the wrap phase ends with the pad actually touching. Before the detector averaged noisy
//! readings, 10 pm ended 8 of 10 crimper closes with no contact and 30 pm all of them.

use crate::common::short_lift;
use tendril_control::task::Phase;
use tendril_run::execute::run_on_twin;

/// Cell time and true pad force \[N\] of the first grasp tick: where the close ended.
fn close_end(noise_pm: f64, seed: u64) -> (f64, f64) {
    let overrides = [format!("interrogator.noise_pm={noise_pm}"), format!("seed={seed}")];
    let overrides: Vec<&str> = overrides.iter().map(String::as_str).collect();
    let report = run_on_twin(&short_lift(&overrides), &Default::default(), None).unwrap().1;
    let row = report.rows.iter().find(|r| r.phase == Phase::Grasp).expect("the run reaches the grasp");
    (row.time_s, row.true_force_n)
}

#[test]
fn the_close_ends_on_contact_at_ten_and_thirty_picometres_of_noise() {
    let (quiet_s, quiet_n) = close_end(3.0, 1);
    assert!(quiet_n > 0.1, "3 pm: the close ended at {quiet_s} s with {quiet_n} N");
    for (noise, seed) in [(10.0, 1), (10.0, 2), (30.0, 1), (30.0, 2)] {
        let (t, f) = close_end(noise, seed);
        assert!(f > 0.05, "{noise} pm, seed {seed}: the close ended at {t} s with only {f} N on the pad");
        // It waits for the contact, but not long: within 0.5 s of the quiet close.
        assert!(t >= quiet_s - 0.1 && t < quiet_s + 0.5, "{noise} pm, seed {seed}: ended at {t} s (3 pm: {quiet_s} s)");
    }
}
