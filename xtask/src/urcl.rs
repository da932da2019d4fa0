//! `cargo xtask urcl PATH-TO-LIBRARY [--out DIR] [--only NAME,...]`: Universal Robots' own client
//! library (`Universal_Robots_Client_Library`, a checkout you got yourself) against `tendril
//! serve`, as a lab would run it against URSim.
//!
//! 1. Builds the library and its examples with CMake into `target/urcl/build` (needs `cmake` and
//!    a C++17 compiler; the checkout itself is not written to).
//! 2. Builds `tendril` and starts `tendril serve scenarios/short-lift.toml` on the controller's own
//!    ports (29999, 30001-30004; the examples also open 50001-50004 on this machine): all must be
//!    free.
//! 3. Runs each example of [`EXAMPLES`] against 127.0.0.1 from the checkout (they read
//!    `resources/` and `examples/resources/` relative to it), one after the other, each with its
//!    time limit; meanwhile an RTDE client of our own records the served joints at 125 Hz.
//! 4. Reports each example as **worked** (exit 0, no `ERROR` line), **refused** (the virtual
//!    controller stopped its program with a refusal, as a controller refuses what it cannot do) or
//!    **failed** (anything else: its log tells why), with how far the arm moved, how far it
//!    lagged its setpoint and where it ended; writes each example's log and joint trace, and a
//!    `summary.csv`, to `--out` (default `target/urcl/results`).

use crate::rtde_trace::{self, Recorder};
use std::io::{BufRead, BufReader};
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// An example: its executable, its arguments after the robot's IP, its time limit \[s\].
pub struct Example {
    /// Name in the library's `examples/` (its source file's stem).
    pub name: &'static str,
    /// The executable CMake builds.
    pub binary: &'static str,
    /// Arguments after the IP: seconds to run, where the example takes them.
    pub args: &'static [&'static str],
    /// Time limit \[s\].
    pub limit_s: u64,
}

/// The examples the check runs, in order (the arm's pose carries over from one to the next).
pub const EXAMPLES: &[Example] = &[
    Example { name: "dashboard_example", binary: "dashboard_example", args: &[], limit_s: 60 },
    Example { name: "rtde_client", binary: "rtde_client_example", args: &["5"], limit_s: 30 },
    Example { name: "primary_pipeline", binary: "primary_pipeline_example", args: &["3"], limit_s: 30 },
    Example {
        name: "primary_pipeline_calibration",
        binary: "primary_pipeline_calibration_example",
        args: &[],
        limit_s: 30,
    },
    Example { name: "full_driver", binary: "driver_example", args: &[], limit_s: 90 },
    Example {
        name: "trajectory_point_interface",
        binary: "trajectory_point_interface_example",
        args: &[],
        limit_s: 120,
    },
    Example { name: "spline_example", binary: "spline_example", args: &[], limit_s: 120 },
    Example {
        name: "script_command_interface",
        binary: "script_command_interface_example",
        args: &["20"],
        limit_s: 60,
    },
    Example { name: "instruction_executor", binary: "instruction_executor", args: &[], limit_s: 240 },
    Example { name: "send_script", binary: "send_script", args: &[], limit_s: 60 },
    Example { name: "script_sender", binary: "script_sender_example", args: &["3"], limit_s: 30 },
    Example { name: "freedrive_example", binary: "freedrive_example", args: &["5"], limit_s: 60 },
    Example { name: "force_mode_example", binary: "force_mode_example", args: &["5"], limit_s: 60 },
    Example { name: "tool_contact_example", binary: "tool_contact_example", args: &["5"], limit_s: 60 },
];

/// The ports the controller and the examples use on this machine.
const PORTS: [u16; 9] = [29999, 30001, 30002, 30003, 30004, 50001, 50002, 50003, 50004];

/// What `tendril serve` prints when it stops an uploaded program for something it does not do.
const REFUSAL: &str = "is not supported by the virtual controller";

/// How an example ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Verdict {
    /// It ran to its end without an error.
    Worked,
    /// The virtual controller refused what it asked (the reason).
    Refused(String),
    /// Anything else (the reason).
    Failed(String),
}

impl Verdict {
    fn word(&self) -> &'static str {
        match self {
            Verdict::Worked => "worked",
            Verdict::Refused(_) => "refused",
            Verdict::Failed(_) => "failed",
        }
    }
}

