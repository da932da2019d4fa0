//! The command line's operator stops: SIGINT (Ctrl-C), SIGTERM and SIGHUP turned into the stop
//! request the control loop checks every tick ([`tendril_cell::interrupt`]).

use tendril_cell::interrupt::{SIGHUP, SIGINT, SIGTERM, exit_code, name, request, requested};

/// Turns SIGINT, SIGTERM and SIGHUP into a stop request, on a small thread of its own. A second
/// signal of any kind after the first ends the process at once (exit `128 + signal`), for a stop
/// that does not come.
pub fn install_signal_handlers() -> std::io::Result<()> {
    use tokio::signal::unix::{SignalKind, signal};
    let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build()?;
    // Registered here, before the thread starts, so no signal is missed after `install` returns.
    let mut streams = runtime.block_on(async {
        Ok::<_, std::io::Error>([
            (SIGINT, signal(SignalKind::interrupt())?),
            (SIGTERM, signal(SignalKind::terminate())?),
            (SIGHUP, signal(SignalKind::hangup())?),
        ])
    })?;
    std::thread::Builder::new().name("signals".into()).spawn(move || {
        runtime.block_on(async move {
            loop {
                let [(n1, s1), (n2, s2), (n3, s3)] = &mut streams;
                let n = tokio::select! {
                    _ = s1.recv() => *n1,
                    _ = s2.recv() => *n2,
                    _ = s3.recv() => *n3,
                };
                if let Some(first) = requested() {
                    eprintln!("tendril: {} again after {}: exiting now", name(n), name(first));
                    std::process::exit(i32::from(exit_code(n)));
                }
                eprintln!("tendril: {}: stopping cleanly (send it again to exit at once)", name(n));
                request(n);
            }
        });
    })?;
    Ok(())
}
