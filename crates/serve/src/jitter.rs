//! Timing faults the virtual devices can inject into their links: packets held back and bunched,
//! as an ordinary PC or a Wi-Fi link does to them (`tendril serve --jitter`, `tendril chart
//! jitter`). Pure and seeded: [`DelayLine`] says when a packet handed to a link at a given time
//! leaves it; the IO around it waits for that time.
//!
//! Two mechanisms, each stated with its numbers in [`JitterProfile`]:
//! - **stalls**: the link's sender is not run for a while (a stock kernel's scheduling, another
//!   process on the core, a Wi-Fi retransmission burst): a Poisson process of stalls, each of a
//!   length drawn uniformly between two bounds; a packet handed over during a stall leaves when it
//!   ends, so the packets behind it bunch up and leave together;
//! - **latency**: every packet is delayed by a log-normal time (median and log-spread).
//!
//! Packets never overtake each other (TCP and a serial line keep their order).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, LogNormal};
use serde::{Deserialize, Serialize};
use std::collections::VecDeque;
use std::time::{Duration, Instant};

/// The timing a link is given.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct JitterModel {
    /// Stalls per second [1/s] (0: none).
    pub stall_rate_hz: f64,
    /// Shortest and longest stall \[s\].
    pub stall_s: (f64, f64),
    /// Median per-packet latency \[s\] (0: none).
    pub latency_median_s: f64,
    /// Log-normal spread of the latency (σ of its logarithm) [-].
    pub latency_sigma: f64,
}

/// The named timing profiles (`--jitter NAME`). Their numbers are stated choices, each from a
/// measurement or a typical figure, so that a study can say what it injected.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum JitterProfile {
    /// Nothing injected: the links are as fast as the machine makes them.
    None,
    /// A quiet PC on loopback: 50 µs median latency (σ 0.5; loopback round trips measure tens of
    /// microseconds) and a 1-3 ms stall twice a second (the sub-scheduling-tick gaps an idle
    /// stock kernel gives a woken thread).
    Loopback,
    /// A busy stock PC: as `loopback`, with stalls of 5-20 ms twice a second (the issue's
    /// measurement on an idle 2-core machine: 7-16 ms gaps on loopback every few seconds; twice as
    /// often and somewhat longer for a loaded one).
    BusyPc,
    /// Wi-Fi between the PC and the devices: 3 ms median latency with a heavy tail (σ 0.7: 10 ms
    /// at the 95th percentile) and a 20-80 ms burst every two seconds (retransmissions, power save,
    /// a neighbour's traffic).
    Wifi,
}

impl JitterProfile {
    /// The profile's numbers; `None` for [`JitterProfile::None`].
    pub fn model(self) -> Option<JitterModel> {
        let loopback =
            JitterModel { stall_rate_hz: 2.0, stall_s: (1e-3, 3e-3), latency_median_s: 50e-6, latency_sigma: 0.5 };
        match self {
            JitterProfile::None => None,
            JitterProfile::Loopback => Some(loopback),
            JitterProfile::BusyPc => Some(JitterModel { stall_s: (5e-3, 20e-3), ..loopback }),
            JitterProfile::Wifi => Some(JitterModel {
                stall_rate_hz: 0.5,
                stall_s: (20e-3, 80e-3),
                latency_median_s: 3e-3,
                latency_sigma: 0.7,
            }),
        }
    }
}

/// Timing injected into the links of the virtual devices: the model, the seed of its delays (each
/// link draws its own from it), and the links it applies to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jitter {
    /// What is injected.
    pub model: JitterModel,
    /// Seed [-].
    pub seed: u64,
    /// Only this link (`None`: every link of the devices, [`Link::Twin`] not included).
    pub only: Option<Link>,
}

impl Jitter {
    /// `profile`'s jitter on every link, seeded; `None` for [`JitterProfile::None`].
    pub fn profile(profile: JitterProfile, seed: u64) -> Option<Jitter> {
        profile.model().map(|model| Jitter { model, seed, only: None })
    }

