//! UR5e driver: RTDE client on 30004 (thin async IO over the sans-IO [`ClientSession`]) and the
//! motion program upload on 30002.
//!
//! A reader task decodes the 500 Hz output stream into the latest [`ArmSample`]; the control
//! thread writes the targets and the enable flag as one input data package per tick, without
//! waiting on the socket ([`UrClient::try_send`]).

use super::tcp;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use tendril_rtde::{ClientEvent, ClientSession, RtdeValue};
use tendril_urscript as urscript;
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::tcp::OwnedWriteHalf;

/// Output fields requested, in recipe order (the names [`ArmSample`] is decoded from).
pub const OUTPUT_NAMES: [&str; 8] = [
    "timestamp",
    "actual_q",
    "actual_qd",
    "actual_TCP_pose",
    "robot_mode",
    "safety_mode",
    "runtime_state",
    "actual_TCP_force",
];

/// RTDE output rate \[Hz\]: the e-Series maximum.
pub const OUTPUT_RATE_HZ: f64 = 500.0;

/// Input bytes the socket may hold back before the controller counts as not reading: about 30
/// ticks' packages.
const MAX_UNSENT: usize = 2048;

/// How long each set-up reply may take.
const SETUP_TIMEOUT: Duration = Duration::from_secs(3);

/// One decoded output package.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArmSample {
    /// Controller time \[s\].
    pub timestamp_s: f64,
    /// Joint positions \[rad\].
    pub q: [f64; 6],
    /// Joint velocities [rad/s].
    pub qd: [f64; 6],
    /// TCP pose (m, rotation vector rad).
    pub tcp_pose: [f64; 6],
    /// Robot mode (7 running).
    pub robot_mode: i32,
    /// Safety mode (1 normal).
    pub safety_mode: i32,
    /// Runtime state (2 playing).
    pub runtime_state: u32,
    /// The external wrench on the tool, base frame (N, N·m), the payload compensated.
    pub tcp_force: [f64; 6],
}

impl ArmSample {
    /// The vertical load the tool carries \[N\], positive downward: minus the z component of
    /// the external force on the tool ([`tendril_cell::CellState::tool_load_n`]).
    pub fn tool_load_n(&self) -> f64 {
        -self.tcp_force[2]
    }
}

/// The reader task's view: the latest sample, when it arrived, and the error that ended the stream.
#[derive(Debug, Default)]
pub struct ArmFeed {
    /// Latest sample and its arrival time.
    pub latest: Option<(ArmSample, Instant)>,
    /// Why the stream ended, if it did.
    pub closed: Option<String>,
    /// The tool's load over the samples since it was last taken ([`UrClient::take_tool_load`]).
    pub load: LoadMean,
}

/// The mean of the tool's load over the samples since it was last taken: a control tick reads the
/// mean of the (five, at 100 Hz) samples the 500 Hz stream brought since the last tick.
#[derive(Debug, Default, Clone, Copy)]
pub struct LoadMean {
    sum_n: f64,
    count: u32,
    last_n: Option<f64>,
}

impl LoadMean {
    /// Adds one sample's load \[N\].
    pub fn add(&mut self, load_n: f64) {
        self.sum_n += load_n;
        self.count += 1;
    }

    /// The mean since the last take (the last mean again when no sample came since), and starts
    /// anew.
    pub fn take(&mut self) -> Option<f64> {
        if self.count > 0 {
            self.last_n = Some(self.sum_n / f64::from(self.count));
            (self.sum_n, self.count) = (0.0, 0);
        }
        self.last_n
    }
}

/// A connected, started RTDE session.
pub struct UrClient {
    session: ClientSession,
    writer: OwnedWriteHalf,
    input_recipe: u8,
    /// Input bytes the socket has not taken yet (sent first next time, so packages stay whole).
    unsent: Vec<u8>,
    /// Shared with the reader task.
    pub feed: Arc<Mutex<ArmFeed>>,
    reader: tokio::task::JoinHandle<()>,
}

fn err(cause: impl std::fmt::Display) -> String {
    format!("RTDE: {cause}")
}

