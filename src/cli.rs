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
    /// Build the physics scene from a scenario and run a scripted grasp, printing the readout.
    PhysicsCheck {
        /// Scenario TOML with optional [physics], [finger], [object], [check] sections.
        scenario: Option<std::path::PathBuf>,
        /// Overrides `key=value`, e.g. `finger.relaxation_time_s=8`.
        #[arg(long = "set")]
        set: Vec<crate::scenario::Override>,
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
        Command::PhysicsCheck { scenario, set } => {
            let s: crate::cell::physics::check::CheckScenario = match scenario {
                Some(path) => crate::scenario::load(&path, &set)?,
                None => crate::scenario::from_str("", std::path::Path::new("(defaults)"), &set)?,
            };
            crate::cell::physics::check::run(&s)?;
            Ok(ExitCode::SUCCESS)
        }
    }
}
