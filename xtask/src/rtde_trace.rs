//! A third RTDE client beside the ones UR's examples open: it records the served joints (target
//! and actual) at 125 Hz while each example runs, so `cargo xtask urcl` can tell whether the
//! twin's arm followed what the example commanded.

use std::io::{Read, Write};
use std::net::TcpStream;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;
use tendril_rtde::{ClientEvent, ClientSession, RtdeValue};

/// What is recorded, in recipe order.
const OUTPUTS: [&str; 4] = ["timestamp", "target_q", "actual_q", "runtime_state"];
/// Recording rate \[Hz\].
const FREQUENCY_HZ: f64 = 125.0;

/// One sample: controller time \[s\], target and actual joints \[rad\], runtime state.
#[derive(Debug, Clone, Copy)]
pub struct Sample {
    pub time_s: f64,
    pub target_q: [f64; 6],
    pub actual_q: [f64; 6],
    pub runtime_state: u32,
}

/// The recorder: samples go to `samples` until `stop` is set.
pub struct Recorder {
    pub samples: Arc<Mutex<Vec<Sample>>>,
    stop: Arc<AtomicBool>,
    thread: Option<std::thread::JoinHandle<Result<(), String>>>,
}

impl Recorder {
    /// Connects to RTDE at `addr` and records in the background.
    pub fn start(addr: &str) -> Result<Recorder, String> {
        let mut socket = TcpStream::connect(addr).map_err(|e| format!("RTDE at {addr}: {e}"))?;
        socket.set_read_timeout(Some(Duration::from_millis(200))).map_err(|e| e.to_string())?;
        let mut session = ClientSession::new();
        let mut buf = Vec::new();
        let mut ask =
            |session: &mut ClientSession, packet: tendril_rtde::ClientPacket| -> Result<ClientEvent, String> {
                socket.write_all(&packet.encode().map_err(|e| e.to_string())?).map_err(|e| e.to_string())?;
                loop {
                    let events = session.feed(&mut buf).map_err(|e| e.to_string())?;
                    if let Some(e) = events.into_iter().next() {
                        return Ok(e);
                    }
                    let mut chunk = [0u8; 4096];
                    let n = socket.read(&mut chunk).map_err(|e| format!("RTDE set-up: {e}"))?;
                    if n == 0 {
                        return Err("RTDE closed during set-up".into());
                    }
                    buf.extend_from_slice(&chunk[..n]);
                }
            };
        let version = session.request_protocol_version();
        ask(&mut session, version)?;
        let setup = session.setup_outputs(FREQUENCY_HZ, &OUTPUTS).map_err(|e| e.to_string())?;
        ask(&mut session, setup)?;
        let start = session.start();
        ask(&mut session, start)?;
        let (samples, stop) = (Arc::new(Mutex::new(Vec::new())), Arc::new(AtomicBool::new(false)));
        let (into, stopped) = (samples.clone(), stop.clone());
        let thread = std::thread::spawn(move || -> Result<(), String> {
            let mut chunk = [0u8; 16 * 1024];
            while !stopped.load(Ordering::SeqCst) {
                match socket.read(&mut chunk) {
                    Ok(0) => return Err("RTDE closed".into()),
                    Ok(n) => buf.extend_from_slice(&chunk[..n]),
                    Err(e) if matches!(e.kind(), std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut) => {
                        continue;
                    }
                    Err(e) => return Err(e.to_string()),
                }
                for event in session.feed(&mut buf).map_err(|e| e.to_string())? {
                    if let ClientEvent::Data { values, .. } = event
                        && let Some(s) = sample(&values)
                    {
                        into.lock().unwrap_or_else(|p| p.into_inner()).push(s);
                    }
                }
            }
            Ok(())
        });
        Ok(Recorder { samples, stop, thread: Some(thread) })
    }

    /// The samples since the last call.
    pub fn take(&self) -> Vec<Sample> {
        std::mem::take(&mut *self.samples.lock().unwrap_or_else(|p| p.into_inner()))
    }

    /// Stops recording; the recording thread's error, if it failed.
    pub fn stop(mut self) -> Result<(), String> {
        self.stop.store(true, Ordering::SeqCst);
        self.thread.take().map_or(Ok(()), |t| t.join().unwrap_or(Err("recorder panicked".into())))
    }
}

fn sample(values: &[RtdeValue]) -> Option<Sample> {
    match values {
        [RtdeValue::Double(t), RtdeValue::Vector6d(target), RtdeValue::Vector6d(actual), RtdeValue::Uint32(state)] => {
            Some(Sample { time_s: *t, target_q: *target, actual_q: *actual, runtime_state: *state })
        }
        _ => None,
    }
}

/// What a recording says about the arm: how far it moved, how far it was from its setpoint at
/// worst, where it ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Motion {
    /// Joint travel: every joint's path length added up \[rad\].
    pub travel_rad: f64,
    /// Largest distance between any joint's setpoint and its measured angle \[rad\].
    pub max_lag_rad: f64,
    /// The last measured joints \[rad\].
    pub last_q: [f64; 6],
}

/// The motion in `samples` (`None` if there are none).
pub fn motion(samples: &[Sample]) -> Option<Motion> {
    let last = samples.last()?;
    let travel_rad =
        samples.windows(2).map(|w| (0..6).map(|j| (w[1].actual_q[j] - w[0].actual_q[j]).abs()).sum::<f64>()).sum();
    let max_lag_rad =
        samples.iter().flat_map(|s| (0..6).map(move |j| (s.target_q[j] - s.actual_q[j]).abs())).fold(0.0, f64::max);
    Some(Motion { travel_rad, max_lag_rad, last_q: last.actual_q })
}

/// The samples as CSV: time, the six targets, the six measured joints, the runtime state.
pub fn csv(samples: &[Sample]) -> String {
    let mut out = String::from("time_s");
    for prefix in ["target_q", "actual_q"] {
        for j in 0..6 {
            out.push_str(&format!(",{prefix}{j}"));
        }
    }
    out.push_str(",runtime_state\n");
    for s in samples {
        out.push_str(&format!("{:.4}", s.time_s));
        for q in s.target_q.iter().chain(&s.actual_q) {
            out.push_str(&format!(",{q:.6}"));
        }
        out.push_str(&format!(",{}\n", s.runtime_state));
    }
    out
}