impl UrClient {
    /// Connects, negotiates version 2, sets up the output and input recipes and starts streaming.
    pub async fn connect(addr: &str) -> Result<UrClient, String> {
        let stream = tcp::connect(addr, SETUP_TIMEOUT).await.map_err(err)?;
        let (mut reader, mut writer) = stream.into_split();
        let mut session = ClientSession::new();
        let mut buf = Vec::new();

        let packet = session.request_protocol_version();
        let ev = request(&mut session, &mut reader, &mut writer, &mut buf, packet.encode().map_err(err)?).await?;
        if ev != (ClientEvent::ProtocolVersion { accepted: true }) {
            return Err(err("protocol version 2 refused"));
        }
        let packet = session.request_controller_version();
        request(&mut session, &mut reader, &mut writer, &mut buf, packet.encode().map_err(err)?).await?;
        let packet = session.setup_outputs(OUTPUT_RATE_HZ, &OUTPUT_NAMES).map_err(err)?;
        let ev = request(&mut session, &mut reader, &mut writer, &mut buf, packet.encode().map_err(err)?).await?;
        let output_recipe = match ev {
            ClientEvent::OutputRecipe(r) => r.id,
            other => return Err(err(format!("unexpected reply to output setup: {other:?}"))),
        };
        let names = urscript::input_names();
        let refs: Vec<&str> = names.iter().map(String::as_str).collect();
        let packet = session.setup_inputs(&refs).map_err(err)?;
        let ev = request(&mut session, &mut reader, &mut writer, &mut buf, packet.encode().map_err(err)?).await?;
        let input_recipe = match ev {
            ClientEvent::InputRecipe(r) => r.id,
            other => return Err(err(format!("unexpected reply to input setup: {other:?}"))),
        };
        let mut client_session = session.clone();
        let packet = session.start();
        let ev = request(&mut session, &mut reader, &mut writer, &mut buf, packet.encode().map_err(err)?).await?;
        if ev != (ClientEvent::Started { accepted: true }) {
            return Err(err("start refused"));
        }
        client_session.handle(tendril_rtde::ServerPacket::Start { accepted: true }).map_err(err)?;
        let feed = Arc::new(Mutex::new(ArmFeed::default()));
        let reader = tokio::spawn(read_outputs(reader, buf, client_session, output_recipe, feed.clone()));
        Ok(UrClient { session, writer, input_recipe, unsent: Vec::with_capacity(MAX_UNSENT), feed, reader })
    }

    /// Writes the six targets \[rad\], their time on the client's clock `stamp_s` \[s\] and the
    /// enable flag in one data package and waits until the socket took it (and anything held back
    /// before it).
    pub async fn send(&mut self, q: [f64; 6], stamp_s: f64, enable: bool) -> Result<(), String> {
        self.queue(q, stamp_s, enable)?;
        self.writer.write_all(&self.unsent).await.map_err(err)?;
        self.unsent.clear();
        Ok(())
    }

    /// Writes the package without waiting: what the socket does not take now is held back and
    /// goes first next time. Fails if the controller stops reading (more than 2 KiB
    /// held back) or the connection broke.
    pub fn try_send(&mut self, q: [f64; 6], stamp_s: f64, enable: bool) -> Result<(), String> {
        self.queue(q, stamp_s, enable)?;
        while !self.unsent.is_empty() {
            match self.writer.try_write(&self.unsent) {
                Ok(n) => drop(self.unsent.drain(..n)),
                Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => break,
                Err(e) => return Err(err(e)),
            }
        }
        if self.unsent.len() > MAX_UNSENT {
            return Err(err(format!("controller not reading: {} input bytes held back", self.unsent.len())));
        }
        Ok(())
    }

    /// Appends the input data package for `q`, `stamp_s` and `enable` to the bytes to send (in
    /// [`urscript::input_names`] order).
    fn queue(&mut self, q: [f64; 6], stamp_s: f64, enable: bool) -> Result<(), String> {
        let mut values: Vec<RtdeValue> = q.iter().map(|&v| RtdeValue::Double(v)).collect();
        values.push(RtdeValue::Double(stamp_s));
        values.push(RtdeValue::Int32(i32::from(enable)));
        let packet = self.session.input_data(self.input_recipe, &values).map_err(err)?;
        self.unsent.extend_from_slice(&packet.encode().map_err(err)?);
        Ok(())
    }

    /// The mean tool load \[N\] of the samples since the last call ([`LoadMean::take`]).
    pub fn take_tool_load(&self) -> Option<f64> {
        self.feed.lock().unwrap_or_else(|p| p.into_inner()).load.take()
    }

    /// The latest sample and its age, or why the stream ended.
    pub fn latest(&self) -> Result<Option<(ArmSample, Duration)>, String> {
        let feed = self.feed.lock().unwrap_or_else(|p| p.into_inner());
        if let Some(why) = &feed.closed {
            return Err(err(why));
        }
        Ok(feed.latest.map(|(s, at)| (s, at.elapsed())))
    }
}

impl Drop for UrClient {
    fn drop(&mut self) {
        self.reader.abort();
    }
}

