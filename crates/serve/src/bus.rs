//! The virtual Dynamixel bus on a pseudo-terminal: the MX-106 pair answering on its master side.

use super::jitter::{Held, Jitter, Link};
use super::state::{DeviceState, lock};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use tendril_drivers::realtime::RealtimeOptions;
use tendril_dynamixel::StreamDecoder;

/// Opens the pseudo-terminal pair and serves the bus on its master side until `stop`.
pub fn open_bus(
    state: Arc<Mutex<DeviceState>>,
    stop: Arc<AtomicBool>,
    realtime: RealtimeOptions,
    jitter: Option<Jitter>,
    epoch: Instant,
) -> anyhow::Result<(PathBuf, std::thread::JoinHandle<()>)> {
    use std::os::unix::io::AsRawFd;
    let (mut master, slave) = serial2::SerialPort::pair()?;
    // serial2 opens the slave by name; /proc tells which /dev/pts/N it is.
    let path = std::fs::read_link(format!("/proc/self/fd/{}", slave.as_raw_fd()))?;
    master.set_read_timeout(Duration::from_millis(20))?;
    let handle = std::thread::Builder::new().name("dxl-bus".into()).spawn(move || {
        // Keeping the slave open means reads on the master never fail with EIO between clients.
        let _slave = slave;
        let _ = realtime.apply_to_current_thread();
        let mut decoder = StreamDecoder::new();
        let mut chunk = [0u8; 1024];
        // Injected jitter holds each request back (and with it the reply and whatever comes behind).
        let mut link = Held::new(jitter, Link::Bus, epoch);
        while !stop.load(Ordering::SeqCst) {
            match master.read(&mut chunk) {
                Ok(n) if n > 0 => {
                    if link.push(()).is_none() {
                        if let Some(at) = link.next_release() {
                            std::thread::sleep(at.saturating_duration_since(Instant::now()));
                        }
                        link.due();
                    }
                    let reply = lock(&state).bus.respond_to_bytes(&mut decoder, &chunk[..n]);
                    if !reply.is_empty() && master.write_all(&reply).is_err() {
                        return;
                    }
                }
                Ok(_) => {}
                Err(e) if matches!(e.kind(), std::io::ErrorKind::TimedOut | std::io::ErrorKind::WouldBlock) => {}
                Err(_) => std::thread::sleep(Duration::from_millis(5)),
            }
        }
    })?;
    Ok((path, handle))
}
