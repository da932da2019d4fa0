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
        /// Folder holding the scenario files.
        #[arg(long, default_value = "scenarios")]
        scenarios: std::path::PathBuf,
    },
    /// Run one pick-and-place scenario on the twin; writes DIR/trace.csv and DIR/summary.json.
    Run {
        /// The scenario file (scenarios/crimper.toml, ...).
        scenario: std::path::PathBuf,
        /// Output folder [default: out/<scenario name>].
        #[arg(long)]
        out: Option<std::path::PathBuf>,
        /// Seed of the sensor noise (same scenario and seed: identical trace).
        #[arg(long)]
        seed: Option<u64>,
        /// Keep force control on while the arm moves (`on`) or switch it off before (`off`).
        #[arg(long, value_parser = ["on", "off"])]
        feedback: Option<String>,
        /// Override a scenario value: `--set key.path=value` (repeatable), checked like the file.
        #[arg(long = "set")]
        set: Vec<crate::scenario::Override>,
    },
    /// Run the paper's calibration procedures on a bench CSV (columns: time_s, load_cell_n,
    /// fbg1_nm, fbg2_nm, temperature_c) and print the results.
    Calibrate {
        /// The bench CSV.
        file: std::path::PathBuf,
    },
    /// Simulate one bench scenario (scenarios/bench-*.toml) and write its record as CSV.
    Bench {
        /// The bench scenario file.
        scenario: std::path::PathBuf,
        /// Write the record here (CSV, the format `calibrate` reads); default: standard output.
        #[arg(long)]
        out: Option<std::path::PathBuf>,
        /// Override a scenario value: `--set key.path=value` (repeatable).
        #[arg(long = "set")]
        set: Vec<String>,
    },
    /// Build the physics scene from a scenario and run a scripted grasp, printing the readout.
    PhysicsCheck {
        /// Scenario TOML with optional [physics], [finger], [object], [check] sections.
        scenario: Option<std::path::PathBuf>,
        /// Overrides `key=value`, e.g. `finger.relaxation_time_s=8`.
        #[arg(long = "set")]
        set: Vec<crate::scenario::Override>,
    },
    /// Draw charts (PNG and SVG): a run directory's force trace, a sweep directory's heatmaps, or
    /// the charts of speed_accuracy.csv, stability.csv and gain_map.csv (a file or its folder).
    Plot {
        /// A run directory, a sweep directory, or one of the CSV files.
        path: std::path::PathBuf,
        /// Write the charts here (default: next to the input).
        #[arg(long)]
        out: Option<std::path::PathBuf>,
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
        Command::Reproduce { what, json, scenarios } => {
            let rows = reproduce_rows(&what, &scenarios)?;
            print!("{}", crate::reproduce::render_table(&rows));
            if let Some(path) = json {
                let text = serde_json::to_string_pretty(&rows)?;
                std::fs::write(&path, text + "\n")
                    .map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", path.display()))?;
            }
            Ok(if rows.iter().all(|r| r.pass) { ExitCode::SUCCESS } else { ExitCode::FAILURE })
        }
        Command::Run { scenario, out, seed, feedback, set } => {
            let mut overrides = set;
            if let Some(seed) = seed {
                overrides
                    .push(crate::scenario::Override { key: "seed".into(), value: toml::Value::Integer(seed as i64) });
            }
            if let Some(f) = feedback {
                overrides
                    .push(crate::scenario::Override { key: "feedback".into(), value: toml::Value::Boolean(f == "on") });
            }
            let s: crate::run::scenario::PickPlaceScenario = crate::scenario::load(&scenario, &overrides)?;
            let dir = out.unwrap_or_else(|| std::path::Path::new("out").join(&s.name));
            let (summary, _) = crate::run::execute::run_on_twin(&s, &Default::default(), Some(&dir))?;
            print!("{}", crate::run::summary::render_text(&summary));
            println!("wrote {0}/trace.csv and {0}/summary.json", dir.display());
            Ok(if summary.outcome == "error" { ExitCode::FAILURE } else { ExitCode::SUCCESS })
        }
        Command::Calibrate { file } => {
            print!("{}", crate::calibration::report::calibrate_file(&file)?);
            Ok(ExitCode::SUCCESS)
        }
        Command::Bench { scenario, out, set } => {
            let overrides = set.iter().map(|s| s.parse()).collect::<Result<Vec<crate::scenario::Override>, _>>()?;
            let s: crate::sensor_bench::BenchScenario = crate::scenario::load(&scenario, &overrides)?;
            let csv = crate::sensor_bench::run(&s).to_csv();
            match out {
                Some(path) => {
                    std::fs::write(&path, csv).map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", path.display()))?
                }
                None => print!("{csv}"),
            }
            Ok(ExitCode::SUCCESS)
        }
        Command::PhysicsCheck { scenario, set } => {
            let s: crate::cell::physics::check::CheckScenario = match scenario {
                Some(path) => crate::scenario::load(&path, &set)?,
                None => crate::scenario::from_str("", std::path::Path::new("(defaults)"), &set)?,
            };
            crate::cell::physics::check::run(&s)?;
            Ok(ExitCode::SUCCESS)
        }
        Command::Plot { path, out } => {
            for file in crate::plot::plot_path(&path, out.as_deref())? {
                println!("{}", file.display());
            }
            Ok(ExitCode::SUCCESS)
        }
    }
}

/// The rows of `tendril reproduce WHAT`: `sensor` (Sec. IV), `gripper` (Sec. V) or `all`.
pub fn reproduce_rows(what: &str, scenario_dir: &std::path::Path) -> anyhow::Result<Vec<crate::reproduce::Row>> {
    match what {
        "sensor" => crate::reproduce::sensor::rows(scenario_dir),
        "gripper" => crate::reproduce::gripper::rows(scenario_dir, &[]),
        "all" => {
            let mut rows = crate::reproduce::sensor::rows(scenario_dir)?;
            rows.extend(crate::reproduce::gripper::rows(scenario_dir, &[])?);
            Ok(rows)
        }
        other => anyhow::bail!("reproduce {other}: unknown (expected sensor, gripper or all)"),
    }
}
