//! The TCP side of the virtual devices: RTDE, the script ports ([`super::primary`]), the dashboard,
//! HYPERION commands and stream.

use super::config::{ServeConfig, UrAddrs};
use super::dashboard::answer;
use super::jitter::{Held, Link};
use super::primary::{self, ScriptPort};
use super::state::{DeviceState, lock};
use std::net::SocketAddr;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use tendril_rtde::dashboard::{Command, GREETING};
use tendril_rtde::{ServerConfig, ServerSession};
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::{TcpListener, TcpStream};
use tokio::sync::watch;

/// A client sending more than this without completing a frame is dropped [bytes].
const MAX_PENDING: usize = 1 << 20;

type Shared = Arc<Mutex<DeviceState>>;

/// Binds the listeners and spawns their accept loops; returns the bound addresses.
pub async fn listen_all(
    c: &ServeConfig,
    state: Shared,
    ticks: watch::Receiver<u64>,
    epoch: Instant,
) -> anyhow::Result<([SocketAddr; 4], UrAddrs)> {
    let bind = |port| async move {
        TcpListener::bind(SocketAddr::new(c.bind, port))
            .await
            .map_err(|e| anyhow::anyhow!("cannot listen on {}:{port}: {e}", c.bind))
    };
    let rtde = bind(c.rtde_port).await?;
    let script = bind(c.script_port).await?;
    let command = bind(c.command_port).await?;
    let stream = bind(c.stream_port).await?;
    let dashboard = bind(c.dashboard_port).await?;
    let realtime_script = bind(c.realtime_script_port).await?;
    let primary = bind(c.primary_port).await?;
    let addrs = [rtde.local_addr()?, script.local_addr()?, command.local_addr()?, stream.local_addr()?];
    let ur_addrs = UrAddrs {
        dashboard: dashboard.local_addr()?,
        realtime_script: realtime_script.local_addr()?,
        primary: primary.local_addr()?,
    };
    // The program's sockets run on this runtime.
    lock(&state).sockets.attach(tokio::runtime::Handle::current(), c.script_hosts.clone());
    let (idle, jitter) = (c.idle_timeout, c.jitter);
    {
        let (state, ticks) = (state.clone(), ticks.clone());
        tokio::spawn(accept(rtde, move |s| {
            let links = (Held::new(jitter, Link::RtdeIn, epoch), Held::new(jitter, Link::RtdeOut, epoch));
            serve_rtde(s, state.clone(), ticks.clone(), idle, links)
        }));
    }
    for (listener, port) in
        [(primary, ScriptPort::Primary), (script, ScriptPort::Secondary), (realtime_script, ScriptPort::RealTime)]
    {
        let (state, ticks) = (state.clone(), ticks.clone());
        tokio::spawn(accept(listener, move |s| primary::serve(s, port, state.clone(), ticks.clone())));
    }
    {
        let state = state.clone();
        tokio::spawn(accept(dashboard, move |s| serve_dashboard(s, state.clone(), idle)));
    }
    {
        let state = state.clone();
        tokio::spawn(accept(command, move |s| serve_commands(s, state.clone(), idle)));
    }
    tokio::spawn(accept(stream, move |s| {
        serve_stream(s, state.clone(), ticks.clone(), Held::new(jitter, Link::Peaks, epoch))
    }));
    Ok((addrs, ur_addrs))
}

async fn accept<F, Fut>(listener: TcpListener, handler: F)
where
    F: Fn(TcpStream) -> Fut,
    Fut: std::future::Future<Output = ()> + Send + 'static,
{
    loop {
        match listener.accept().await {
            Ok((socket, _)) => {
                let _ = socket.set_nodelay(true);
                tokio::spawn(handler(socket));
            }
            // Out of descriptors and the like: back off instead of spinning.
            Err(_) => tokio::time::sleep(Duration::from_millis(50)).await,
        }
    }
}

/// One RTDE connection: replies to requests; data packages on each twin tick while started.
/// Closed after `idle` with nothing received or sent (a started session sends every tick).
/// `links` hold back what arrives and what is sent, when jitter is injected.
async fn serve_rtde(
    mut socket: TcpStream,
    state: Shared,
    mut ticks: watch::Receiver<u64>,
    idle: Duration,
    links: (Held<Vec<u8>>, Held<Vec<u8>>),
) {
    let id = {
        let mut s = lock(&state);
        s.next_session += 1;
        s.next_session
    };
    let (mut arriving, mut leaving) = links;
    let mut session = ServerSession::new(id, ServerConfig::default());
    let mut buf = Vec::new();
    let mut chunk = vec![0u8; 16 * 1024];
    let mut last_activity = tokio::time::Instant::now();
    loop {
        let out = tokio::select! {
            () = tokio::time::sleep_until(last_activity + idle) => break,
            r = socket.read(&mut chunk) => match r {
                Ok(n) if n > 0 => {
                    last_activity = tokio::time::Instant::now();
                    match arriving.push(chunk[..n].to_vec()) {
                        Some(bytes) => match feed(&mut session, &mut buf, &bytes, &state) {
                            Some(out) => out,
                            None => break, // malformed or oversized: close, as the controller does
                        },
                        None => Vec::new(),
                    }
                }
                _ => break,
            },
            () = sleep_until(arriving.next_release()), if arriving.next_release().is_some() => {
                let mut out = Vec::new();
                for bytes in arriving.due() {
                    match feed(&mut session, &mut buf, &bytes, &state) {
                        Some(more) => out.extend(more),
                        None => return lock(&state).inputs.release(id),
                    }
                }
                out
            }
            changed = ticks.changed() => {
                if changed.is_err() {
                    break;
                }
                let s = lock(&state);
                let now = s.outputs.timestamp_s;
                let packets = session.poll_outputs(now, &s.outputs, &s.inputs);
                let mut out = Vec::new();
                for p in packets {
                    if let Ok(bytes) = p.encode() {
                        out.extend_from_slice(&bytes);
                    }
                }
                if out.is_empty() { out } else { leaving.push(out).unwrap_or_default() }
            }
            () = sleep_until(leaving.next_release()), if leaving.next_release().is_some() => {
                leaving.due().concat()
            }
        };
        if !out.is_empty() {
            if socket.write_all(&out).await.is_err() {
                break;
            }
            last_activity = tokio::time::Instant::now();
        }
    }
    lock(&state).inputs.release(id);
}

