//! The network side of the program's sockets (`socket_open` and the rest, [`tendril_urscript`]'s
//! [`Controller`](tendril_urscript::Controller) socket methods): each socket is a TCP client on
//! the devices' tokio runtime; the program, on the twin thread, only looks at what its task has
//! put in the socket's buffers, so a read waiting for bytes never holds up the twin.
//!
//! - **Hosts**: loopback (127.0.0.0/8, ::1, `localhost`) always; other addresses only when
//!   `tendril serve --allow-host ADDRESS` names them ([`crate::ServeConfig::script_hosts`]).
//!   Anything else, or a host name other than `localhost` (the virtual controller resolves no
//!   names), is refused: the program stops with the line and the reason.
//! - **Limits**: [`MAX_SOCKETS`] open at once, [`MAX_OPENS_PER_S`] `socket_open` calls per second
//!   of twin time, [`MAX_BUFFERED`] bytes received and not yet read per socket (beyond it the
//!   socket stops reading and TCP holds the sender back) and queued to send per socket (a send
//!   beyond it fails: `socket_send_*` returns False).
//! - **Time**: bytes become readable at the twin time they arrived at, as RTDE packages do
//!   ([`crate::arrival`]): a twin that fell behind and catches up does not see them early.

use std::collections::{HashMap, VecDeque};
use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use tendril_urscript::SocketState;
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::sync::mpsc;

/// Sockets a program may have open at once. UR does not publish its controller's limit; 16 is
/// four times what UR's external control program opens (three) and bounds what a program opening
/// sockets in a loop can hold: the 17th `socket_open` stops it.
pub const MAX_SOCKETS: usize = 16;
/// `socket_open` calls per second of twin time. UR's external control program retries a
/// connection five times, 0.2 s apart, for each of its three sockets (at most 15 a second); 50
/// leaves room for that and stops a program that opens and closes connections in a loop before
/// it floods the host it connects to.
pub const MAX_OPENS_PER_S: usize = 50;
/// Bytes a socket holds received and unread, and queued to send \[bytes\] (1 MiB: UR's reverse
/// interface sends 36 bytes every 2 ms, its trajectory interface 84 bytes a point).
pub const MAX_BUFFERED: usize = 1 << 20;
/// How long a connection may take (`socket_open`'s 2 s).
pub const CONNECT_TIMEOUT: Duration = Duration::from_secs(2);

/// What a socket's task and the program share.
#[derive(Debug)]
struct Link {
    state: SocketState,
    /// Chunks received, with the twin time they arrived at \[s\], oldest first.
    arrived: VecDeque<(f64, Vec<u8>)>,
    /// Bytes due by the program's clock, not read yet.
    due: VecDeque<u8>,
    /// The peer closed its side (what it sent before stays readable).
    peer_closed: bool,
}

impl Link {
    fn unread(&self) -> usize {
        self.due.len() + self.arrived.iter().map(|(_, b)| b.len()).sum::<usize>()
    }
}

#[derive(Debug)]
struct Socket {
    link: Arc<Mutex<Link>>,
    outgoing: mpsc::UnboundedSender<Vec<u8>>,
    queued: Arc<AtomicUsize>,
    task: tokio::task::JoinHandle<()>,
}

impl Drop for Socket {
    fn drop(&mut self) {
        // Closing a socket ends its task, which drops the connection.
        self.task.abort();
    }
}

fn lock(link: &Mutex<Link>) -> std::sync::MutexGuard<'_, Link> {
    link.lock().unwrap_or_else(|p| p.into_inner())
}

/// The program's sockets.
#[derive(Debug, Default)]
pub struct ProgramSockets {
    runtime: Option<tokio::runtime::Handle>,
    allowed: Vec<IpAddr>,
    /// Wall instant of twin time 0.
    clock: Option<Instant>,
    open: HashMap<String, Socket>,
    /// Twin times of the `socket_open` calls in the last second \[s\].
    recent_opens: VecDeque<f64>,
}

impl ProgramSockets {
    /// Gives the sockets a runtime to run on and the hosts allowed beyond loopback.
    pub fn attach(&mut self, runtime: tokio::runtime::Handle, allowed: Vec<IpAddr>) {
        self.runtime = Some(runtime);
        self.allowed = allowed;
    }