    /// Whether `link` is given this jitter: the link it names; with none named, every link of the
    /// devices. The twin's own thread ([`Link::Twin`]) only when named: the devices' links are
    /// what a client meets, and the jitter study's cases on every link are theirs.
    pub fn applies_to(&self, link: Link) -> bool {
        match self.only {
            Some(only) => only == link,
            None => link != Link::Twin,
        }
    }
}

/// The links of the virtual devices, each with its own [`DelayLine`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
#[repr(u64)]
pub enum Link {
    /// RTDE output packages, controller → client.
    RtdeOut = 1,
    /// RTDE input packages, client → controller.
    RtdeIn = 2,
    /// HYPERION peak stream, interrogator → client.
    Peaks = 3,
    /// The Dynamixel bus: a request, its processing and its replies.
    Bus = 4,
    /// The twin's own thread (only when named): not run for the stall, its physics falls behind
    /// real time and then catches up tick after tick, as on a busy PC or a virtual machine whose
    /// host holds it.
    Twin = 5,
}

/// When each packet handed to one link leaves it (see the module docs).
#[derive(Debug, Clone)]
pub struct DelayLine {
    model: JitterModel,
    rng: ChaCha8Rng,
    /// The next stall: start and end \[s\].
    stall: (f64, f64),
    /// When the last packet left \[s\].
    last_release_s: f64,
}

impl DelayLine {
    /// A line for `link` under `model`, seeded: the same seed and link give the same delays for the
    /// same hand-over times.
    pub fn new(model: JitterModel, seed: u64, link: Link) -> DelayLine {
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ (link as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
        let stall = next_stall(&model, &mut rng, 0.0);
        DelayLine { model, rng, stall, last_release_s: f64::NEG_INFINITY }
    }

    /// When a packet handed over at `sent_s` \[s\] (non-decreasing from call to call) leaves.
    pub fn release_s(&mut self, sent_s: f64) -> f64 {
        while self.stall.1 <= sent_s {
            self.stall = next_stall(&self.model, &mut self.rng, self.stall.1);
        }
        let mut at = if self.stall.0 <= sent_s { self.stall.1 } else { sent_s };
        if self.model.latency_median_s > 0.0 {
            let latency = LogNormal::new(self.model.latency_median_s.ln(), self.model.latency_sigma.max(0.0))
                .map_or(self.model.latency_median_s, |d| d.sample(&mut self.rng));
            at += latency;
        }
        self.last_release_s = at.max(self.last_release_s);
        self.last_release_s
    }
}

/// Injected timing on one link of a running device: when each packet handed to it leaves, on the
/// wall clock. Without a model it passes everything on at once.
#[derive(Debug)]
pub struct Held<T> {
    line: Option<DelayLine>,
    /// Wall-clock time 0 of the line's clock.
    epoch: Instant,
    queue: VecDeque<(Instant, T)>,
}

impl<T> Held<T> {
    /// The link `link` timed by `jitter` (`None`: nothing injected), its clock starting at `epoch`.
    pub fn new(jitter: Option<Jitter>, link: Link, epoch: Instant) -> Held<T> {
        let jitter = jitter.filter(|j| j.applies_to(link));
        let line = jitter.map(|j| DelayLine::new(j.model, j.seed, link));
        Held { line, epoch, queue: VecDeque::new() }
    }

    /// Hands `item` to the link now: back at once when nothing is injected, else held until its
    /// release ([`Held::due`]).
    pub fn push(&mut self, item: T) -> Option<T> {
        let Some(line) = &mut self.line else { return Some(item) };
        let sent_s = self.epoch.elapsed().as_secs_f64();
        let release = self.epoch + Duration::from_secs_f64(line.release_s(sent_s).max(0.0));
        self.queue.push_back((release, item));
        None
    }

    /// When the next held item is due.
    pub fn next_release(&self) -> Option<Instant> {
        self.queue.front().map(|(at, _)| *at)
    }

