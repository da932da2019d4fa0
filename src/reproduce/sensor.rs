//! `tendril reproduce sensor`: the paper's Sec. IV sensor results from the simulated bench.
//!
//! Runs the four bench scenarios through the same calibration code a recorded bench would go
//! through: force calibration → (fitted curve, sensitivity, RMSE, hysteresis), validation →
//! load-cell comparison, water bath → K_T1, K_T2, r, compensation test → compensated and
//! uncompensated RMSE. Also fits the software hysteresis compensation on the calibration run and
//! reports what it does on the validation run.

use super::Row;
use anyhow::Context;
use std::path::Path;
use tendril_config as scenario;
use tendril_fbg::bench::BenchScenario;
use tendril_fbg::calibration::{self, BenchRecord};
use tendril_fbg::estimate::ForceCalibration;

/// Scenario files read from the scenario folder.
pub const SCENARIOS: [&str; 4] = [
    "bench-force-calibration.toml",
    "bench-validation.toml",
    "bench-temperature-calibration.toml",
    "bench-compensation.toml",
];

/// The paper's calibration curve `Δλ1 [pm] = 144.99 N² + 527.62 N − 91.42` (Sec. IV-B).
pub fn paper_curve_pm(n: f64) -> f64 {
    144.99 * n * n + 527.62 * n - 91.42
}

/// Loads and runs one bench scenario.
pub fn run_scenario(path: &Path) -> anyhow::Result<(BenchScenario, BenchRecord)> {
    let s: BenchScenario = scenario::load(path, &[])?;
    let record = tendril_fbg::bench::run(&s);
    Ok((s, record))
}

fn at_most(quantity: &str, paper: &str, twin: f64, limit: f64, unit: &str, digits: usize) -> Row {
    Row {
        quantity: quantity.into(),
        paper: paper.into(),
        twin: format!("{twin:.digits$} {unit}"),
        tolerance: format!("≤ {limit:.digits$} {unit}"),
        pass: twin.is_finite() && twin <= limit,
    }
}

