//! `tendril plot`.

use super::emit;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `tendril plot`.
#[derive(Debug, clap::Args)]
pub struct PlotArgs {
    /// A run directory, a sweep directory, or one of the CSV files.
    path: PathBuf,
    /// Write the charts here (default: next to the input).
    #[arg(long)]
    out: Option<PathBuf>,
}

pub fn run(a: PlotArgs) -> anyhow::Result<ExitCode> {
    for file in tendril_plot::plot_path(&a.path, a.out.as_deref())? {
        emit(&format!("{}\n", file.display()));
    }
    Ok(ExitCode::SUCCESS)
}
