//! Slip and drop detection from the force estimate alone, as the paper observes it: while an object
//! slips the reading falls gradually, then drops to zero when contact is lost.
//!
//! Three cues, each on the estimate averaged over a window that grows with the reading's noise
//! (learnt at home, as the guarded close does: [`super::contact`]):
//! - a **slip warning** when the averaged estimate falls below `slip_fraction` × the setpoint;
//! - a **drop alarm** when it falls by `fall_fraction` × the setpoint within `fall_window_s` (an
//!   object leaving the hand unloads the pad within a tenth of a second), or when contact is lost
//!   (within `lost_force_n` of the unloaded reading for `lost_hold_s`).
//!
//! With a wrist force sensor ([`tendril_cell::CellState::tool_load_n`]) a third cue watches the
//! load the tool carries ([`super::load`]): a drop alarm when it falls by half. Once it can see the
//! object's weight go, the pad's *loss* only warns of slip (the pad may lose an object that still
//! hangs in the hand, and it cannot see one leave a grip whose pad keeps its load), while the pad's
//! sudden *fall* still raises the alarm (a knock that sets the object sliding down the grip unloads
//! the pad at once, and the wrist only as the slide speeds up). And once the hand has risen
//! `lift_check_m` since the carry began, the wrist must read the object's weight: an object the
//! hand did not take up (a slick one left on the table) is a drop alarm then, though no load fell.
//!
//! Each alarm starts an episode; an episode ends once its cue has been clear for [`REARM_S`]. On
//! the twin the episodes are judged against the ground truth ([`judge`]): the delay from the true
//! drop to the first drop alarm, and the drop alarms that no drop followed (false alarms).
//!
//! What the pad cannot see: a drop while the pad is already unloaded (without feedback the shampoo
//! hangs on the palm's pinch for seconds after the pad lost it), and an object sliding through a
//! grip whose pad keeps its load (near-zero friction). What neither sees: an object that slides
//! down the grip and stays in the hand (the knocked hammer), whose weight the hand still carries.
//! docs/studies/disturbances.md#measured has the figures.

use super::contact::{MAX_WINDOW_TICKS, Z};
use super::load::{LoadCue, LoadCues};
use serde::{Deserialize, Serialize};
use std::collections::VecDeque;
use tendril_config::{Checker, Validate};

/// How long a cue must stay clear before a new alarm of the same kind counts as a new episode
/// \[s\]. 0.5 s: longer than the pad's ring after an impact (0.3-0.4 s on the twin), so one knock
/// is one episode.
pub const REARM_S: f64 = 0.5;

/// How early a drop alarm may come and still count as seeing the drop \[s\]: the fall that ends in a
/// drop starts up to a few tenths of a second before the drop watch's criterion is met (0.1-0.2 s
/// in the reproduction runs).
pub const EARLY_S: f64 = 0.5;

