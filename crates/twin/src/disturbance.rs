//! Disturbances the twin can inflict on a run (TOML `[disturbance]`): a push on the object and a
//! gap in the interrogator's peak stream. Both exist on the simulated cell only: the sim cell gets
//! the schedule at construction (`tendril_run`'s `PickPlaceScenario::sim_cell`) and the real path
//! refuses a scenario that configures one ([`DisturbanceConfig::refuse_on_real`]).
//!
//! Each is off unless its sub-table is given, so a scenario without `[disturbance]` runs exactly
//! as before. A disturbance starts either at a cell time (`time_s`) or at an offset after the task
//! enters a phase (`phase` + `offset_s`); the runner tells the cell when each phase starts
//! ([`tendril_cell::Cell::phase_started`]).
//!
//! ```toml
//! [disturbance.push]          # a 0.3 N·s knock along world +y, 1 s into the transfer
//! impulse_n_s = 0.3
//! direction_deg = 90.0
//! phase = "transfer"
//! offset_s = 1.0
//!
//! [disturbance.dropout]       # 0.5 s without interrogator samples, 2 s into the lift
//! phase = "lift"
//! offset_s = 2.0
//! duration_s = 0.5
//! ```

use serde::{Deserialize, Serialize};
use tendril_cell::{MAX_PHASE_S, Phase};
use tendril_config::{Checker, Validate};

/// The scenario's disturbances (TOML `[disturbance]`); both off by default.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DisturbanceConfig {
    /// A push on the object (`[disturbance.push]`), off when absent.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub push: Option<PushConfig>,
    /// A gap in the interrogator's sample stream (`[disturbance.dropout]`), off when absent.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dropout: Option<DropoutConfig>,
}

impl DisturbanceConfig {
    /// Whether any disturbance is configured.
    pub fn any(&self) -> bool {
        self.push.is_some() || self.dropout.is_some()
    }

    /// The error for a run on the real cell: disturbances only exist on the twin (nobody stands by
    /// the real cell to knock the object on cue, and a real interrogator's gaps are its own).
    pub fn refuse_on_real(&self) -> Result<(), String> {
        let mut given = vec![];
        if self.push.is_some() {
            given.push("disturbance.push");
        }
        if self.dropout.is_some() {
            given.push("disturbance.dropout");
        }
        if given.is_empty() {
            Ok(())
        } else {
            Err(format!(
                "{} configured: disturbances exist only on the simulated cell; remove the section \
                 (or `--set`) to run on the real hardware",
                given.join(" and ")
            ))
        }
    }
}

impl Validate for DisturbanceConfig {
    fn validate(&self, at: &mut Checker) {
        if let Some(push) = &self.push {
            at.section("push", push);
        }
        if let Some(dropout) = &self.dropout {
            at.section("dropout", dropout);
        }
    }
}

/// When a disturbance starts: `time_s`, or `phase` + `offset_s` (exactly one of `time_s` and
/// `phase`). The keys sit directly in the disturbance's table.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Onset {
    /// Cell time of the start \[s\].
    pub time_s: Option<f64>,
    /// The phase whose start the onset counts from.
    pub phase: Option<Phase>,
    /// Delay after the phase starts \[s\].
    pub offset_s: f64,
}

/// Latest onset accepted \[s\]: the longest task is nine phases of [`MAX_PHASE_S`] at most.
pub const MAX_ONSET_S: f64 = 9.0 * MAX_PHASE_S;

impl Validate for Onset {
    fn validate(&self, at: &mut Checker) {
        match (self.time_s, self.phase) {
            (Some(_), Some(_)) => at.require("time_s", false, || "give either `time_s` or `phase`, not both".into()),
            (None, None) => at.require("phase", false, || {
                "the start is missing: give `time_s` [s] or `phase` (and `offset_s` [s])".into()
            }),
            (Some(t), None) => {
                // After 0: the sensor is tared on the first samples at home.
                at.in_range("time_s", t, 0.0, MAX_ONSET_S);
                at.require("offset_s", self.offset_s == 0.0, || "`offset_s` needs `phase`".into());
            }
            (None, Some(phase)) => {
                at.require("phase", !matches!(phase, Phase::Home | Phase::Done), || {
                    format!("`{}` cannot start a disturbance: home is the tare, done is after the run", phase.name())
                });
                at.in_range("offset_s", self.offset_s, 0.0, MAX_PHASE_S);
            }
        }
    }
}

