//! Command-line interface: one file per command group, each with its arguments and handler.

mod chart;
mod devices;
mod latency;
mod physics;
mod plot;
mod realtime;
mod reproduce;
mod run;
mod sensor;
mod serve;
mod sweep;

use clap::{Parser, Subcommand};
use std::io::Write;
use std::process::ExitCode;

pub use reproduce::reproduce_rows;

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
    Reproduce(reproduce::ReproduceArgs),
    /// Run one pick-and-place scenario on the twin; writes DIR/trace.csv and DIR/summary.json.
    Run(run::RunArgs),
    /// Run a sweep over scenario keys in parallel; writes DIR/results.csv as runs finish.
    Sweep(sweep::SweepArgs),
    /// Merge the results files of a sharded sweep into one.
    Merge(sweep::MergeArgs),
    /// Draw charts (PNG and SVG): a run directory's force trace, a sweep directory's heatmaps, or
    /// the charts of speed_accuracy.csv, stability.csv and gain_map.csv (a file or its folder).
    Plot(plot::PlotArgs),
    /// Run a study over many runs and chart it: speed against accuracy, stability limits of the
    /// integrators, or the (Kp, Ki) map of each object.
    Chart(chart::ChartArgs),
    /// Run the paper's calibration procedures on a bench CSV (columns: time_s, load_cell_n,
    /// fbg1_nm, fbg2_nm, temperature_c) and print the results.
    Calibrate(sensor::CalibrateArgs),
    /// Simulate one bench scenario (scenarios/bench-*.toml) and write its record as CSV.
    Bench(sensor::BenchArgs),
    /// Build the physics scene from a scenario and run a scripted grasp, printing the readout.
    PhysicsCheck(physics::PhysicsCheckArgs),
    /// Write a scenario's assembled scene as one standalone MJCF (with a `start` keyframe) that
    /// MuJoCo's own tools open.
    Scene(physics::SceneArgs),
    /// Run the twin in real time behind the real devices' protocols (RTDE, URScript, a Dynamixel
    /// bus on a pseudo-terminal, HYPERION); loopback unless --bind says otherwise.
    Serve(serve::ServeArgs),
    /// Measure the real path's control-tick latency against the virtual devices on loopback.
    Latency(latency::LatencyArgs),
}

/// Runs the CLI and maps errors to a non-zero exit code with a one-line message.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Reproduce(a) => reproduce::run(a),
        Command::Run(a) => run::run(a),
        Command::Sweep(a) => sweep::run(a),
        Command::Merge(a) => sweep::merge(a),
        Command::Plot(a) => plot::run(a),
        Command::Chart(a) => chart::run(a),
        Command::Calibrate(a) => sensor::calibrate(a),
        Command::Bench(a) => sensor::bench(a),
        Command::PhysicsCheck(a) => physics::run(a),
        Command::Scene(a) => physics::scene(a),
        Command::Serve(a) => serve::run(a),
        Command::Latency(a) => latency::run(a),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("tendril: {e:#}");
            ExitCode::FAILURE
        }
    }
}

/// Writes to standard output; a closed pipe (`tendril ... | head`) ends output quietly instead
/// of panicking as `print!` would.
fn emit(text: &str) {
    let _ = std::io::stdout().lock().write_all(text.as_bytes());
}

/// Writes `text` to `path`, naming the file in the error.
fn write_file(path: &std::path::Path, text: &str) -> anyhow::Result<()> {
    std::fs::write(path, text).map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", path.display()))
}

/// Exit code for a list of pass/fail verdicts: success only when all pass.
fn exit_all(pass: bool) -> ExitCode {
    if pass { ExitCode::SUCCESS } else { ExitCode::FAILURE }
}