/// Thresholds of the slip detector (TOML `[slip]`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SlipConfig {
    /// Slip is flagged when the estimate falls below this fraction of the reference force
    /// (the setpoint). 0.5: the paper's held runs dip to 72 % of the setpoint at worst
    /// (crimper, 0.43 N of 0.6 N), so half the setpoint is clearly outside normal fluctuation.
    pub slip_fraction: f64,
    /// Contact is taken as lost when the estimate is within this force \[N\] of the unloaded
    /// reading: 20× the sensor's noise-limited resolution (2.57 mN, paper Sec. IV-B). The
    /// unloaded reading is not 0 N with the paper's calibration (its −91.42 pm intercept makes
    /// eq. (8) read ≈ 0.16 N at zero shift), so the threshold is relative to it. Raised to the
    /// averaged noise's 5σ on a noisier interrogator.
    pub lost_force_n: f64,
    /// The force must stay below `lost_force_n` this long \[s\] before the object is declared
    /// lost, so single noisy samples do not trigger it.
    pub lost_hold_s: f64,
    /// A drop alarm is raised when the averaged estimate falls by this fraction of the reference
    /// within `fall_window_s`. 0.5: the same half of the setpoint as the slip warning; the held
    /// runs' largest falls at the paper's timings are 0.2-0.3 of it.
    pub fall_fraction: f64,
    /// The window of the fall \[s\]. 0.2 s: a drop unloads the pad in 0.1-0.2 s on the twin, while
    /// the grip's creep without feedback takes seconds to lose as much.
    pub fall_window_s: f64,
    /// With a wrist force sensor, a drop alarm is raised when the tool's load falls by this
    /// fraction of the load carried ([`super::load`]). 0.5: an object leaving the hand takes all
    /// of its weight; the carried load moves by a few percent with the arm's accelerations (the
    /// paper's 15 °/s² over the arm's reach of about 0.6 m: 0.16 m/s², under 2 % of g).
    pub load_fall_fraction: f64,
    /// With a wrist force sensor, how far the hand must have risen since the carry began \[m\]
    /// before the wrist must read the object's weight (short of it by `load_fall_fraction`: a drop
    /// alarm). 0.02 m: an object the hand has not taken up after 20 mm of rise has slid 20 mm down
    /// the grip, which is what the drop watch counts as a drop (`run::drop_watch`); the object's
    /// weight moves onto the hand within the first few millimetres of a lift that carries it.
    pub lift_check_m: f64,
}

impl Default for SlipConfig {
    fn default() -> Self {
        SlipConfig {
            slip_fraction: 0.5,
            lost_force_n: 0.05,
            lost_hold_s: 0.2,
            fall_fraction: 0.5,
            fall_window_s: 0.2,
            load_fall_fraction: 0.5,
            lift_check_m: 0.02,
        }
    }
}

impl Validate for SlipConfig {
    fn validate(&self, at: &mut Checker) {
        at.in_range("slip_fraction", self.slip_fraction, 0.0, 1.0);
        // Within the sensor's range (4.69 N, paper Sec. IV-B): a larger threshold is always met.
        at.require("lost_force_n", self.lost_force_n > 0.0 && self.lost_force_n <= 4.69, || {
            format!("must be > 0 and at most the sensor's range 4.69 N, got {}", self.lost_force_n)
        });
        // 60 s: longer than any phase in which the object is held in the paper (the 15 s grasp,
        // the 11 s lift), so a longer hold could never declare a loss.
        at.in_range("lost_hold_s", self.lost_hold_s, 0.0, 60.0);
        // A fall of more than the whole setpoint (fraction 1) can still happen from an overshoot,
        // up to the sensor's range; 0 would alarm on every tick.
        at.require("fall_fraction", self.fall_fraction > 0.0 && self.fall_fraction <= 5.0, || {
            format!("must be > 0 and at most 5, got {}", self.fall_fraction)
        });
        // 10 s: beyond it the grip's creep without feedback alone makes the fall.
        at.require("fall_window_s", self.fall_window_s > 0.0 && self.fall_window_s <= 10.0, || {
            format!("must be > 0 and at most 10 s, got {}", self.fall_window_s)
        });
        // A fall of the whole load or more can never be read (the load cannot fall below zero),
        // and 0 would alarm on every tick.
        at.require("load_fall_fraction", self.load_fall_fraction > 0.0 && self.load_fall_fraction < 1.0, || {
            format!("must be > 0 and < 1, got {}", self.load_fall_fraction)
        });
        // 0.5 m: beyond any lift of the cell's task (the paper's is about 0.1 m), so the check
        // would never run; 0 would check while the object still stands on the table.
        at.require("lift_check_m", self.lift_check_m > 0.0 && self.lift_check_m <= 0.5, || {
            format!("must be > 0 and at most 0.5 m, got {}", self.lift_check_m)
        });
    }
}