impl Onset {
    /// The cell time of the onset once it is known: `time_s`, or the phase's start plus the offset
    /// (`None` until the phase has started).
    pub fn resolve(&self, phase_start_s: impl Fn(Phase) -> Option<f64>) -> Option<f64> {
        match (self.time_s, self.phase) {
            (Some(t), _) => Some(t),
            (None, Some(p)) => phase_start_s(p).map(|t| t + self.offset_s),
            (None, None) => None,
        }
    }
}

/// A push on the object (TOML `[disturbance.push]`): a constant horizontal force over
/// `duration_s` whose time integral is `impulse_n_s`, applied at the object's centre of mass
/// (MuJoCo's `xfrc_applied`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PushConfig {
    /// Impulse [N·s]. The issue's knock: 0.3 N·s (0.7 m/s on the 419 g hammer were it free).
    pub impulse_n_s: f64,
    /// Horizontal direction of the push [°], in the world frame: 0 is +x, 90 is +y.
    #[serde(default)]
    pub direction_deg: f64,
    /// How long the force acts \[s\]. Default 20 ms: a knock, short against the grip's response
    /// (≈ 2 s time constant) yet four 5 ms physics steps, so the contacts resolve it. Rounded to
    /// whole physics steps (at least one); the force is scaled so the impulse is exact.
    #[serde(default = "default_push_duration")]
    pub duration_s: f64,
    /// Cell time of the start \[s\] (cell time counts from activation, 0 at the start of the
    /// task); or give `phase`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_s: Option<f64>,
    /// The phase whose start the onset counts from (`"lift"`, `"transfer"`...); or give `time_s`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub phase: Option<Phase>,
    /// Delay after the phase starts \[s\]; only with `phase`. Default 0.
    #[serde(default)]
    pub offset_s: f64,
}

fn default_push_duration() -> f64 {
    0.02
}

/// Largest impulse accepted [N·s]: 5 N·s stops a 1 kg object moving at 5 m/s, far beyond any knock
/// a hand-held object survives; the issue asks for 0.3.
pub const MAX_IMPULSE_N_S: f64 = 5.0;

impl Validate for PushConfig {
    fn validate(&self, at: &mut Checker) {
        at.in_range("impulse_n_s", self.impulse_n_s, 0.0, MAX_IMPULSE_N_S);
        at.in_range("direction_deg", self.direction_deg, -360.0, 360.0);
        // 1 ms .. 1 s: from a tap to a steady shove (longer is a load, not a knock).
        at.in_range("duration_s", self.duration_s, 1e-3, 1.0);
        self.onset().validate(at);
    }
}

impl PushConfig {
    /// The knock `tendril view` applies when the scenario has no `[disturbance.push]`: the
    /// issue's 0.3 N·s along world +y over the default 20 ms (its start is set when it is asked
    /// for).
    pub fn default_knock() -> PushConfig {
        PushConfig {
            impulse_n_s: 0.3,
            direction_deg: 90.0,
            duration_s: default_push_duration(),
            time_s: None,
            phase: None,
            offset_s: 0.0,
        }
    }

    /// When the push starts.
    pub fn onset(&self) -> Onset {
        Onset { time_s: self.time_s, phase: self.phase, offset_s: self.offset_s }
    }

    /// The world-frame force \[N\] for a push spread over `steps` physics steps of `dt_s`.
    pub fn force_n(&self, steps: usize, dt_s: f64) -> [f64; 3] {
        let magnitude = self.impulse_n_s / (steps.max(1) as f64 * dt_s);
        let (s, c) = self.direction_deg.to_radians().sin_cos();
        [magnitude * c, magnitude * s, 0.0]
    }

    /// Number of physics steps of `dt_s` the push lasts (at least one).
    pub fn steps(&self, dt_s: f64) -> usize {
        ((self.duration_s / dt_s).round() as usize).max(1)
    }
}