/// Feeds bytes an RTDE client sent to its session; the replies, or `None` when the input is
/// malformed or a frame grows past [`MAX_PENDING`].
fn feed(session: &mut ServerSession, buf: &mut Vec<u8>, bytes: &[u8], state: &Shared) -> Option<Vec<u8>> {
    buf.extend_from_slice(bytes);
    let mut s = lock(state);
    let before = s.inputs.packages;
    let fed = session.feed(buf, &mut s.inputs);
    if s.inputs.packages != before {
        let s = &mut *s;
        s.program_inputs.arrived(&s.inputs);
    }
    match fed {
        Ok(out) if buf.len() <= MAX_PENDING => Some(out),
        _ => None,
    }
}

/// Sleeps until `at` (never returns when there is nothing held: the `select!` guard keeps it off).
async fn sleep_until(at: Option<Instant>) {
    match at {
        Some(at) => tokio::time::sleep_until(tokio::time::Instant::from_std(at)).await,
        None => std::future::pending().await,
    }
}

/// Longest dashboard command line accepted [bytes].
const MAX_DASHBOARD_LINE: usize = 4096;

/// The dashboard server: a greeting, then one reply line per command line; `quit`, a line longer
/// than [`MAX_DASHBOARD_LINE`] or `idle` without a byte closes the connection.
async fn serve_dashboard(mut socket: TcpStream, state: Shared, idle: Duration) {
    if socket.write_all(format!("{GREETING}\n").as_bytes()).await.is_err() {
        return;
    }
    let mut buf = Vec::new();
    let mut chunk = [0u8; 1024];
    loop {
        match tokio::time::timeout(idle, socket.read(&mut chunk)).await {
            Ok(Ok(n)) if n > 0 => buf.extend_from_slice(&chunk[..n]),
            _ => return,
        }
        while let Some(end) = buf.iter().position(|&b| b == b'\n') {
            let line: Vec<u8> = buf.drain(..=end).collect();
            let command = Command::parse(&String::from_utf8_lossy(&line[..end]));
            let (text, close) = {
                let mut s = lock(&state);
                let now = s.status.time_s;
                answer(&command, &mut s, now)
            };
            if socket.write_all(format!("{text}\n").as_bytes()).await.is_err() || close {
                return;
            }
        }
        if buf.len() > MAX_DASHBOARD_LINE {
            return;
        }
    }
}

/// HYPERION commands: one reply per request; a malformed request, or `idle` without a byte,
/// closes the connection.
async fn serve_commands(mut socket: TcpStream, state: Shared, idle: Duration) {
    let mut buf = Vec::new();
    let mut chunk = [0u8; 4096];
    loop {
        match tokio::time::timeout(idle, socket.read(&mut chunk)).await {
            Ok(Ok(n)) if n > 0 => buf.extend_from_slice(&chunk[..n]),
            _ => return,
        }
        let reply = lock(&state).interrogator.feed(&mut buf);
        match reply {
            Ok(out) => {
                if !out.is_empty() && socket.write_all(&out).await.is_err() {
                    return;
                }
            }
            Err(_) => return,
        }
    }
}

/// HYPERION peak stream: after each twin tick, every scan since the last one sent (a reader that
/// keeps up gets consecutive serial numbers; one more than the backlog behind loses the oldest).
/// `leaving` holds frames back when jitter is injected.
async fn serve_stream(
    mut socket: TcpStream,
    state: Shared,
    mut ticks: watch::Receiver<u64>,
    mut leaving: Held<Vec<u8>>,
) {
    let mut sent = None;
    loop {
        let bytes = tokio::select! {
            changed = ticks.changed() => {
                if changed.is_err() {
                    return;
                }
                let bytes = {
                    let s = lock(&state);
                    s.interrogator.stream_after(sent)
                };
                match bytes {
                    Ok((bytes, last)) => {
                        sent = last;
                        if bytes.is_empty() { bytes } else { leaving.push(bytes).unwrap_or_default() }
                    }
                    Err(_) => return,
                }
            }
            () = sleep_until(leaving.next_release()), if leaving.next_release().is_some() => leaving.due().concat(),
        };
        if !bytes.is_empty() && socket.write_all(&bytes).await.is_err() {
            return;
        }
    }
}
