//! Software hysteresis compensation (the paper's future work): fitted on the simulated calibration
//! run, applied to the validation run. Against a noise-free load cell the figures show what the
//! compensation itself does (the shipped scenarios' 0.095 N load-cell noise dominates their RMSE).

use std::path::Path;
use tendril_config::{Override, load};
use tendril_fbg::bench::{BenchScenario, run};
use tendril_fbg::calibration::{compare, fit_hysteresis_model, force_calibration};
use tendril_fbg::estimate::ForceCalibration;

fn scenario(name: &str) -> BenchScenario {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios").join(name);
    let quiet: Override = "load_cell.noise_n=0.0".parse().unwrap();
    load(&path, &[quiet]).unwrap()
}

#[test]
fn compensation_reduces_hysteresis_and_rmse() {
    let cal_rec = run(&scenario("bench-force-calibration.toml"));
    let val_rec = run(&scenario("bench-validation.toml"));
    let cal = force_calibration(&cal_rec).unwrap().calibration(24.29 / 10.31);
    let model = fit_hysteresis_model(&cal_rec, &cal).unwrap();
    let plain = compare(&val_rec, &cal).unwrap();
    let comp = compare(&val_rec, &ForceCalibration { hysteresis: Some(model.clone()), ..cal }).unwrap();
    println!("model {model:?}");
    println!(
        "hysteresis {:.2} % -> {:.2} % of range; RMSE {:.4} N -> {:.4} N",
        plain.hysteresis_percent, comp.hysteresis_percent, plain.rmse_n, comp.rmse_n
    );
    assert!(comp.hysteresis_percent < 0.3 * plain.hysteresis_percent);
    assert!(comp.rmse_n < 0.5 * plain.rmse_n);
}