/// A gap in the interrogator's peak stream (TOML `[disturbance.dropout]`).
///
/// During the gap the interrogator delivers no new sample: the cell keeps reporting the last one
/// and says it is not new ([`tendril_cell::Cell::sample_is_new`]); the runner holds the last
/// estimate and counts the tick in `dropped_samples`. A missing sample is not an invalid one (a
/// NaN peak, a reading below the calibration curve): it does not count towards
/// `MAX_CONSECUTIVE_INVALID_SAMPLES`, as a late packet is not a broken fibre; `duration_s` is
/// bounded instead. The sensor model keeps running underneath (its noise and thermal state
/// advance), so after the gap the samples are those of the undisturbed run.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DropoutConfig {
    /// Length of the gap \[s\].
    pub duration_s: f64,
    /// The start's cell time \[s\], as [`PushConfig::time_s`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_s: Option<f64>,
    /// The start's phase, as [`PushConfig::phase`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub phase: Option<Phase>,
    /// The start's delay after the phase \[s\], as [`PushConfig::offset_s`].
    #[serde(default)]
    pub offset_s: f64,
}

/// Longest dropout accepted \[s\]: 5 s, two and a half closed-loop time constants (≈ 2 s) flying
/// blind; a longer silence is a failed interrogator, which should stop the run.
pub const MAX_DROPOUT_S: f64 = 5.0;

impl Validate for DropoutConfig {
    fn validate(&self, at: &mut Checker) {
        at.in_range("duration_s", self.duration_s, 1e-3, MAX_DROPOUT_S);
        self.onset().validate(at);
    }
}

impl DropoutConfig {
    /// When the gap starts.
    pub fn onset(&self) -> Onset {
        Onset { time_s: self.time_s, phase: self.phase, offset_s: self.offset_s }
    }
}

/// The twin's disturbance schedule during a run: resolves phase-relative onsets as the phases
/// start and answers what to apply at a given time.
#[derive(Debug, Clone, Default)]
pub struct DisturbanceSchedule {
    config: DisturbanceConfig,
    phase_starts: Vec<(Phase, f64)>,
    /// Knocks asked for during the run ([`DisturbanceSchedule::knock`]), each with its start.
    knocks: Vec<PushConfig>,
}

impl DisturbanceSchedule {
    /// A schedule for `config`, no phase started yet.
    pub fn new(config: DisturbanceConfig) -> Self {
        DisturbanceSchedule { config, phase_starts: vec![], knocks: vec![] }
    }

    /// Whether nothing is scheduled (the cell then runs exactly as without disturbances).
    pub fn is_empty(&self) -> bool {
        !self.config.any()
    }

    /// Forgets the phases seen (a new run on the same cell).
    pub fn restart(&mut self) {
        self.phase_starts.clear();
        self.knocks.clear();
    }

    /// Adds a knock starting at cell time `time_s` (`tendril view`'s key): the impulse, direction
    /// and duration of the scenario's `[disturbance.push]`, or [`PushConfig::default_knock`]'s
    /// when it has none. It comes on top of any scheduled push.
    pub fn knock(&mut self, time_s: f64) {
        let mut knock = self.config.push.unwrap_or_else(PushConfig::default_knock);
        knock.time_s = Some(time_s);
        knock.phase = None;
        knock.offset_s = 0.0;
        self.knocks.push(knock);
    }

    /// Records that the task entered `phase` at `time_s` (the first entry counts).
    pub fn phase_started(&mut self, phase: Phase, time_s: f64) {
        if !self.phase_starts.iter().any(|(p, _)| *p == phase) {
            self.phase_starts.push((phase, time_s));
        }
    }

    fn start_of(&self, onset: &Onset) -> Option<f64> {
        onset.resolve(|p| self.phase_starts.iter().find(|(q, _)| *q == p).map(|(_, t)| *t))
    }

    /// The force on the object \[N\] for the physics step starting at `time_s` of length `dt_s`:
    /// the push's force on the `steps(dt_s)` steps from its onset (a step belongs to the push when
    /// its start lies within half a step of the push's span), zero otherwise.
    /// Knocks ([`DisturbanceSchedule::knock`]) overlapping it add their force.
    pub fn push_force_n(&self, time_s: f64, dt_s: f64) -> Option<[f64; 3]> {
        let scheduled = self.config.push.as_ref().and_then(|push| self.one_push_force_n(push, time_s, dt_s));
        self.knocks.iter().filter_map(|k| self.one_push_force_n(k, time_s, dt_s)).fold(scheduled, |sum, f| {
            Some(match sum {
                Some(s) => [s[0] + f[0], s[1] + f[1], s[2] + f[2]],
                None => f,
            })
        })
    }