/// What the detector has seen so far.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct SlipEvents {
    /// When the estimate first fell below `slip_fraction` × reference while holding \[s\].
    pub slip_start_s: Option<f64>,
    /// When the force fell below `lost_force_n` (for at least `lost_hold_s`) while holding \[s\].
    pub lost_s: Option<f64>,
    /// When the first drop alarm (a fall, or the loss) was raised \[s\].
    pub drop_alarm_s: Option<f64>,
    /// When the detector judged the object gone \[s\]: the wrist's fall once its cue is armed,
    /// else the pad's loss (`lost_s`). What a cell without ground truth reports as the drop.
    pub dropped_s: Option<f64>,
}

/// The alarm episodes of a run.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct Alarms {
    /// Start of each slip-warning episode \[s\].
    pub warnings_s: Vec<f64>,
    /// Start of each drop-alarm episode (a fall, or the loss) \[s\].
    pub drops_s: Vec<f64>,
}

/// One cue's episodes: a new one starts when the cue fires after [`REARM_S`] clear.
#[derive(Debug, Clone, Default)]
struct Episodes {
    last_on_s: Option<f64>,
}

impl Episodes {
    /// Feeds the cue's state at `time_s`; true when a new episode starts.
    fn update(&mut self, time_s: f64, on: bool) -> bool {
        if !on {
            return false;
        }
        let new = self.last_on_s.is_none_or(|last| time_s - last > REARM_S);
        self.last_on_s = Some(time_s);
        new
    }
}

/// What the arm tells the detector on one tick.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ArmReading {
    /// The wrist's reading of the load the tool carries \[N\] (`None`: no wrist sensor).
    pub tool_load_n: Option<f64>,
    /// The flange's height in the arm's base frame \[m\], from the measured joints
    /// ([`tendril_ur5e::kinematics::forward`]).
    pub hand_height_m: f64,
}

impl ArmReading {
    /// The reading for the measured joint angles `arm_q` \[rad\] and the wrist's load.
    pub fn from_joints(arm_q: &[f64; 6], tool_load_n: Option<f64>) -> ArmReading {
        ArmReading { tool_load_n, hand_height_m: tendril_ur5e::kinematics::forward(arm_q).translation.vector.z }
    }
}

/// Watches the force estimate during the phases in which the object must stay in the hand.
#[derive(Debug, Clone)]
pub struct SlipDetector {
    config: SlipConfig,
    events: SlipEvents,
    alarms: Alarms,
    below_since: Option<f64>,
    /// The last estimates, for the average (at most [`MAX_WINDOW_TICKS`]).
    recent: VecDeque<f64>,
    /// The averaged estimates of the last `fall_window_s`, with their times.
    averaged: VecDeque<(f64, f64)>,
    warning: Episodes,
    drop: Episodes,
    /// The wrist's cue (never armed on a cell without a wrist sensor).
    load: LoadCue,
    /// The object's weight \[N\], when known: what the wrist must read once the hand has risen.
    object_weight_n: Option<f64>,
    /// The hand's height when the carry began \[m\].
    carry_start_height_m: Option<f64>,
}

impl SlipDetector {
    /// A detector with nothing seen.
    pub fn new(config: SlipConfig) -> SlipDetector {
        SlipDetector {
            config,
            events: SlipEvents::default(),
            alarms: Alarms::default(),
            below_since: None,
            recent: VecDeque::new(),
            averaged: VecDeque::new(),
            warning: Episodes::default(),
            drop: Episodes::default(),
            load: LoadCue::new(config.load_fall_fraction),
            object_weight_n: None,
            carry_start_height_m: None,
        }
    }

    /// The detector, told the object's weight \[N\]: the wrist must read it once the hand has
    /// risen `lift_check_m` (see the module docs).
    pub fn with_object_weight(mut self, weight_n: f64) -> SlipDetector {
        self.object_weight_n = Some(weight_n);
        self
    }

    /// Learns the wrist's zero and noise from one reading at home (`None`: no wrist sensor).
    pub fn observe_home_load(&mut self, load_n: Option<f64>) {
        if let Some(load) = load_n {
            self.load.observe_home(load);
        }
    }