/// Runs the check (`args`: the library's path, then options).
pub fn run(root: &Path, tendril: &Path, args: &[String]) -> Result<(), String> {
    let (library, out, only) = parse_args(root, args)?;
    for (tool, why) in [("cmake", "apt-get install cmake"), ("c++", "a C++17 compiler, e.g. apt-get install g++")] {
        let found = Command::new(tool).arg("--version").stdout(Stdio::null()).stderr(Stdio::null()).status();
        if !found.is_ok_and(|s| s.success()) {
            return Err(format!("`{tool}` not found: the check builds UR's library with CMake ({why})"));
        }
    }
    if !library.join("CMakeLists.txt").is_file() || !library.join("resources/external_control.urscript").is_file() {
        return Err(format!(
            "{} is not a checkout of Universal_Robots_Client_Library (no CMakeLists.txt or \
             resources/external_control.urscript)",
            library.display()
        ));
    }
    let build = root.join("target/urcl/build");
    eprintln!("urcl: building the library and its examples into {}", build.display());
    crate::run(
        Command::new("cmake")
            .arg("-S")
            .arg(&library)
            .arg("-B")
            .arg(&build)
            .arg("-DCMAKE_BUILD_TYPE=Release")
            .stdout(Stdio::null()),
    )?;
    crate::run(Command::new("cmake").arg("--build").arg(&build).args(["--parallel", "2"]).stdout(Stdio::null()))?;
    for port in PORTS {
        TcpListener::bind(("127.0.0.1", port)).map_err(|e| {
            format!("port {port} is taken ({e}): stop what uses it (a URSim, another `tendril serve`) first")
        })?;
    }
    std::fs::create_dir_all(&out).map_err(|e| format!("{}: {e}", out.display()))?;
    let mut serve = Serve::start(root, tendril)?;
    let recorder = Recorder::start("127.0.0.1:30004")?;
    let mut rows = Vec::new();
    for example in EXAMPLES.iter().filter(|e| only.as_ref().is_none_or(|o| o.iter().any(|n| n == e.name))) {
        let binary = build.join("examples").join(example.binary);
        eprintln!("urcl: {} ...", example.name);
        recorder.take();
        let seen = serve.lines().len();
        let started = Instant::now();
        let (verdict, log) = run_example(&library, &binary, example, &serve)?;
        let seconds = started.elapsed().as_secs_f64();
        let samples = recorder.take();
        std::fs::write(out.join(format!("{}.log", example.name)), &log).map_err(|e| e.to_string())?;
        std::fs::write(out.join(format!("{}.csv", example.name)), rtde_trace::csv(&samples))
            .map_err(|e| e.to_string())?;
        let serve_lines = serve.lines()[seen..].join("\n");
        let verdict = match verdict {
            Verdict::Worked | Verdict::Failed(_) if serve_lines.contains(REFUSAL) => Verdict::Refused(
                serve_lines.lines().find(|l| l.contains(REFUSAL)).unwrap_or_default().trim().to_string(),
            ),
            v => v,
        };
        let motion = rtde_trace::motion(&samples);
        eprintln!(
            "urcl: {:<28} {:<8} {:>6.1} s{}",
            example.name,
            verdict.word(),
            seconds,
            motion
                .map_or(String::new(), |m| format!("  travel {:.3} rad, lag ≤ {:.4} rad", m.travel_rad, m.max_lag_rad))
        );
        rows.push((example.name, verdict, seconds, motion));
    }
    recorder.stop()?;
    serve.stop();
    let mut summary = String::from("example,verdict,seconds,travel_rad,max_lag_rad,last_q,reason\n");
    println!("\n{:<28} {:<8} {:>7} {:>11} {:>11}  reason", "example", "verdict", "seconds", "travel/rad", "lag/rad");
    for (name, verdict, seconds, motion) in &rows {
        let reason = match verdict {
            Verdict::Worked => String::new(),
            Verdict::Refused(r) | Verdict::Failed(r) => r.replace(',', ";"),
        };
        let (travel, lag, last) = motion.map_or((f64::NAN, f64::NAN, String::new()), |m| {
            (m.travel_rad, m.max_lag_rad, m.last_q.map(|q| format!("{q:.4}")).join(" "))
        });
        println!("{name:<28} {:<8} {seconds:>7.1} {travel:>11.3} {lag:>11.4}  {reason}", verdict.word());
        summary.push_str(&format!("{name},{},{seconds:.1},{travel:.4},{lag:.5},{last},{reason}\n", verdict.word()));
    }
    std::fs::write(out.join("summary.csv"), summary).map_err(|e| e.to_string())?;
    println!("\nlogs, joint traces (125 Hz) and summary.csv in {}", out.display());
    let failed = rows.iter().filter(|r| matches!(r.1, Verdict::Failed(_))).count();
    if failed > 0 { Err(format!("{failed} example(s) failed")) } else { Ok(()) }
}

type Options = (PathBuf, PathBuf, Option<Vec<String>>);

fn parse_args(root: &Path, args: &[String]) -> Result<Options, String> {
    let usage = "usage: cargo xtask urcl PATH-TO-LIBRARY [--out DIR] [--only NAME,...]";
    let (mut library, mut out, mut only) = (None, root.join("target/urcl/results"), None);
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--out" => out = PathBuf::from(it.next().ok_or(usage)?),
            "--only" => only = Some(it.next().ok_or(usage)?.split(',').map(String::from).collect::<Vec<_>>()),
            path if library.is_none() && !path.starts_with("--") => library = Some(PathBuf::from(path)),
            other => return Err(format!("unexpected argument {other:?}\n{usage}")),
        }
    }
    let library = library.ok_or(usage)?;
    let library = library.canonicalize().map_err(|e| format!("{}: {e}", library.display()))?;
    if let Some(names) = &only {
        for n in names {
            if !EXAMPLES.iter().any(|e| e.name == n) {
                let known: Vec<&str> = EXAMPLES.iter().map(|e| e.name).collect();
                return Err(format!("--only: no example {n:?} (known: {})", known.join(", ")));
            }
        }
    }
    Ok((library, out, only))
}