/// Sends one request and waits for its reply (text messages in between are skipped).
async fn request(
    session: &mut ClientSession,
    reader: &mut tokio::net::tcp::OwnedReadHalf,
    writer: &mut OwnedWriteHalf,
    buf: &mut Vec<u8>,
    bytes: Vec<u8>,
) -> Result<ClientEvent, String> {
    writer.write_all(&bytes).await.map_err(err)?;
    let deadline = tokio::time::Instant::now() + SETUP_TIMEOUT;
    loop {
        let mut events = session.feed(buf).map_err(err)?.into_iter();
        if let Some(ev) = events.find(|e| !matches!(e, ClientEvent::Message(_) | ClientEvent::Data { .. })) {
            return Ok(ev);
        }
        let mut chunk = [0u8; 4096];
        let n = tokio::time::timeout_at(deadline, reader.read(&mut chunk))
            .await
            .map_err(|_| err("no reply within 3 s"))?
            .map_err(err)?;
        if n == 0 {
            return Err(err("controller closed the connection"));
        }
        buf.extend_from_slice(&chunk[..n]);
    }
}

/// The reader task: decodes data packages until the stream ends.
async fn read_outputs(
    mut reader: tokio::net::tcp::OwnedReadHalf,
    mut buf: Vec<u8>,
    mut session: ClientSession,
    recipe: u8,
    feed: Arc<Mutex<ArmFeed>>,
) {
    let mut chunk = vec![0u8; 64 * 1024];
    let why = loop {
        match session.feed(&mut buf) {
            Ok(events) => {
                let samples: Vec<ArmSample> = events
                    .into_iter()
                    .filter_map(|e| match e {
                        ClientEvent::Data { recipe_id, values } if recipe_id == recipe => decode_sample(&values),
                        _ => None,
                    })
                    .collect();
                if let Some(s) = samples.last() {
                    let mut feed = feed.lock().unwrap_or_else(|p| p.into_inner());
                    for sample in &samples {
                        feed.load.add(sample.tool_load_n());
                    }
                    feed.latest = Some((*s, Instant::now()));
                }
            }
            Err(e) => break e.to_string(),
        }
        match reader.read(&mut chunk).await {
            Ok(0) => break "controller closed the connection".to_string(),
            Ok(n) => buf.extend_from_slice(&chunk[..n]),
            Err(e) => break e.to_string(),
        }
    };
    feed.lock().unwrap_or_else(|p| p.into_inner()).closed = Some(why);
}

/// Values in [`OUTPUT_NAMES`] order to a sample; `None` if the types differ.
pub fn decode_sample(values: &[RtdeValue]) -> Option<ArmSample> {
    use RtdeValue::*;
    match values {
        [
            Double(t),
            Vector6d(q),
            Vector6d(qd),
            Vector6d(pose),
            Int32(mode),
            Int32(safety),
            Uint32(runtime),
            Vector6d(force),
        ] => Some(ArmSample {
            timestamp_s: *t,
            q: *q,
            qd: *qd,
            tcp_pose: *pose,
            robot_mode: *mode,
            safety_mode: *safety,
            runtime_state: *runtime,
            tcp_force: *force,
        }),
        _ => None,
    }
}

/// Sends the motion program to the secondary interface (30002) and closes the connection.
pub async fn upload_program(addr: &str, program: &str) -> Result<(), String> {
    let mut stream = tcp::connect(addr, SETUP_TIMEOUT).await.map_err(|e| format!("URScript {e}"))?;
    stream.write_all(program.as_bytes()).await.map_err(|e| format!("URScript {addr}: {e}"))?;
    if !program.ends_with('\n') {
        stream.write_all(b"\n").await.map_err(|e| format!("URScript {addr}: {e}"))?;
    }
    stream.shutdown().await.map_err(|e| format!("URScript {addr}: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sample_decodes_in_recipe_order_and_its_tool_load_is_minus_the_force_z() {
        use RtdeValue::*;
        let values = [
            Double(1.5),
            Vector6d([0.1; 6]),
            Vector6d([0.0; 6]),
            Vector6d([0.2; 6]),
            Int32(7),
            Int32(1),
            Uint32(2),
            Vector6d([0.5, -0.2, -3.44, 0.0, 0.0, 0.0]),
        ];
        assert_eq!(values.len(), OUTPUT_NAMES.len());
        let s = decode_sample(&values).unwrap();
        assert_eq!((s.timestamp_s, s.robot_mode, s.runtime_state), (1.5, 7, 2));
        assert_eq!(s.tool_load_n(), 3.44);
        // A recipe without the force (an older set-up) does not decode.
        assert_eq!(decode_sample(&values[..7]), None);
    }

    #[test]
    fn a_tick_takes_the_mean_load_of_the_samples_since_the_last_and_holds_it_when_none_came() {
        let mut m = LoadMean::default();
        assert_eq!(m.take(), None);
        for load in [3.0, 3.5, 4.0, 3.5, 3.0] {
            m.add(load);
        }
        assert_eq!(m.take(), Some(3.4));
        assert_eq!(m.take(), Some(3.4));
        m.add(1.0);
        assert_eq!(m.take(), Some(1.0));
    }
}