    /// The held items due by now, oldest first.
    pub fn due(&mut self) -> Vec<T> {
        let now = Instant::now();
        let n = self.queue.iter().take_while(|(at, _)| *at <= now).count();
        self.queue.drain(..n).map(|(_, item)| item).collect()
    }
}

/// The stall after `after_s`: its start (exponential gap at the model's rate) and end.
fn next_stall(model: &JitterModel, rng: &mut ChaCha8Rng, after_s: f64) -> (f64, f64) {
    if model.stall_rate_hz <= 0.0 || model.stall_s.1 <= 0.0 {
        return (f64::INFINITY, f64::INFINITY);
    }
    let gap = -(1.0 - rng.random::<f64>()).ln() / model.stall_rate_hz;
    let (lo, hi) = model.stall_s;
    let length = lo + (hi - lo).max(0.0) * rng.random::<f64>();
    (after_s + gap, after_s + gap + length)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Packets every `period_s` for `seconds` through a line: their delays \[s\].
    fn delays(model: JitterModel, seed: u64, period_s: f64, seconds: f64) -> Vec<f64> {
        let mut line = DelayLine::new(model, seed, Link::Peaks);
        (0..(seconds / period_s) as usize)
            .map(|k| {
                let t = k as f64 * period_s;
                line.release_s(t) - t
            })
            .collect()
    }

    #[test]
    fn stalls_hold_packets_back_bunch_them_and_never_reorder() {
        let model =
            JitterModel { stall_rate_hz: 2.0, stall_s: (0.01, 0.02), latency_median_s: 0.0, latency_sigma: 0.0 };
        let d = delays(model, 7, 1e-3, 100.0);
        let held = d.iter().filter(|&&x| x > 0.0).count() as f64 / d.len() as f64;
        // Two stalls a second of 15 ms on average hold 3 % of the packets.
        assert!((0.02..0.04).contains(&held), "{held}");
        assert!(d.iter().all(|&x| (0.0..=0.02 + 1e-12).contains(&x)), "no delay beyond the longest stall");
        // Order: release times never decrease.
        let mut line = DelayLine::new(model, 7, Link::Peaks);
        let releases: Vec<f64> = (0..10_000).map(|k| line.release_s(k as f64 * 1e-3)).collect();
        assert!(releases.windows(2).all(|w| w[1] >= w[0]));
        // Bunching: a stall's packets leave at its end, together.
        assert!(releases.windows(2).any(|w| w[1] == w[0]));
    }

    #[test]
    fn latency_has_the_stated_median_and_the_same_seed_gives_the_same_delays() {
        let model = JitterModel { stall_rate_hz: 0.0, stall_s: (0.0, 0.0), latency_median_s: 3e-3, latency_sigma: 0.7 };
        // Sent 50 ms apart, packets do not queue behind each other: each delay is its own draw.
        let mut d = delays(model, 1, 0.05, 500.0);
        assert_eq!(d, delays(model, 1, 0.05, 500.0));
        assert_ne!(d, delays(model, 2, 0.05, 500.0));
        d.sort_by(f64::total_cmp);
        let median = d[d.len() / 2];
        assert!((median - 3e-3).abs() < 0.3e-3, "{median}");
    }

    #[test]
    fn the_twin_stalls_only_when_named_and_a_named_link_alone_is_given_the_jitter() {
        let every = Jitter::profile(JitterProfile::BusyPc, 1).unwrap();
        assert!(every.applies_to(Link::RtdeIn) && every.applies_to(Link::Bus) && !every.applies_to(Link::Twin));
        let twin = Jitter { only: Some(Link::Twin), ..every };
        assert!(twin.applies_to(Link::Twin) && !twin.applies_to(Link::Peaks));
    }

    #[test]
    fn the_profiles_are_stated_and_none_injects_nothing() {
        assert_eq!(JitterProfile::None.model(), None);
        for p in [JitterProfile::Loopback, JitterProfile::BusyPc, JitterProfile::Wifi] {
            let m = p.model().unwrap();
            assert!(m.stall_s.0 <= m.stall_s.1 && m.latency_median_s > 0.0, "{p:?}");
        }
    }
}