    /// How many estimates the cues average for a reading noise of `noise_n` \[N\] (1 SD) and a
    /// setpoint of `reference_n`: enough that the fall's threshold is [`Z`] SDs of the difference
    /// of two averages, at most [`MAX_WINDOW_TICKS`] (1 at the paper's 3 pm noise).
    pub fn window_ticks(&self, noise_n: f64, reference_n: f64) -> usize {
        let fall = self.config.fall_fraction * reference_n;
        if fall <= 0.0 || !noise_n.is_finite() {
            return 1;
        }
        let k = (2.0 * (Z * noise_n / fall).powi(2)).ceil();
        (k as usize).clamp(1, MAX_WINDOW_TICKS)
    }

    /// Feeds one tick: the force estimate and what the arm reads (the wrist's load, `None` without
    /// a wrist sensor, and the hand's height). `unloaded_n` is what the estimator reads with nothing
    /// on the sensor (the estimate at the tare) and `noise_n` the SD of the readings there;
    /// `holding` is true in the phases where the object must stay in the hand; `reference_n` is
    /// the force the grasp should have (the setpoint).
    #[allow(clippy::too_many_arguments)]
    pub fn update(
        &mut self,
        time_s: f64,
        force_n: f64,
        arm: ArmReading,
        unloaded_n: f64,
        noise_n: f64,
        reference_n: f64,
        holding: bool,
    ) -> SlipEvents {
        let expected_n = self.expected_load_n(arm.hand_height_m, holding);
        let load = self.load.update(arm.tool_load_n, holding, expected_n);
        if !holding {
            self.below_since = None;
            self.recent.clear();
            self.averaged.clear();
            return self.events;
        }
        let pad = self.pad_cues(time_s, force_n, unloaded_n, noise_n, reference_n);
        // With the wrist armed, the pad's loss only warns: the hand still carries the object (it
        // hangs on the pinch). The pad's sudden fall stays an alarm: something moved the object in
        // the hand, and a slide the wrist sees only once it speeds up may follow.
        let wrist = self.load.armed();
        let drop_on = load.short || if wrist { load.fell || pad.fell } else { pad.fell || pad.lost };
        if self.warning.update(time_s, pad.below_slip || (wrist && pad.lost)) {
            self.alarms.warnings_s.push(time_s);
        }
        if self.drop.update(time_s, drop_on) {
            let pad_loss = (!wrist && pad.lost).then_some(self.events.lost_s).flatten();
            self.alarms.drops_s.push(pad_loss.unwrap_or(time_s));
        }
        if drop_on && self.events.drop_alarm_s.is_none() {
            self.events.drop_alarm_s = self.alarms.drops_s.last().copied();
        }
        if self.events.dropped_s.is_none() {
            self.events.dropped_s = match (wrist, load, pad.lost) {
                (_, LoadCues { short: true, .. }, _) | (true, LoadCues { fell: true, .. }, _) => Some(time_s),
                (false, _, true) => self.events.lost_s,
                _ => None,
            };
        }
        self.events
    }

    /// The load the wrist must read this tick \[N\]: the object's weight once the hand has risen
    /// `lift_check_m` above where the carry began, else `None`.
    fn expected_load_n(&mut self, hand_height_m: f64, holding: bool) -> Option<f64> {
        if !holding {
            self.carry_start_height_m = None;
            return None;
        }
        let start = *self.carry_start_height_m.get_or_insert(hand_height_m);
        self.object_weight_n.filter(|_| hand_height_m - start >= self.config.lift_check_m)
    }