/// Runs the sensor bench scenarios in `scenario_dir` and returns the comparison rows (issue §5).
pub fn rows(scenario_dir: &Path) -> anyhow::Result<Vec<Row>> {
    let path = |name: &str| scenario_dir.join(name);
    let (_, cal_rec) = run_scenario(&path(SCENARIOS[0]))?;
    let (val_s, val_rec) = run_scenario(&path(SCENARIOS[1]))?;
    let (_, temp_rec) = run_scenario(&path(SCENARIOS[2]))?;
    let (comp_s, comp_rec) = run_scenario(&path(SCENARIOS[3]))?;

    let fit = calibration::force_calibration(&cal_rec).context(SCENARIOS[0])?;
    let temp = calibration::temperature_calibration(&temp_rec).context(SCENARIOS[2])?;
    let cal = fit.calibration(temp.r);
    let cmp = calibration::compare(&val_rec, val_s.estimator.as_ref().unwrap_or(&cal)).context(SCENARIOS[1])?;
    let taped = comp_s.taped_heating.as_ref().context("bench-compensation.toml needs [taped_heating]")?;
    let comp_cal = comp_s.estimator.as_ref().unwrap_or(&cal);
    let comp = calibration::compensation_test(&comp_rec, comp_cal, taped.settle_s, 1.0).context(SCENARIOS[3])?;
    let model = calibration::fit_hysteresis_model(&cal_rec, &cal).context("hysteresis model")?;
    let cmp_h = calibration::compare(&val_rec, &ForceCalibration { hysteresis: Some(model), ..cal.clone() })
        .context("hysteresis compensation")?;

    let curve_dev = (0..=419)
        .map(|i| 0.5 + i as f64 * 0.01)
        .map(|n| (fit.a_pm_per_n2 * n * n + fit.b_pm_per_n * n + fit.c_pm - paper_curve_pm(n)).abs())
        .fold(0.0, f64::max);
    let mut rows = vec![
        Row {
            quantity: "calibration curve, max deviation over 0.5-4.69 N [pm]".into(),
            paper: "144.99 N² + 527.62 N − 91.42".into(),
            twin: format!(
                "{:.2} N² + {:.2} N − {:.2} ({curve_dev:.1} pm off)",
                fit.a_pm_per_n2, fit.b_pm_per_n, -fit.c_pm
            ),
            tolerance: "≤ 60 pm".into(),
            pass: curve_dev.is_finite() && curve_dev <= 60.0,
        },
        // R² and fit RMSE: tolerances of our own (the issue sets none); the paper rounds R² to 0.99.
        Row::within("calibration fit R² [-]", 0.99, fit.r2, 0.005, "", 3),
        Row::within("calibration fit RMSE [pm]", 144.21, fit.rmse_pm, 40.0, "pm", 1),
        Row::within("sensitivity [pm/N]", 1169.04, fit.sensitivity_pm_per_n, 0.03 * 1169.04, "pm/N", 1),
        Row::within("calibration force RMSE [N]", 0.12, fit.rmse_n, 0.04, "N", 3),
        Row::within("load-cell comparison RMSE [N]", 0.14, cmp.rmse_n, 0.04, "N", 3),
        Row::within("max hysteresis [% FS]", 4.83, fit.hysteresis_percent, 0.5, "%", 2),
        Row::within("max hysteresis at [N]", 2.68, fit.hysteresis_at_n, 0.4, "N", 2),
        Row::within("K_T1 [pm/°C]", 24.29, temp.kt1_pm_per_c, 0.02 * 24.29, "pm/°C", 2),
        Row::within("K_T2 [pm/°C]", 10.31, temp.kt2_pm_per_c, 0.02 * 10.31, "pm/°C", 2),
        Row {
            quantity: "K_T1 fit R² [-]".into(),
            paper: "0.99".into(),
            twin: format!("{:.4}", temp.r2_1),
            tolerance: "≥ 0.99".into(),
            pass: temp.r2_1 >= 0.99,
        },
        Row {
            quantity: "K_T2 fit R² [-]".into(),
            paper: "1.00".into(),
            twin: format!("{:.4}", temp.r2_2),
            tolerance: "≥ 0.99".into(),
            pass: temp.r2_2 >= 0.99,
        },
        // Two 2 % tolerances combine to about 4 % on the ratio.
        Row::within("r = K_T1/K_T2 [-]", 2.356, temp.r, 0.04 * 2.356, "", 3),
        at_most("compensation test: compensated RMSE [N]", "0.01 N", comp.compensated_rmse_n, 0.02, "N", 3),
        Row::within("compensation test: uncompensated RMSE [N]", 0.23, comp.uncompensated_rmse_n, 0.05, "N", 3),
        // Tolerances below are this twin's own (the issue sets none): the paper's figures to ± 25 %.
        Row::within("compensation test: max uncompensated error [N]", 0.4, comp.max_uncompensated_error_n, 0.1, "N", 2),
        Row::within(
            "compensation test: ΔT read by FBG2 [°C]",
            11.0,
            comp.fbg2_shift_pm / temp.kt2_pm_per_c,
            0.5,
            "°C",
            2,
        ),
    ];
    rows.push(Row {
        quantity: "software hysteresis compensation: max hysteresis on validation [% of range]".into(),
        paper: "— (future work)".into(),
        twin: format!("{:.2} % (without: {:.2} %)", cmp_h.hysteresis_percent, cmp.hysteresis_percent),
        tolerance: "below without".into(),
        pass: cmp_h.hysteresis_percent < cmp.hysteresis_percent,
    });
    rows.push(Row {
        quantity: "software hysteresis compensation: validation RMSE [N]".into(),
        paper: "— (future work)".into(),
        twin: format!("{:.3} N (without: {:.3} N)", cmp_h.rmse_n, cmp.rmse_n),
        tolerance: "below without".into(),
        pass: cmp_h.rmse_n < cmp.rmse_n,
    });
    Ok(rows)
}
