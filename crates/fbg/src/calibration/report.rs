//! `tendril calibrate FILE.csv`: every procedure the record supports, as a plain-text report.

use super::{BenchRecord, force_calibration, temperature_calibration};
use std::fmt::Write;
use std::path::Path;

/// Reads a bench CSV and runs the force calibration (if it has load-cell data) and the temperature
/// calibration (if it has thermometer data); returns the report text.
pub fn calibrate_file(file: &Path) -> anyhow::Result<String> {
    let record = BenchRecord::read_csv(file)?;
    let mut out = String::new();
    let has_force = record.rows.iter().any(|r| r.load_cell_n.is_some());
    let has_temp = record.rows.iter().any(|r| r.temperature_c.is_some());
    writeln!(out, "{}: {} rows", file.display(), record.rows.len())?;
    if has_force {
        let f =
            force_calibration(&record).map_err(|e| anyhow::anyhow!("{}: force calibration: {e}", file.display()))?;
        writeln!(out, "force calibration ({} load/unload cycles):", f.cycles)?;
        writeln!(out, "  Δλ1 = {:.2} N² + {:.2} N + {:.2} pm", f.a_pm_per_n2, f.b_pm_per_n, f.c_pm)?;
        writeln!(out, "  R² {:.4}, fit RMSE {:.2} pm, force RMSE {:.3} N", f.r2, f.rmse_pm, f.rmse_n)?;
        writeln!(
            out,
            "  range {:.2} N -> {:.1} pm, sensitivity {:.1} pm/N",
            f.peak_force_n, f.span_pm, f.sensitivity_pm_per_n
        )?;
        writeln!(out, "  max hysteresis {:.2} % of full scale at {:.2} N", f.hysteresis_percent, f.hysteresis_at_n)?;
    }
    if has_temp {
        let t = temperature_calibration(&record)
            .map_err(|e| anyhow::anyhow!("{}: temperature calibration: {e}", file.display()))?;
        writeln!(out, "temperature calibration:")?;
        writeln!(
            out,
            "  K_T1 {:.3} pm/°C (R² {:.4}), K_T2 {:.3} pm/°C (R² {:.4}), r {:.4}",
            t.kt1_pm_per_c, t.r2_1, t.kt2_pm_per_c, t.r2_2, t.r
        )?;
    }
    if !has_force && !has_temp {
        anyhow::bail!("{}: no load_cell_n and no temperature_c values: nothing to calibrate", file.display());
    }
    Ok(out)
}
