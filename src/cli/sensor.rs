//! `tendril calibrate` and `tendril bench`: the sensor bench.

use super::{emit, write_file};
use std::path::PathBuf;
use std::process::ExitCode;
use tendril_config::Override;
use tendril_fbg::bench::BenchScenario;

/// Arguments of `tendril calibrate`.
#[derive(Debug, clap::Args)]
pub struct CalibrateArgs {
    /// The bench CSV.
    file: PathBuf,
}

/// Arguments of `tendril bench`.
#[derive(Debug, clap::Args)]
pub struct BenchArgs {
    /// The bench scenario file.
    scenario: PathBuf,
    /// Write the record here (CSV, the format `calibrate` reads); default: standard output.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Override a scenario value: `--set key.path=value` (repeatable).
    #[arg(long = "set")]
    set: Vec<Override>,
}

pub fn calibrate(a: CalibrateArgs) -> anyhow::Result<ExitCode> {
    emit(&tendril_fbg::calibration::report::calibrate_file(&a.file)?);
    Ok(ExitCode::SUCCESS)
}

pub fn bench(a: BenchArgs) -> anyhow::Result<ExitCode> {
    let s: BenchScenario = tendril_config::load(&a.scenario, &a.set)?;
    let csv = tendril_fbg::bench::run(&s).to_csv();
    match a.out {
        Some(path) => write_file(&path, &csv)?,
        None => emit(&csv),
    }
    Ok(ExitCode::SUCCESS)
}