    /// The force of `push` alone on the step starting at `time_s`, if the step belongs to it.
    fn one_push_force_n(&self, push: &PushConfig, time_s: f64, dt_s: f64) -> Option<[f64; 3]> {
        let start = self.start_of(&push.onset())?;
        let steps = push.steps(dt_s);
        let first = start - 0.5 * dt_s;
        let inside = time_s >= first && time_s < first + steps as f64 * dt_s;
        inside.then(|| push.force_n(steps, dt_s))
    }

    /// Whether an interrogator sample at `time_s` is lost in the dropout.
    pub fn sample_dropped(&self, time_s: f64) -> bool {
        let Some(dropout) = self.config.dropout.as_ref() else { return false };
        self.start_of(&dropout.onset()).is_some_and(|start| time_s >= start && time_s < start + dropout.duration_s)
    }

    /// Whether a push is configured or a knock was asked for.
    pub fn has_push(&self) -> bool {
        self.config.push.is_some() || !self.knocks.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn push(at: Onset) -> PushConfig {
        PushConfig {
            impulse_n_s: 0.3,
            direction_deg: 90.0,
            duration_s: 0.02,
            time_s: at.time_s,
            phase: at.phase,
            offset_s: at.offset_s,
        }
    }

    #[test]
    fn the_push_delivers_its_impulse_over_whole_steps_once_its_phase_started() {
        let at = Onset { time_s: None, phase: Some(Phase::Transfer), offset_s: 1.0 };
        let mut s = DisturbanceSchedule::new(DisturbanceConfig { push: Some(push(at)), dropout: None });
        let dt = 0.005;
        assert_eq!(s.push_force_n(12.0, dt), None, "phase not started");
        s.phase_started(Phase::Transfer, 11.0);
        let mut impulse = [0.0; 3];
        for k in 0..1000 {
            if let Some(f) = s.push_force_n(11.5 + k as f64 * dt, dt) {
                for i in 0..3 {
                    impulse[i] += f[i] * dt;
                }
            }
        }
        assert!(impulse[0].abs() < 1e-12 && (impulse[1] - 0.3).abs() < 1e-12, "{impulse:?}");
        assert!(s.push_force_n(12.0, dt).is_some() && s.push_force_n(12.02, dt).is_none());
    }

    #[test]
    fn a_knock_adds_its_impulse_on_top_of_the_scheduled_push() {
        let at = Onset { time_s: Some(2.0), phase: None, offset_s: 0.0 };
        let mut s = DisturbanceSchedule::new(DisturbanceConfig { push: Some(push(at)), dropout: None });
        let dt = 0.005;
        s.knock(2.0);
        s.knock(5.0);
        let mut impulse = [0.0; 3];
        for k in 0..2000 {
            if let Some(f) = s.push_force_n(k as f64 * dt, dt) {
                for i in 0..3 {
                    impulse[i] += f[i] * dt;
                }
            }
        }
        // The scheduled push and two knocks of its size, one overlapping it.
        assert!(impulse[0].abs() < 1e-12 && (impulse[1] - 0.9).abs() < 1e-12, "{impulse:?}");
        assert!(s.push_force_n(5.0, dt).is_some() && s.push_force_n(4.0, dt).is_none());
        s.restart();
        assert!(s.push_force_n(5.0, dt).is_none(), "a restart forgets the knocks");
    }

    #[test]
    fn without_a_push_a_knock_has_the_default_size() {
        let mut s = DisturbanceSchedule::default();
        assert!(!s.has_push());
        s.knock(1.0);
        assert!(s.has_push());
        let dt = 0.005;
        let total: f64 = (0..400).filter_map(|k| s.push_force_n(k as f64 * dt, dt)).map(|f| f[1] * dt).sum();
        assert!((total - PushConfig::default_knock().impulse_n_s).abs() < 1e-12, "{total}");
    }

    #[test]
    fn the_dropout_covers_its_span() {
        let at = Onset { time_s: Some(2.0), phase: None, offset_s: 0.0 };
        let s = DisturbanceSchedule::new(DisturbanceConfig {
            push: None,
            dropout: Some(DropoutConfig { duration_s: 0.5, time_s: at.time_s, phase: at.phase, offset_s: at.offset_s }),
        });
        assert!(!s.sample_dropped(1.999) && s.sample_dropped(2.0) && s.sample_dropped(2.499));
        assert!(!s.sample_dropped(2.5));
    }
}