/// Runs one example from the library's folder within its time limit; its verdict from its own
/// ending, and its output.
fn run_example(library: &Path, binary: &Path, example: &Example, serve: &Serve) -> Result<(Verdict, String), String> {
    let mut child = Command::new(binary)
        .arg("127.0.0.1")
        .args(example.args)
        .current_dir(library)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("{}: {e}", binary.display()))?;
    let output = collect(&mut child);
    let deadline = Instant::now() + Duration::from_secs(example.limit_s);
    let status = loop {
        if let Some(status) = child.try_wait().map_err(|e| e.to_string())? {
            break Some(status);
        }
        if Instant::now() > deadline || !serve.running() {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let log = output.join().unwrap_or_default();
    let error = log.lines().find(|l| l.contains("ERROR")).map(str::trim);
    let verdict = match (status, error) {
        (None, _) if !serve.running() => Verdict::Failed("tendril serve stopped".into()),
        (None, _) => Verdict::Failed(format!("still running after {} s", example.limit_s)),
        (Some(s), _) if !s.success() => {
            Verdict::Failed(format!("exit {s}{}", error.map_or(String::new(), |e| format!(": {e}"))))
        }
        (Some(_), Some(e)) => Verdict::Failed(e.to_string()),
        (Some(_), None) => Verdict::Worked,
    };
    Ok((verdict, log))
}

/// Collects a child's stdout and stderr, interleaved by line, until both close.
fn collect(child: &mut Child) -> std::thread::JoinHandle<String> {
    let lines = Arc::new(Mutex::new(String::new()));
    let readers: Vec<_> = [
        child.stdout.take().map(|s| Box::new(s) as Box<dyn std::io::Read + Send>),
        child.stderr.take().map(|s| Box::new(s) as Box<dyn std::io::Read + Send>),
    ]
    .into_iter()
    .flatten()
    .map(|stream| {
        let lines = lines.clone();
        std::thread::spawn(move || {
            for line in BufReader::new(stream).lines().map_while(Result::ok) {
                let mut l = lines.lock().unwrap_or_else(|p| p.into_inner());
                l.push_str(&line);
                l.push('\n');
            }
        })
    })
    .collect();
    std::thread::spawn(move || {
        for r in readers {
            let _ = r.join();
        }
        lines.lock().unwrap_or_else(|p| p.into_inner()).clone()
    })
}

/// `tendril serve scenarios/short-lift.toml`, its output lines kept.
struct Serve {
    child: Child,
    lines: Arc<Mutex<Vec<String>>>,
}

impl Serve {
    fn start(root: &Path, tendril: &Path) -> Result<Serve, String> {
        let mut child = Command::new(tendril)
            .args(["serve", "scenarios/short-lift.toml"])
            .current_dir(root)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| format!("{}: {e}", tendril.display()))?;
        let lines = Arc::new(Mutex::new(Vec::new()));
        for stream in [
            child.stdout.take().map(|s| Box::new(s) as Box<dyn std::io::Read + Send>),
            child.stderr.take().map(|s| Box::new(s) as Box<dyn std::io::Read + Send>),
        ]
        .into_iter()
        .flatten()
        {
            let lines = lines.clone();
            std::thread::spawn(move || {
                for line in BufReader::new(stream).lines().map_while(Result::ok) {
                    lines.lock().unwrap_or_else(|p| p.into_inner()).push(line);
                }
            });
        }
        let serve = Serve { child, lines };
        let deadline = Instant::now() + Duration::from_secs(60);
        while !serve.lines().iter().any(|l| l.starts_with("tendril serve:")) {
            if Instant::now() > deadline || !serve.running() {
                return Err(format!("tendril serve did not start:\n{}", serve.lines().join("\n")));
            }
            std::thread::sleep(Duration::from_millis(100));
        }
        // The listeners are up once it prints its ports; the twin's first tick follows at once.
        std::thread::sleep(Duration::from_millis(500));
        Ok(serve)
    }

    fn lines(&self) -> Vec<String> {
        self.lines.lock().unwrap_or_else(|p| p.into_inner()).clone()
    }

    fn running(&self) -> bool {
        // `try_wait` needs `&mut`; a child that exited has closed its output, which the reader
        // threads see, but the status is what tells: look without reaping.
        std::fs::metadata(format!("/proc/{}", self.child.id())).is_ok()
            && !std::fs::read_to_string(format!("/proc/{}/stat", self.child.id()))
                .is_ok_and(|s| s.split_whitespace().nth(2) == Some("Z"))
    }

    fn stop(&mut self) {
        // SIGTERM: serve stops cleanly on it (it prints how long the twin ran).
        let _ = Command::new("kill").arg("-TERM").arg(self.child.id().to_string()).status();
        let _ = self.child.wait();
    }
}
