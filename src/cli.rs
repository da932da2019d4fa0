//! Command-line interface: parses arguments and dispatches to the library.

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// tendril: digital twin of an FBG-sensed grow-and-twine gripping cell.
#[derive(Debug, Parser)]
#[command(name = "tendril", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Reproduce the paper's results and compare them with the paper's figures.
    Reproduce {
        /// Which results: `sensor` (Sec. IV), `gripper` (Sec. V) or `all`.
        what: String,
        /// Also write the comparison table as JSON to this file.
        #[arg(long)]
        json: Option<std::path::PathBuf>,
    },
}

/// Runs the CLI and maps errors to a non-zero exit code with a one-line message.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("tendril: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> anyhow::Result<ExitCode> {
    match cli.command {
        Command::Reproduce { what, json } => {
            let _ = json;
            anyhow::bail!("reproduce {what}: not built yet")
        }
    }
}