    /// The pad's cues this tick (all off once the pad has lost the object).
    fn pad_cues(&mut self, time_s: f64, force_n: f64, unloaded_n: f64, noise_n: f64, reference_n: f64) -> PadCues {
        if self.events.lost_s.is_some() {
            return PadCues::default();
        }
        let k = self.window_ticks(noise_n, reference_n);
        self.recent.push_back(force_n);
        while self.recent.len() > k {
            self.recent.pop_front();
        }
        let mean = self.recent.iter().sum::<f64>() / self.recent.len() as f64;
        self.averaged.push_back((time_s, mean));
        while self.averaged.front().is_some_and(|&(t, _)| time_s - t > self.config.fall_window_s + 1e-9) {
            self.averaged.pop_front();
        }

        let below_slip = mean < self.config.slip_fraction * reference_n;
        if below_slip && self.events.slip_start_s.is_none() {
            self.events.slip_start_s = Some(time_s);
        }
        let highest = self.averaged.iter().map(|&(_, m)| m).fold(f64::NEG_INFINITY, f64::max);
        let fell = highest - mean >= self.config.fall_fraction * reference_n;
        let lost_n = self.config.lost_force_n.max(Z * noise_n / (k as f64).sqrt());
        let mut lost = false;
        if mean - unloaded_n < lost_n {
            let since = *self.below_since.get_or_insert(time_s);
            if time_s - since >= self.config.lost_hold_s {
                self.events.lost_s = Some(since);
                self.events.slip_start_s.get_or_insert(since);
                lost = true;
            }
        } else {
            self.below_since = None;
        }
        PadCues { below_slip, fell, lost }
    }

    /// The events so far.
    pub fn events(&self) -> SlipEvents {
        self.events
    }

    /// The alarm episodes so far.
    pub fn alarms(&self) -> &Alarms {
        &self.alarms
    }
}

/// The pad's cues on one tick.
#[derive(Debug, Clone, Copy, Default)]
struct PadCues {
    /// The averaged estimate is below the slip warning's threshold.
    below_slip: bool,
    /// It fell by the drop alarm's fraction within the fall window.
    fell: bool,
    /// Contact is lost (this tick the loss was declared).
    lost: bool,
}

/// The drop alarms judged against the true drop (on the twin, which knows it).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct Judgement {
    /// From the true drop to the first drop alarm at most [`EARLY_S`] before it \[s\] (negative:
    /// the alarm came first); `None` when there was no drop or no such alarm.
    pub detection_delay_s: Option<f64>,
    /// Drop alarms no drop followed: every one in a run whose object was held, the ones more than
    /// [`EARLY_S`] before the drop in one that dropped it.
    pub false_alarms: u64,
}