    /// Starts the twin's clock: twin time 0 is `origin`.
    pub fn start_clock(&mut self, origin: Instant) {
        self.clock = Some(origin);
    }

    /// How many sockets are open.
    pub fn count(&self) -> usize {
        self.open.len()
    }

    fn address(&self, host: &str) -> Result<IpAddr, String> {
        let ip = if host.eq_ignore_ascii_case("localhost") {
            IpAddr::V4(Ipv4Addr::LOCALHOST)
        } else {
            host.parse::<IpAddr>().map_err(|_| {
                format!("{host:?} is not an IP address (the virtual controller resolves no host names but localhost)")
            })?
        };
        if ip.is_loopback() || self.allowed.contains(&ip) {
            Ok(ip)
        } else {
            Err(format!(
                "{ip} is not an allowed host: the virtual controller connects to loopback only, unless \
                 `tendril serve --allow-host {ip}` allows it"
            ))
        }
    }

    /// `socket_open`: starts connecting `name` to `host:port` at twin time `now_s` \[s\].
    pub fn open(&mut self, name: &str, host: &str, port: u16, now_s: f64) -> Result<(), String> {
        let runtime = self.runtime.clone().ok_or("socket_open: the virtual controller has no network running")?;
        let ip = self.address(host).map_err(|e| format!("socket_open: {e}"))?;
        self.close(name);
        if self.open.len() >= MAX_SOCKETS {
            return Err(format!(
                "socket_open: more than {MAX_SOCKETS} sockets open at once (close some with socket_close)"
            ));
        }
        while self.recent_opens.front().is_some_and(|t| now_s - t >= 1.0) {
            self.recent_opens.pop_front();
        }
        if self.recent_opens.len() >= MAX_OPENS_PER_S {
            return Err(format!("socket_open: more than {MAX_OPENS_PER_S} sockets opened within a second"));
        }
        self.recent_opens.push_back(now_s);
        let link = Arc::new(Mutex::new(Link {
            state: SocketState::Connecting,
            arrived: VecDeque::new(),
            due: VecDeque::new(),
            peer_closed: false,
        }));
        let (outgoing, to_send) = mpsc::unbounded_channel();
        let queued = Arc::new(AtomicUsize::new(0));
        let clock = self.clock.unwrap_or_else(Instant::now);
        let task = runtime.spawn(connection(SocketAddr::new(ip, port), link.clone(), to_send, queued.clone(), clock));
        self.open.insert(name.to_string(), Socket { link, outgoing, queued, task });
        Ok(())
    }

    /// Where socket `name` stands.
    pub fn state(&self, name: &str) -> SocketState {
        let Some(s) = self.open.get(name) else { return SocketState::Closed };
        let link = lock(&s.link);
        if link.peer_closed && link.unread() == 0 { SocketState::Closed } else { link.state.clone() }
    }

    /// Exactly `n` bytes of `name` that had arrived by twin time `now_s`, if there are that many.
    pub fn read(&mut self, name: &str, n: usize, now_s: f64) -> Option<Vec<u8>> {
        let s = self.open.get(name)?;
        let mut link = lock(&s.link);
        while link.arrived.front().is_some_and(|(at, _)| *at <= now_s) {
            let (_, bytes) = link.arrived.pop_front().expect("checked");
            link.due.extend(bytes);
        }
        (link.due.len() >= n).then(|| link.due.drain(..n).collect())
    }

    /// Queues `bytes` on `name`; false if it is not open or its queue is full.
    pub fn send(&mut self, name: &str, bytes: &[u8]) -> bool {
        let Some(s) = self.open.get(name) else { return false };
        if lock(&s.link).state != SocketState::Open || s.queued.load(Ordering::SeqCst) + bytes.len() > MAX_BUFFERED {
            return false;
        }
        s.queued.fetch_add(bytes.len(), Ordering::SeqCst);
        s.outgoing.send(bytes.to_vec()).is_ok()
    }

    /// Closes `name`.
    pub fn close(&mut self, name: &str) {
        self.open.remove(name);
    }

