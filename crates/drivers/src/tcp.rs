//! TCP connections of the drivers: bounded connect, Nagle's algorithm off.
//!
//! Every packet the drivers send is small and wanted now (an RTDE input package per tick, a
//! HYPERION command, the program); with Nagle on, the kernel may hold one back until the previous
//! is acknowledged, up to a delayed-ACK timeout of tens of milliseconds.

use std::time::Duration;
use tokio::net::TcpStream;

/// Connects to `addr` within `timeout` and turns on TCP_NODELAY. The error names the address.
pub async fn connect(addr: &str, timeout: Duration) -> Result<TcpStream, String> {
    let stream = tokio::time::timeout(timeout, TcpStream::connect(addr))
        .await
        .map_err(|_| format!("{addr}: connect timed out"))?
        .map_err(|e| format!("{addr}: {e}"))?;
    stream.set_nodelay(true).map_err(|e| format!("{addr}: TCP_NODELAY: {e}"))?;
    Ok(stream)
}