/// Judges the drop-alarm episodes `drops_s` against the true drop at `drop_s` (cell times \[s\]).
pub fn judge(drops_s: &[f64], drop_s: Option<f64>) -> Judgement {
    match drop_s {
        None => Judgement { detection_delay_s: None, false_alarms: drops_s.len() as u64 },
        Some(d) => Judgement {
            detection_delay_s: drops_s.iter().find(|&&a| a >= d - EARLY_S).map(|a| a - d),
            false_alarms: drops_s.iter().filter(|&&a| a < d - EARLY_S).count() as u64,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gradual_fall_then_zero_gives_slip_then_loss() {
        let mut d = SlipDetector::new(SlipConfig::default());
        // 1.6 N held for 2 s, falls linearly to 0 over 4 s, stays at 0.
        for i in 0..1000 {
            let t = i as f64 * 0.01;
            let f = if t < 2.0 { 1.6 } else { (1.6 * (1.0 - (t - 2.0) / 4.0)).max(0.0) };
            d.update(t, f, ArmReading::default(), 0.0, 0.0, 1.6, true);
        }
        let e = d.events();
        assert!((e.slip_start_s.unwrap() - 4.0).abs() < 0.02, "{e:?}");
        assert!((e.lost_s.unwrap() - 5.88).abs() < 0.03, "{e:?}");
    }

    #[test]
    fn brief_dips_and_non_holding_phases_are_ignored() {
        let mut d = SlipDetector::new(SlipConfig::default());
        for i in 0..100 {
            let t = i as f64 * 0.01;
            let f = if i % 10 == 0 { 0.0 } else { 1.0 };
            d.update(t, f + 0.16, ArmReading::default(), 0.16, 0.0, 1.0, true);
        }
        assert_eq!(d.events().lost_s, None);
        d.update(1.0, 0.0, ArmReading::default(), 0.0, 0.0, 1.0, false);
        d.update(2.0, 0.0, ArmReading::default(), 0.0, 0.0, 1.0, false);
        assert_eq!(d.events().lost_s, None);
    }

    /// 100 Hz ticks of `f(t)` for `seconds`, plus noise of SD `sigma`, all while holding.
    fn feed(d: &mut SlipDetector, seconds: f64, sigma: f64, f: impl Fn(f64) -> f64) {
        let n = (seconds * 100.0) as usize;
        for (i, e) in crate::contact::gaussian(sigma, n, 11).into_iter().enumerate() {
            let t = i as f64 * 0.01;
            d.update(t, f(t) + e, ArmReading::default(), 0.16, sigma, 0.6, true);
        }
    }

    #[test]
    fn a_sudden_fall_raises_a_drop_alarm_and_the_same_fall_as_a_creep_does_not() {
        let mut sudden = SlipDetector::new(SlipConfig::default());
        feed(&mut sudden, 10.0, 0.0, |t| if t < 5.0 { 0.76 } else { 0.36 });
        assert_eq!(sudden.alarms().drops_s, vec![5.0]);
        let mut creep = SlipDetector::new(SlipConfig::default());
        feed(&mut creep, 10.0, 0.0, |t| 0.76 - 0.05 * t);
        assert!(creep.alarms().drops_s.is_empty(), "{:?}", creep.alarms());
        assert!(creep.events().slip_start_s.is_some(), "the creep still warns of slip");
    }

    #[test]
    fn thirty_pm_of_noise_raises_no_alarm_on_a_steady_grip_and_still_sees_the_drop() {
        // 0.11 N: the estimate's SD at 30 pm of interrogator noise (measured on the twin).
        let mut d = SlipDetector::new(SlipConfig::default());
        assert!(d.window_ticks(0.11, 0.6) > 5, "{}", d.window_ticks(0.11, 0.6));
        feed(&mut d, 20.0, 0.11, |t| if t < 15.0 { 0.76 } else { 0.16 });
        assert_eq!(d.alarms().warnings_s.len(), 1, "{:?}", d.alarms());
        let first = d.alarms().drops_s[0];
        assert!((15.0..15.3).contains(&first), "{:?}", d.alarms());
    }

    /// A detector that learnt the wrist's noise (0.78 N, the default per tick) at home, fed 10 s
    /// of `pad(t)` and a wrist reading of `load(t)` with that noise, all while holding.
    fn with_wrist(pad: impl Fn(f64) -> f64, load: impl Fn(f64) -> f64) -> SlipDetector {
        let mut d = SlipDetector::new(SlipConfig::default());
        for e in crate::contact::gaussian(0.78, 50, 5) {
            d.observe_home_load(Some(e));
        }
        for (i, e) in crate::contact::gaussian(0.78, 1000, 9).into_iter().enumerate() {
            let t = i as f64 * 0.01;
            let arm = ArmReading { tool_load_n: Some(load(t) + e), hand_height_m: 0.0 };
            d.update(t, pad(t), arm, 0.16, 0.0, 0.6, true);
        }
        d
    }

    #[test]
    fn with_the_wrist_armed_the_pads_loss_only_warns_and_the_loads_fall_raises_the_drop_alarm() {
        // The pad's load creeps away between 1 and 3 s (the object hangs on the pinch); the hand
        // carries 3.4 N until 6 s.
        let d = with_wrist(|t| 0.76 - 0.3 * (t - 1.0).clamp(0.0, 2.0), |t| if t < 6.0 { 3.4 } else { 0.0 });
        let (events, alarms) = (d.events(), d.alarms());
        assert!(events.lost_s.is_some_and(|t| (2.7..3.0).contains(&t)), "{events:?}");
        assert!(alarms.warnings_s.first().is_some_and(|t| (2.4..2.6).contains(t)), "{alarms:?}");
        assert_eq!(alarms.drops_s.len(), 1, "{alarms:?}");
        assert!((6.0..6.1).contains(&alarms.drops_s[0]), "{alarms:?}");
        assert_eq!(events.dropped_s, Some(alarms.drops_s[0]));
        assert_eq!(events.drop_alarm_s, Some(alarms.drops_s[0]));
    }

    #[test]
    fn with_the_wrist_armed_a_sudden_fall_of_the_pad_still_raises_the_drop_alarm() {
        // A knock unloads the pad at once at 3 s; the object slides down the grip while the hand
        // still carries it.
        let d = with_wrist(|t| if t < 3.0 { 0.76 } else { 0.16 }, |_| 3.4);
        assert_eq!(d.alarms().drops_s, vec![3.0], "{:?}", d.alarms());
        assert_eq!(d.events().dropped_s, None, "the hand still carries the object");
    }

    /// A detector that learnt the wrist's noise at home and was told a 3.4 N object, fed 6 s of
    /// the hand rising at 10 mm/s from 1 s, a steady pad, and a wrist reading of `load(height)`.
    fn lifting(weight_known: bool, load: impl Fn(f64) -> f64) -> SlipDetector {
        let mut d = SlipDetector::new(SlipConfig::default());
        if weight_known {
            d = d.with_object_weight(3.4);
        }
        for e in crate::contact::gaussian(0.78, 50, 5) {
            d.observe_home_load(Some(e));
        }
        for (i, e) in crate::contact::gaussian(0.78, 600, 13).into_iter().enumerate() {
            let t = i as f64 * 0.01;
            let rise_m = 0.01 * (t - 1.0).max(0.0);
            let arm = ArmReading { tool_load_n: Some(load(rise_m) + e), hand_height_m: 0.4 + rise_m };
            d.update(t, 0.76, arm, 0.16, 0.0, 0.6, true);
        }
        d
    }

    #[test]
    fn an_object_the_hand_did_not_take_up_is_a_drop_once_the_hand_has_risen_the_lift_check() {
        // A slick object stays on the table: the wrist reads the grip's 0.5 N drag, the pad keeps
        // its load. The hand passes 20 mm at 3 s.
        let slick = lifting(true, |_| 0.5);
        assert_eq!(slick.alarms().drops_s.len(), 1, "{:?}", slick.alarms());
        assert!((3.0..3.1).contains(&slick.alarms().drops_s[0]), "{:?}", slick.alarms());
        assert_eq!(slick.events().dropped_s, Some(slick.alarms().drops_s[0]));
        // Taken up within the first 3 mm, the same lift raises nothing.
        let carried = lifting(true, |rise| 3.4 * (rise / 0.003).min(1.0));
        assert!(carried.alarms().drops_s.is_empty(), "{:?}", carried.alarms());
        // Without the object's weight the detector cannot know what the hand should carry.
        let unknown = lifting(false, |_| 0.5);
        assert!(unknown.alarms().drops_s.is_empty(), "{:?}", unknown.alarms());
    }

    #[test]
    fn without_a_wrist_reading_the_pads_loss_is_the_drop() {
        let mut d = SlipDetector::new(SlipConfig::default());
        d.observe_home_load(None);
        for i in 0..600 {
            let t = i as f64 * 0.01;
            d.update(t, if t < 3.0 { 0.76 } else { 0.16 }, ArmReading::default(), 0.16, 0.0, 0.6, true);
        }
        let events = d.events();
        assert!(events.lost_s.is_some_and(|t| (3.0..3.05).contains(&t)), "{events:?}");
        assert_eq!(events.dropped_s, events.lost_s);
        assert_eq!(d.alarms().drops_s.first().copied(), events.lost_s);
    }

    #[test]
    fn alarms_are_judged_against_the_true_drop() {
        assert_eq!(judge(&[1.0, 4.0], None), Judgement { detection_delay_s: None, false_alarms: 2 });
        let j = judge(&[1.0, 9.8, 12.0], Some(10.0));
        assert_eq!(j.false_alarms, 1);
        assert!((j.detection_delay_s.unwrap() + 0.2).abs() < 1e-12);
        assert_eq!(judge(&[], Some(10.0)).detection_delay_s, None);
    }
}