    /// Closes every socket (the program ended).
    pub fn close_all(&mut self) {
        self.open.clear();
        self.recent_opens.clear();
    }
}

/// One socket's connection: connect, then move bytes both ways until either side closes.
async fn connection(
    addr: SocketAddr,
    link: Arc<Mutex<Link>>,
    mut to_send: mpsc::UnboundedReceiver<Vec<u8>>,
    queued: Arc<AtomicUsize>,
    clock: Instant,
) {
    let stream = match tokio::time::timeout(CONNECT_TIMEOUT, tokio::net::TcpStream::connect(addr)).await {
        Ok(Ok(stream)) => stream,
        Ok(Err(e)) => return lock(&link).state = SocketState::Failed(e.to_string()),
        Err(_) => return lock(&link).state = SocketState::Failed(format!("no connection within {CONNECT_TIMEOUT:?}")),
    };
    let _ = stream.set_nodelay(true);
    lock(&link).state = SocketState::Open;
    let (mut reader, mut writer) = stream.into_split();
    let mut chunk = vec![0u8; 16 * 1024];
    loop {
        let full = lock(&link).unread() >= MAX_BUFFERED;
        tokio::select! {
            r = reader.read(&mut chunk), if !full => match r {
                Ok(n) if n > 0 => {
                    let at_s = clock.elapsed().as_secs_f64();
                    lock(&link).arrived.push_back((at_s, chunk[..n].to_vec()));
                }
                _ => break,
            },
            // A full buffer: look again once the program may have read some.
            () = tokio::time::sleep(Duration::from_millis(2)), if full => {}
            bytes = to_send.recv() => match bytes {
                Some(bytes) => {
                    queued.fetch_sub(bytes.len(), Ordering::SeqCst);
                    if writer.write_all(&bytes).await.is_err() {
                        break;
                    }
                }
                None => return,
            },
        }
    }
    let mut l = lock(&link);
    l.peer_closed = true;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn loopback_and_the_allowed_hosts_only_and_no_names_but_localhost() {
        let mut s = ProgramSockets::default();
        let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
        assert!(s.open("a", "127.0.0.1", 9, 0.0).unwrap_err().contains("no network"), "not attached yet");
        s.attach(runtime.handle().clone(), vec!["192.0.2.7".parse().unwrap()]);
        for host in ["127.0.0.1", "127.1.2.3", "::1", "localhost", "192.0.2.7"] {
            assert_eq!(s.address(host).map(|_| ()), Ok(()), "{host}");
        }
        let refused = s.address("192.0.2.8").unwrap_err();
        assert!(refused.contains("not an allowed host") && refused.contains("--allow-host 192.0.2.8"), "{refused}");
        assert!(s.address("driver.local").unwrap_err().contains("resolves no host names"));
        // Opening is asynchronous: the socket connects on the runtime, the caller only looks.
        s.open("a", "127.0.0.1", 9, 0.0).unwrap();
        assert_eq!(s.count(), 1);
        s.close_all();
        assert_eq!((s.count(), s.state("a")), (0, SocketState::Closed));
    }

    #[test]
    fn bytes_are_readable_from_the_twin_time_they_arrived_at_and_whole() {
        let mut s = ProgramSockets::default();
        let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
        s.attach(runtime.handle().clone(), Vec::new());
        s.open("a", "127.0.0.1", 9, 0.0).unwrap();
        {
            let link = &s.open["a"].link;
            let mut l = lock(link);
            l.state = SocketState::Open;
            l.arrived.push_back((0.010, vec![1, 2, 3]));
            l.arrived.push_back((0.020, vec![4, 5]));
        }
        assert_eq!(s.read("a", 2, 0.005), None, "not yet arrived at 5 ms");
        assert_eq!(s.read("a", 4, 0.012), None, "only three bytes by 12 ms");
        assert_eq!(s.read("a", 2, 0.012), Some(vec![1, 2]));
        assert_eq!(s.read("a", 3, 0.020), Some(vec![3, 4, 5]));
        assert_eq!(s.read("nope", 1, 1.0), None);
    }
}
