//! The gripper bus on a thread of its own, so that no control tick waits on it.
//!
//! A Dynamixel bus is half duplex: a sync read is a request and two replies, whose timing is the
//! motors' (return delay), the adapter's (USB latency timer) and the kernel's. Done on the control
//! thread, any late reply is a late tick. [`GripperLink`] moves the bus to an IO thread (started
//! by the control thread, so it inherits its priority and CPU): the tick asks for positions
//! ([`GripperLink::request_present`], shortly before the tick), takes the newest that arrived
//! ([`GripperLink::latest`]) and posts the goals ([`GripperLink::set_goal_rad`]); the IO thread
//! does the bus traffic in between. A reply that comes late costs the tick one sample of freshness
//! (counted in [`LinkStats`]), not its deadline; a bus that stops answering shows as positions that
//! grow old, which the cell's watchdog turns into a stop.

use super::dxl::GripperBus;
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::Instant;

/// Motor positions [growth, twine] in rad and when their sync read was put on the bus.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotorSample {
    /// Angles from the set-up position \[rad\].
    pub rad: [f64; 2],
    /// When the request for them was sent.
    pub requested_at: Instant,
    /// Which request they answer (1, 2, ... ; 0 = the sample taken when the link started).
    pub request: u64,
}

/// How fresh the positions the ticks used were.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct LinkStats {
    /// Samples taken by [`GripperLink::latest`].
    pub reads: u64,
    /// Of those, answers to an earlier request than the newest one sent: the replies to the
    /// newest were late and the tick used the positions of the tick before.
    pub behind: u64,
}

impl std::ops::AddAssign for LinkStats {
    fn add_assign(&mut self, other: LinkStats) {
        self.reads += other.reads;
        self.behind += other.behind;
    }
}

/// What the control thread and the IO thread share.
#[derive(Debug)]
struct Shared {
    /// Requests sent by the control thread so far.
    requested: u64,
    /// A goal not yet on the bus.
    goal: Option<[f64; 2]>,
    latest: MotorSample,
    /// Why the IO thread stopped, if it failed.
    failed: Option<String>,
    stop: bool,
    stats: LinkStats,
}

/// The gripper's bus, served by an IO thread.
pub struct GripperLink {
    shared: Arc<(Mutex<Shared>, Condvar)>,
    thread: Option<JoinHandle<GripperBus>>,
}

fn lock(m: &Mutex<Shared>) -> MutexGuard<'_, Shared> {
    m.lock().unwrap_or_else(|p| p.into_inner())
}

impl GripperLink {
    /// Hands `bus` to a new IO thread, with `first` (positions just read from it) as the first
    /// sample. The thread gets the calling thread's scheduling.
    pub fn start(bus: GripperBus, first: [f64; 2]) -> Result<GripperLink, String> {
        let shared = Arc::new((
            Mutex::new(Shared {
                requested: 0,
                goal: None,
                latest: MotorSample { rad: first, requested_at: Instant::now(), request: 0 },
                failed: None,
                stop: false,
                stats: LinkStats::default(),
            }),
            Condvar::new(),
        ));
        let io = shared.clone();
        let thread = std::thread::Builder::new()
            .name("dxl-io".into())
            .spawn(move || serve(bus, &io))
            .map_err(|e| format!("Dynamixel: IO thread: {e}"))?;
        Ok(GripperLink { shared, thread: Some(thread) })
    }

    /// Asks for fresh positions (sent as soon as the IO thread is free).
    pub fn request_present(&self) {
        let (m, wake) = &*self.shared;
        lock(m).requested += 1;
        wake.notify_one();
    }

    /// Posts goals [growth, twine] in rad (a newer goal replaces one not yet sent).
    pub fn set_goal_rad(&self, goal: [f64; 2]) {
        let (m, wake) = &*self.shared;
        lock(m).goal = Some(goal);
        wake.notify_one();
    }

    /// The newest positions, or why the bus failed; never waits for the bus.
    pub fn latest(&self) -> Result<MotorSample, String> {
        let mut s = lock(&self.shared.0);
        if let Some(why) = &s.failed {
            return Err(why.clone());
        }
        let behind = s.latest.request < s.requested;
        s.stats.reads += 1;
        s.stats.behind += u64::from(behind);
        Ok(s.latest)
    }

    /// Freshness of the positions read so far.
    pub fn stats(&self) -> LinkStats {
        lock(&self.shared.0).stats
    }

    /// Stops the IO thread (after the transfer under way) and gives the bus back.
    pub fn stop(mut self) -> Result<GripperBus, String> {
        self.shutdown().unwrap_or_else(|| Err("Dynamixel: IO thread already stopped".into()))
    }

    /// Stops and joins the IO thread, if it still runs.
    fn shutdown(&mut self) -> Option<Result<GripperBus, String>> {
        let thread = self.thread.take()?;
        lock(&self.shared.0).stop = true;
        self.shared.1.notify_one();
        Some(thread.join().map_err(|_| "Dynamixel: IO thread panicked".to_string()))
    }
}

impl Drop for GripperLink {
    fn drop(&mut self) {
        let _ = self.shutdown();
    }
}

/// The IO thread: goals and position requests onto the bus, in the order the tick needs them.
fn serve(mut bus: GripperBus, shared: &(Mutex<Shared>, Condvar)) -> GripperBus {
    let (m, wake) = shared;
    let mut answered = 0;
    loop {
        let (goal, request) = {
            let mut s = lock(m);
            while !s.stop && s.goal.is_none() && s.requested == answered {
                s = wake.wait(s).unwrap_or_else(|p| p.into_inner());
            }
            if s.stop {
                return bus;
            }
            (s.goal.take(), (s.requested > answered).then_some(s.requested))
        };
        let result = goal.map_or(Ok(()), |g| bus.set_goal_rad(g)).and_then(|()| match request {
            Some(request) => {
                let requested_at = Instant::now();
                let rad = bus.present_rad()?;
                answered = request;
                lock(m).latest = MotorSample { rad, requested_at, request };
                Ok(())
            }
            None => Ok(()),
        });
        if let Err(why) = result {
            lock(m).failed = Some(why);
            return bus;
        }
    }
}
