//! Command-line interface: one file per command group, each with its arguments and handler.

mod chart;
mod devices;
mod fit;
mod keys;
mod latency;
mod physics;
mod plot;
mod realtime;
mod render;
mod reproduce;
mod ros2_latency;
mod run;
mod scenario_args;
mod sensor;
mod serve;
mod sweep;
mod tune;
mod view;

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
    /// Run one scenario on the twin live in MuJoCo's interactive viewer: the controller in the
    /// loop at real time (or --speed), keys to pause, switch feedback and knock the object, the
    /// mouse to push it; needs a display.
    View(view::ViewArgs),
    /// Render a finished run (its frames.bin) as an MP4 video with the force trace under the
    /// picture; offscreen through EGL, no display needed.
    Render(render::RenderArgs),
    /// Run a sweep over scenario keys in parallel; writes DIR/results.csv as runs finish.
    Sweep(sweep::SweepArgs),
    /// Calibrate the twin to recorded runs: search the scenario keys FIT.toml names for the values
    /// whose runs best match the recordings; writes DIR/overlay.toml, DIR/fit.json and a chart.
    Fit(fit::FitArgs),
    /// Tune the controller on the twin: search gains, setpoint and controller keys per object for
    /// the best hold, fluctuation, rise and overshoot; writes an overlay per object and charts.
    Tune(tune::TuneArgs),
    /// Merge the results files of a sharded sweep into one.
    Merge(sweep::MergeArgs),
    /// Draw charts (PNG and SVG): a run directory's force trace, a sweep directory's heatmaps, or
    /// the charts of speed_accuracy.csv, stability.csv, gain_map.csv and controllers.csv (a file
    /// or its folder).
    Plot(plot::PlotArgs),
    /// Run a study over many runs and chart it: speed against accuracy, stability limits of the
    /// integrators, the (Kp, Ki) map of each object, or the force controllers under disturbances.
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
    /// Print the scenario key reference (Markdown): every key with its unit, default, bounds and
    /// meaning, from the code (the book's "Scenario keys" page).
    Keys(keys::KeysArgs),
}

/// Runs the CLI and maps errors to a non-zero exit code with a one-line message.
pub fn main() -> ExitCode {
    // SAFETY: first thing, before any thread exists that could use MuJoCo.
    unsafe { tendril_twin::mujoco_log::install() };
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Reproduce(a) => reproduce::run(a),
        Command::Run(a) => run::run(a),
        Command::View(a) => view::run(a),
        Command::Render(a) => render::run(a),
        Command::Sweep(a) => sweep::run(a),
        Command::Merge(a) => sweep::merge(a),
        Command::Fit(a) => fit::run(a),
        Command::Tune(a) => tune::run(a),
        Command::Plot(a) => plot::run(a),
        Command::Chart(a) => chart::run(a),
        Command::Calibrate(a) => sensor::calibrate(a),
        Command::Bench(a) => sensor::bench(a),
        Command::PhysicsCheck(a) => physics::run(a),
        Command::Scene(a) => physics::scene(a),
        Command::Serve(a) => serve::run(a),
        Command::Latency(a) => latency::run(a),
        Command::Keys(a) => keys::run(a),
    };
    let code = match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("tendril: {}", error_chain(&e));
            return ExitCode::FAILURE;
        }
    };
    // Output that could not be written (`> /dev/full`) is a failure, reported here once.
    let flushed = std::io::stdout().lock().flush();
    match STDOUT_ERROR
        .get()
        .cloned()
        .or(flushed.err().filter(|e| e.kind() != std::io::ErrorKind::BrokenPipe).map(|e| e.to_string()))
    {
        Some(e) => {
            eprintln!("tendril: standard output: cannot write: {e}");
            ExitCode::FAILURE
        }
        None => code,
    }
}

/// The first error writing standard output, other than a closed pipe.
static STDOUT_ERROR: std::sync::OnceLock<String> = std::sync::OnceLock::new();

/// Writes to standard output; a closed pipe (`tendril ... | head`) ends output quietly instead
/// of panicking as `print!` would; any other write error (a full disk) is kept and makes
/// [`main`] exit non-zero.
fn emit(text: &str) {
    if let Err(e) = std::io::stdout().lock().write_all(text.as_bytes())
        && e.kind() != std::io::ErrorKind::BrokenPipe
    {
        let _ = STDOUT_ERROR.set(e.to_string());
    }
}

/// Writes `text` to `path` atomically (a failure keeps the previous file), naming the file in the
/// error.
fn write_file(path: &std::path::Path, text: &str) -> anyhow::Result<()> {
    tendril_config::write_atomically(path, text.as_bytes())
        .map_err(|(file, e)| anyhow::anyhow!("{}: cannot write: {e}", file.display()))
}

/// Longest duration a `--seconds` argument accepts \[s\]: a week, longer than any session on the
/// cell; NaN, infinities and negative values are refused.
pub const MAX_SECONDS: f64 = 7.0 * 86_400.0;

/// Parses a `--seconds` value: finite, > 0 and at most [`MAX_SECONDS`].
fn seconds_arg(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 && v <= MAX_SECONDS => Ok(v),
        _ => Err(format!("must be a number of seconds in (0, {MAX_SECONDS}], got {s}")),
    }
}

/// Exit code of a run or sweep in which a run ended with outcome `error` (diverged physics, a
/// device fault): everything was written, but not every run completed. Distinct from 1 (nothing
/// or not everything could be done: bad input, a write error) so scripts can tell them apart.
pub const EXIT_RUN_ERROR: u8 = 3;

/// The exit code of a command that ran scenarios: `128 + signal` if an operator stop ended it,
/// [`EXIT_RUN_ERROR`] if a run ended in error, else success.
fn exit_for_runs(any_error: bool) -> ExitCode {
    match tendril_cell::interrupt::requested() {
        Some(signal) => ExitCode::from(tendril_cell::interrupt::exit_code(signal)),
        None if any_error => ExitCode::from(EXIT_RUN_ERROR),
        None => ExitCode::SUCCESS,
    }
}

/// Exit code for a list of pass/fail verdicts: success only when all pass.
fn exit_all(pass: bool) -> ExitCode {
    if pass { ExitCode::SUCCESS } else { ExitCode::FAILURE }
}

/// `error: cause: cause ...`, leaving out a cause whose text the message before it already ends
/// with (errors that print their source in their own message, as `{file}: cannot read: {source}`
/// does, would otherwise say it twice).
fn error_chain(e: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in e.chain() {
        let cause = cause.to_string();
        if text.ends_with(&cause) {
            continue;
        }
        if !text.is_empty() {
            text.push_str(": ");
        }
        text.push_str(&cause);
    }
    text
}
