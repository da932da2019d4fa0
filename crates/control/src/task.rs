//! The paper's pick-and-place sequence (Sec. V-B, Fig. 6) as a time- and event-driven state
//! machine: home → grow → wrap → grasp under force control → lift → transfer → lower → release.
//!
//! Each tick the sequencer takes the cell's state and the force estimate and returns the
//! command. It never sees the true force: control runs on the sensor, as on the real cell.

use super::contact::ContactDetector;
use super::controller::{ArmMotion, ControlContext, ForceController, MoveOutlook};
use super::hold::{Grip, HoldConfig};
use super::settle::{GraspEnd, SettleConfig, SettleWatch};
use super::trajectory::{JointLimits, JointMove};
use serde::{Deserialize, Serialize};
use tendril_cell::gripper::{GripperConfig, MX106_MAX_SPEED_DEG_S};
use tendril_cell::{ARM_JOINTS, CellCommand, CellState};
pub use tendril_cell::{MAX_PHASE_S, Phase};
use tendril_config::{Checker, Validate};

/// The task's poses and timing (TOML `[task]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TaskConfig {
    /// Home pose above the object [°]: the UR5e's common home (docs/facts.md#ur5e-home-pose).
    pub home_deg: [f64; ARM_JOINTS],
    /// Pose at the top of the lift [°]: shoulder and elbow raise the tool about 15 cm.
    pub lift_deg: [f64; ARM_JOINTS],
    /// Pose above the collection site [°]: base turned 60° from the lift pose.
    pub transfer_deg: [f64; ARM_JOINTS],
    /// Pose at the collection site [°]: the lift reversed at the new base angle, stopping ≈ 1.5 cm
    /// (a tenth of the lift) above the table, from where the release lets the object down: an object
    /// that slipped a few millimetres in the hand would otherwise be pushed into the table at the
    /// end of the lowering, loading the pad by up to 3× the setpoint while the arm still moves
    /// (tuned so that the fluctuation while moving is the grip's, as in the paper's Fig. 9).
    pub place_deg: [f64; ARM_JOINTS],
    /// Time at home before growing, while the sensor is tared \[s\].
    pub settle_s: f64,
    /// Finger growth \[m\]. Paper Sec. V-B: 14.0 cm.
    pub growth_m: f64,
    /// Growth feed speed [m/s]. 5 cm/s is a quarter of what the MX-106 (45 rpm) gives on a
    /// 12 mm pinion, a gentle feed for a soft strip.
    pub growth_speed_m_s: f64,
    /// Twine speed of the guarded close before force control [°/s]. Tuned: 15 °/s (4.2 mm/s of
    /// tendon on the 16 mm spool, below the 7.5 mm/s the physics tests wind at) so the close stops
    /// near first contact, well below the setpoint, and the PID does the rise, as in the paper
    /// (at the PID's own limit, 90 °/s, the close overshot every setpoint before the PID started).
    pub wrap_speed_deg_s: f64,
    /// Rise of the force estimate above its unloaded reading that ends the guarded close \[N\]:
    /// first contact. 0.1 N is 40× the noise-limited resolution (paper: 2.57 mN), well clear of
    /// noise, and a sixth of the smallest setpoint (0.6 N), early enough to start force control.
    /// Noisier readings are averaged and the threshold raised ([`super::contact`]).
    pub wrap_contact_n: f64,
    /// Longest guarded close \[s\]; past it the grasp starts anyway (and will likely fail).
    pub wrap_timeout_s: f64,
    /// Grasp period under force control before the arm moves \[s\]. Paper Sec. V-B: 15 s. With
    /// `settled_grasp.enabled` the grasp ends once settled instead.
    pub grasp_s: f64,
    /// Shortest lift duration \[s\]. The paper reports the crimper dropping "during the upward
    /// motion" at ≈ 10 s after the arm started: the lift lasts 11 s.
    pub lift_s: f64,
    /// Shortest transfer duration \[s\]: the shampoo bottle slips "during the horizontal transfer"
    /// at ≈ 13 s, so the transfer spans 11-16 s.
    pub transfer_s: f64,
    /// Shortest lowering duration \[s\]: the hammer falls "as the arm approaches the collection
    /// site" at ≈ 17 s, so the approach spans 16-21 s.
    pub lower_s: f64,
    /// Time to uncurl the finger at the end \[s\].
    pub release_s: f64,
    /// Joint speed and acceleration limits during the moves.
    pub limits: JointLimits,
    /// Whether the moves last at least `lift_s`, `transfer_s` and `lower_s` (default `true`: the
    /// paper's timing). `false` plans every move time-optimal at `limits`, the paper's 45 °/s and
    /// 15 °/s² by default: the arm then moves as hard as the limits allow, and the phase
    /// durations are the moves' (a few seconds each) instead of the paper's drop times.
    pub minimum_durations: bool,
    /// Grasp until settled instead of for `grasp_s` (off by default: the paper's fixed grasp).
    pub settled_grasp: SettleConfig,
    /// How a long grasp holds: it lets go of the object waiting on the table and re-wraps it.
    pub hold: HoldConfig,
}

impl Default for TaskConfig {
    fn default() -> Self {
        TaskConfig {
            home_deg: [-90.0, -90.0, 90.0, -90.0, -90.0, 0.0],
            lift_deg: [-90.0, -100.0, 80.0, -70.0, -90.0, 0.0],
            transfer_deg: [-30.0, -100.0, 80.0, -70.0, -90.0, 0.0],
            place_deg: [-30.0, -91.0, 89.0, -88.0, -90.0, 0.0],
            settle_s: 0.5,
            growth_m: 0.14,
            growth_speed_m_s: 0.05,
            wrap_speed_deg_s: 15.0,
            wrap_contact_n: 0.1,
            wrap_timeout_s: 20.0,
            grasp_s: 15.0,
            lift_s: 11.0,
            transfer_s: 5.0,
            lower_s: 5.0,
            release_s: 2.0,
            limits: JointLimits::default(),
            minimum_durations: true,
            settled_grasp: SettleConfig::default(),
            hold: HoldConfig::default(),
        }
    }
}

impl Validate for TaskConfig {
    fn validate(&self, at: &mut Checker) {
        for (name, pose) in [
            ("home_deg", &self.home_deg),
            ("lift_deg", &self.lift_deg),
            ("transfer_deg", &self.transfer_deg),
            ("place_deg", &self.place_deg),
        ] {
            // UR5e joint limits ±360° (docs/facts.md#ur5e-joint-limits).
            at.require(name, pose.iter().all(|q| q.is_finite() && q.abs() <= 360.0), || {
                format!("every joint angle must lie within ±360°, got {pose:?}")
            });
        }
        at.in_range("settle_s", self.settle_s, 0.0, MAX_PHASE_S);
        at.in_range("growth_m", self.growth_m, 0.0, 0.3);
        // 1 m/s: faster than any servo and pinion feeds a soft strip (the default is 5 cm/s);
        // the growth must also finish within a phase.
        at.in_range("growth_speed_m_s", self.growth_speed_m_s, 1e-6, 1.0);
        at.require("growth_speed_m_s", self.growth_m / self.growth_speed_m_s <= MAX_PHASE_S, || {
            format!(
                "growing {} m at {} m/s would take longer than {MAX_PHASE_S} s",
                self.growth_m, self.growth_speed_m_s
            )
        });
        at.in_range("wrap_speed_deg_s", self.wrap_speed_deg_s, 1e-3, MX106_MAX_SPEED_DEG_S);
        at.positive("wrap_contact_n", self.wrap_contact_n);
        at.in_range("wrap_timeout_s", self.wrap_timeout_s, 1e-3, MAX_PHASE_S);
        for (name, value) in [
            ("grasp_s", self.grasp_s),
            ("lift_s", self.lift_s),
            ("transfer_s", self.transfer_s),
            ("lower_s", self.lower_s),
            ("release_s", self.release_s),
        ] {
            at.in_range(name, value, 0.0, MAX_PHASE_S);
        }
        at.section("limits", &self.limits);
        at.section("settled_grasp", &self.settled_grasp);
        at.section("hold", &self.hold);
        // Slow joint limits stretch the moves: each must still fit in a phase.
        let moves = [
            (&self.home_deg, &self.lift_deg),
            (&self.lift_deg, &self.transfer_deg),
            (&self.transfer_deg, &self.place_deg),
        ];
        for (from, to) in moves {
            let duration_s = JointMove::plan(radians(from), radians(to), &self.limits, 0.0).duration_s();
            at.require("limits", duration_s.is_nan() || duration_s <= MAX_PHASE_S, || {
                format!("an arm move within these limits takes {duration_s:.0} s, longer than {MAX_PHASE_S} s")
            });
        }
    }
}

/// What the sequencer decided this tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TickDecision {
    /// The command for the cell.
    pub command: CellCommand,
    /// The phase this tick belongs to.
    pub phase: Phase,
    /// The force controller's output [°/s], 0 when it is off.
    pub controller_output_deg_s: f64,
    /// Whether the force controller ran this tick.
    pub controller_on: bool,
    /// The force setpoint this tick \[N\] (the scenario's unless a [`ControlAction::Setpoint`]).
    pub setpoint_n: f64,
}

/// What drives the force loop in one [`TaskSequencer::update_with`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum ControlAction {
    /// The force controller acts.
    #[default]
    Controller,
    /// This twine speed [°/s] instead of the controller's output (clamped to its speed limit);
    /// the controller is not updated.
    TwineSpeed(f64),
    /// The controller acts on this setpoint \[N\] instead of the task's.
    Setpoint(f64),
}

/// Runs the task. Create one per run.
#[derive(Debug)]
pub struct TaskSequencer {
    task: TaskConfig,
    gripper: GripperConfig,
    controller: Box<dyn ForceController>,
    setpoint_n: f64,
    feedback_while_moving: bool,
    phase: Phase,
    phase_start_s: f64,
    arm_move: Option<JointMove>,
    twine_deg: f64,
    growth_m: f64,
    motion_start_s: Option<f64>,
    unloaded_n: f64,
    /// First contact of the guarded close, robust to the estimate's noise.
    contact: ContactDetector,
    /// The lift, planned when the grasp starts (what the controller is told is ahead).
    next_move: Option<JointMove>,
    /// Whether the estimate has settled, with `task.settled_grasp`.
    settle: SettleWatch,
    /// What the grasp came to: how long it lasted and how it ended, once it has.
    grasp: Option<GraspOutcome>,
    /// Where a long grasp stands with its object (`task.hold`), the twine it let go at \[°\] and
    /// when its re-wrap started.
    grip: Grip,
    released_twine_deg: f64,
    rewrap_start_s: f64,
    /// How often the grasp let go, and how far the twine went.
    hold: HoldRecord,
}

/// How the grasp ended and how long it lasted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GraspOutcome {
    /// How it ended: [`GraspEnd::Settled`] also for the paper's fixed grasp run to its end.
    pub end: GraspEnd,
    /// Its length \[s\].
    pub duration_s: f64,
}

/// What the run's long hold did (`task.hold`) and how far the twine went.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct HoldRecord {
    /// Times the grasp let go of the waiting object (and wrapped it again).
    pub releases: u32,
    /// Cell time the twine first reached the end of its travel \[s\], if it did.
    pub travel_end_s: Option<f64>,
    /// The largest twine while the arm was still (the grasp), as a fraction of its travel [-].
    pub max_grasp_travel: f64,
    /// The largest twine over the run, as a fraction of its travel [-].
    pub max_travel: f64,
}

fn radians(deg: &[f64; ARM_JOINTS]) -> [f64; ARM_JOINTS] {
    deg.map(f64::to_radians)
}

impl TaskSequencer {
    /// A sequencer at the start of the task. `feedback_while_moving` keeps the force
    /// controller on during the arm's moves (the paper's second mode) or switches it off
    /// before the arm moves (the first mode). `controller` is the force controller (see
    /// [`crate::controller`]).
    pub fn new(
        task: TaskConfig,
        gripper: GripperConfig,
        controller: Box<dyn ForceController>,
        setpoint_n: f64,
        feedback_while_moving: bool,
    ) -> Self {
        let contact = ContactDetector::new(task.wrap_contact_n);
        TaskSequencer {
            task,
            gripper,
            controller,
            setpoint_n,
            feedback_while_moving,
            phase: Phase::Home,
            phase_start_s: 0.0,
            arm_move: None,
            twine_deg: 0.0,
            growth_m: 0.0,
            motion_start_s: None,
            unloaded_n: 0.0,
            contact,
            next_move: None,
            settle: SettleWatch::default(),
            grasp: None,
            grip: Grip::Holding,
            released_twine_deg: 0.0,
            rewrap_start_s: 0.0,
            hold: HoldRecord::default(),
        }
    }

    /// How the grasp ended and how long it lasted, once it has.
    pub fn grasp_outcome(&self) -> Option<GraspOutcome> {
        self.grasp
    }

    /// What the long hold did and how far the twine went.
    pub fn hold_record(&self) -> HoldRecord {
        self.hold
    }

    /// Sets what the estimator reads with nothing on the sensor \[N\] (the estimate at the tare);
    /// the guarded close looks for a rise above it.
    pub fn set_unloaded_reading(&mut self, force_n: f64) {
        self.unloaded_n = force_n;
    }

    /// The SD of the estimates at home, nothing on the sensor \[N\] (0 before two of them): the
    /// reading's noise, which the contact and slip detectors average against.
    pub fn reading_noise_n(&self) -> f64 {
        self.contact.noise_n()
    }

    /// Time to the arm's next move at cell time `now_s` \[s\] ([`MoveOutlook::time_to_motion_s`]).
    pub fn time_to_motion_s(&self, now_s: f64) -> f64 {
        self.outlook(now_s - self.phase_start_s).time_to_motion_s
    }

    /// The current phase.
    pub fn phase(&self) -> Phase {
        self.phase
    }

    /// The force setpoint \[N\].
    pub fn setpoint_n(&self) -> f64 {
        self.setpoint_n
    }

    /// Whether force control stays on while the arm moves (the paper's second mode).
    pub fn feedback(&self) -> bool {
        self.feedback_while_moving
    }

    /// Switches force control during the arm's moves on or off from the next tick on (a live
    /// view's key); the grasp is always controlled.
    pub fn set_feedback(&mut self, on: bool) {
        self.feedback_while_moving = on;
    }

    /// Cell time at which the arm started to move the object \[s\], once it has.
    pub fn motion_start_s(&self) -> Option<f64> {
        self.motion_start_s
    }

    fn enter(&mut self, phase: Phase, now: f64, arm_q: [f64; ARM_JOINTS]) {
        self.phase = phase;
        self.phase_start_s = now;
        self.arm_move = self.plan_move(phase, arm_q);
        self.next_move = match phase {
            Phase::Grasp => self.plan_move(Phase::Lift, arm_q),
            _ => None,
        };
        if phase == Phase::Lift {
            self.motion_start_s = Some(now);
            if !self.feedback_while_moving {
                self.controller.reset();
            }
        }
        if phase == Phase::Grasp {
            self.controller.reset();
        }
    }

    /// The pose the arm holds in a phase without a move \[rad\]: home until the lift, the place
    /// pose after the lowering.
    fn held_pose(&self) -> [f64; ARM_JOINTS] {
        match self.phase {
            Phase::Home | Phase::Grow | Phase::Wrap | Phase::Grasp => radians(&self.task.home_deg),
            // A grasp that failed lets go where it stood.
            _ if self.motion_start_s.is_none() => radians(&self.task.home_deg),
            _ => radians(&self.task.place_deg),
        }
    }

    /// The arm's move for `phase` (lift, transfer or lower) from `arm_q` \[rad\], if it has one.
    fn plan_move(&self, phase: Phase, arm_q: [f64; ARM_JOINTS]) -> Option<JointMove> {
        let t = &self.task;
        let (pose, min_s) = match phase {
            Phase::Lift => (&t.lift_deg, t.lift_s),
            Phase::Transfer => (&t.transfer_deg, t.transfer_s),
            Phase::Lower => (&t.place_deg, t.lower_s),
            _ => return None,
        };
        let min_s = if t.minimum_durations { min_s } else { 0.0 };
        Some(JointMove::plan(arm_q, radians(pose), &t.limits, min_s))
    }

    /// What lies ahead of the arm `elapsed` seconds into the current phase.
    fn outlook(&self, elapsed: f64) -> MoveOutlook {
        let (time_to_motion_s, plan) = match (self.phase, &self.arm_move, &self.next_move) {
            (Phase::Grasp, _, Some(next)) => (self.grasp_remaining_s(elapsed), next),
            (p, Some(current), _) if p.arm_moving() => (0.0, current),
            _ => return MoveOutlook::default(),
        };
        MoveOutlook {
            time_to_motion_s,
            peak_accel_rad_s2: plan.peak_accel_rad_s2(),
            peak_speed_rad_s: plan.peak_speed_rad_s(),
        }
    }

    /// Time left in the grasp `elapsed` seconds into it \[s\]: to its fixed end, or with
    /// `settled_grasp` the soonest it can settle.
    fn grasp_remaining_s(&self, elapsed: f64) -> f64 {
        let s = &self.task.settled_grasp;
        if s.enabled {
            self.settle.time_to_settled_s(s, self.phase_start_s + elapsed)
        } else {
            (self.task.grasp_s - elapsed).max(0.0)
        }
    }

    /// How the grasp ends this tick, if it does.
    fn grasp_end(&mut self, now: f64, elapsed: f64, force_n: f64) -> Option<GraspEnd> {
        let s = self.task.settled_grasp;
        if s.enabled {
            self.settle.update(&s, now, elapsed, force_n, self.setpoint_n)
        } else {
            (elapsed >= self.task.grasp_s).then_some(GraspEnd::Settled)
        }
    }

    /// One tick: `force_n` is the compensated force estimate, `dt_s` the tick period.
    pub fn update(&mut self, state: &CellState, force_n: f64, dt_s: f64) -> TickDecision {
        self.update_with(state, force_n, dt_s, ControlAction::Controller)
    }

    /// As [`TaskSequencer::update`], with the force loop driven by `action` this tick.
    pub fn update_with(&mut self, state: &CellState, force_n: f64, dt_s: f64, action: ControlAction) -> TickDecision {
        let now = state.time_s;
        let elapsed = now - self.phase_start_s;
        let arm_target = self.arm_move.as_ref().map(|m| m.end());
        if self.phase == Phase::Home {
            self.contact.observe_unloaded(force_n);
        }
        let touched = self.phase == Phase::Wrap && self.contact.touched(force_n - self.unloaded_n);
        let next = match self.phase {
            Phase::Home if elapsed >= self.task.settle_s => Some(Phase::Grow),
            Phase::Grow if self.growth_m >= self.task.growth_m => Some(Phase::Wrap),
            Phase::Wrap if touched || elapsed >= self.task.wrap_timeout_s => Some(Phase::Grasp),
            Phase::Grasp => self.grasp_end(now, elapsed, force_n).map(|end| {
                self.grasp = Some(GraspOutcome { end, duration_s: elapsed });
                match end {
                    GraspEnd::Settled => Phase::Lift,
                    // Fail safely: let go where the object stands, never lift it.
                    GraspEnd::TimedOut => Phase::Release,
                }
            }),
            Phase::Lift | Phase::Transfer | Phase::Lower
                if self.arm_move.as_ref().is_some_and(|m| elapsed >= m.duration_s()) =>
            {
                Some(match self.phase {
                    Phase::Lift => Phase::Transfer,
                    Phase::Transfer => Phase::Lower,
                    _ => Phase::Release,
                })
            }
            Phase::Release if elapsed >= self.task.release_s => Some(Phase::Done),
            _ => None,
        };
        if let Some(phase) = next {
            // Chain moves from the commanded pose (the planned end, or the pose held), not the
            // measured one: small tracking errors do not accumulate into the plan, and a servoed arm
            // that sags under its payload (`physics.arm_mode = "dynamic"`: 1.5 mrad at the shoulder)
            // is not sent a step to its sagged pose when the lift starts.
            let from = arm_target.unwrap_or_else(|| self.held_pose());
            self.enter(phase, now, from);
        }
        let elapsed = now - self.phase_start_s;

        let arm_q = match &self.arm_move {
            Some(m) => m.sample(elapsed).0,
            None => self.held_pose(),
        };

        self.update_grip(now, elapsed, force_n);
        let mut controller_output = 0.0;
        let controller_on = match self.phase {
            Phase::Grasp => self.grip == Grip::Holding,
            p if p.arm_moving() => self.feedback_while_moving,
            _ => false,
        };
        match self.phase {
            Phase::Grow => self.growth_m = (self.growth_m + self.task.growth_speed_m_s * dt_s).min(self.task.growth_m),
            Phase::Wrap => self.twine_deg += self.task.wrap_speed_deg_s * dt_s,
            Phase::Release => self.unwind(dt_s),
            Phase::Grasp if self.grip == Grip::Released => self.unwind(dt_s),
            Phase::Grasp if self.grip == Grip::Rewrapping => self.twine_deg += self.task.wrap_speed_deg_s * dt_s,
            _ => {}
        }
        let setpoint_n = match action {
            ControlAction::Setpoint(n) => n,
            _ => self.setpoint_n,
        };
        if controller_on {
            // The integral must not wind up while the tendon is at a travel limit it pushes against.
            let tighten = setpoint_n > force_n;
            let blocked =
                (tighten && self.twine_deg >= self.gripper.twine_max_deg) || (!tighten && self.twine_deg <= 0.0);
            // What the task knows of the arm's motion: the plan at this tick (still while it holds).
            let arm = self.arm_move.as_ref().map_or_else(ArmMotion::default, |m| ArmMotion {
                qd_rad_s: m.sample(elapsed).1,
                qdd_rad_s2: m.acceleration(elapsed),
            });
            let outlook = self.outlook(elapsed);
            let context = ControlContext { setpoint_n, force_n, dt_s, phase: self.phase, blocked, arm, outlook };
            controller_output = match action {
                ControlAction::TwineSpeed(deg_s) => {
                    let max = self.controller.max_speed_deg_s();
                    deg_s.clamp(-max, max)
                }
                _ => self.controller.update(&context),
            };
            self.twine_deg += controller_output * dt_s;
        }
        self.twine_deg = self.twine_deg.clamp(0.0, self.gripper.twine_max_deg);
        self.record_twine(now);

        TickDecision {
            command: CellCommand {
                arm_q,
                growth_motor_rad: self.gripper.growth_motor_rad(self.growth_m),
                twine_motor_rad: self.twine_deg.to_radians(),
            },
            phase: self.phase,
            controller_output_deg_s: controller_output,
            controller_on,
            setpoint_n,
        }
    }
}

impl TaskSequencer {
    /// A long grasp's release and re-wrap (`task.hold`; not with a settled grasp, which ends as
    /// soon as it can): let go once it has lasted `release_after_s` or used `release_at_travel`,
    /// close again in time to touch near the twine it let go at and leave `rewrap_settle_s` before
    /// the move, hold once the close touches (or after `task.wrap_timeout_s`, as the first close).
    fn update_grip(&mut self, now: f64, elapsed: f64, force_n: f64) {
        if self.phase != Phase::Grasp || self.task.settled_grasp.enabled {
            self.grip = Grip::Holding;
            return;
        }
        let hold = self.task.hold;
        let remaining = self.grasp_remaining_s(elapsed);
        let travel_used = self.twine_deg / self.gripper.twine_max_deg;
        let close_s = |twine_deg: f64| twine_deg / self.task.wrap_speed_deg_s;
        self.grip = match self.grip {
            Grip::Holding if hold.release(elapsed, remaining, travel_used, close_s(self.twine_deg)) => {
                self.hold.releases += 1;
                self.released_twine_deg = self.twine_deg;
                Grip::Released
            }
            Grip::Released if hold.rewrap(remaining, close_s(self.released_twine_deg)) => {
                self.contact.restart();
                self.rewrap_start_s = now;
                Grip::Rewrapping
            }
            Grip::Rewrapping
                if self.contact.touched(force_n - self.unloaded_n)
                    || now - self.rewrap_start_s >= self.task.wrap_timeout_s =>
            {
                self.controller.reset();
                Grip::Holding
            }
            grip => grip,
        };
    }

    /// Unwinds the twine towards the straight finger at the controller's speed limit.
    fn unwind(&mut self, dt_s: f64) {
        self.twine_deg = (self.twine_deg - self.controller.max_speed_deg_s() * dt_s).max(0.0);
    }

    /// Keeps the twine's record: its largest value, in the grasp and over the run, and when it
    /// first reached the travel's end.
    fn record_twine(&mut self, now: f64) {
        let h = &mut self.hold;
        let used = self.twine_deg / self.gripper.twine_max_deg;
        h.max_travel = h.max_travel.max(used);
        if self.phase == Phase::Grasp {
            h.max_grasp_travel = h.max_grasp_travel.max(used);
        }
        if self.twine_deg >= self.gripper.twine_max_deg && h.travel_end_s.is_none() {
            h.travel_end_s = Some(now);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pid::{Pid, PidConfig};
    use tendril_fbg::signals::Wavelengths;

    /// The state a toy plant's cell reads at `time_s`: the arm at `arm_q`, the twine motor at
    /// `twine_motor_rad`, the sensor's wavelengths at rest (the toy plants hand the force over
    /// directly).
    fn toy_state(time_s: f64, arm_q: [f64; ARM_JOINTS], twine_motor_rad: f64) -> CellState {
        CellState {
            time_s,
            arm_q,
            growth_motor_rad: 0.0,
            twine_motor_rad,
            wavelengths: Wavelengths { fbg1_nm: 1540.0, fbg2_nm: 1550.0 },
            array: Default::default(),
            tool_load_n: None,
        }
    }

    /// A toy plant: force grows linearly with twine past first contact at 60°, and relaxes by
    /// `creep_n_s` per second; returns (phases seen in order, final twine °, force trace).
    fn run_toy(feedback: bool, creep_n_s: f64) -> (Vec<Phase>, Vec<(f64, Phase, f64)>) {
        let (phases, trace, _) = run_toy_with(TaskConfig::default(), feedback, creep_n_s);
        (phases, trace)
    }

    /// As [`run_toy`] with the task given; also returns the commanded arm joints per tick.
    #[allow(clippy::type_complexity)]
    fn run_toy_with(
        task: TaskConfig,
        feedback: bool,
        creep_n_s: f64,
    ) -> (Vec<Phase>, Vec<(f64, Phase, f64)>, Vec<[f64; ARM_JOINTS]>) {
        let gripper = GripperConfig::default();
        let mut seq = TaskSequencer::new(task, gripper, Box::new(Pid::new(PidConfig::default())), 1.0, feedback);
        let dt = 0.01;
        let mut twine_deg: f64 = 0.0;
        let mut offset: f64 = 0.0;
        let mut phases = vec![];
        let mut trace = vec![];
        let mut arm_q = [0.0; ARM_JOINTS];
        let mut arm = vec![];
        for i in 0..10_000 {
            let t = i as f64 * dt;
            let force = (0.02 * (twine_deg - 60.0) - offset).max(0.0);
            let state = toy_state(t, arm_q, twine_deg.to_radians());
            let d = seq.update(&state, force, dt);
            if phases.last() != Some(&d.phase) {
                phases.push(d.phase);
            }
            trace.push((t, d.phase, force));
            twine_deg = d.command.twine_motor_rad.to_degrees();
            arm_q = d.command.arm_q;
            arm.push(arm_q);
            if force > 0.0 {
                offset += creep_n_s * dt;
            }
            if d.phase == Phase::Done {
                break;
            }
        }
        (phases, trace, arm)
    }

    /// A toy plant whose creep grows with the force it carries (as the strip's does: its rate is
    /// the creeping branch's tension over the dashpot): force = 0.02 N/° past first contact at 60°
    /// less the creep, which grows by `creep_per_s` × force per second. Runs the task with `task`
    /// and the paper's PID (setpoint 1 N) and returns the sequencer at the end with every tick's
    /// (time, phase, force, twine °, setpoint).
    #[allow(clippy::type_complexity)]
    fn run_creeping(
        task: TaskConfig,
        creep_per_s: f64,
        ticks: usize,
    ) -> (TaskSequencer, Vec<(f64, Phase, f64, f64, f64)>) {
        let mut seq =
            TaskSequencer::new(task, GripperConfig::default(), Box::new(Pid::new(PidConfig::default())), 1.0, true);
        let dt = 0.01;
        let (mut twine_deg, mut creep, mut arm_q) = (0.0_f64, 0.0_f64, [0.0; ARM_JOINTS]);
        let mut trace = vec![];
        for i in 0..ticks {
            let t = i as f64 * dt;
            let force = (0.02 * (twine_deg - 60.0) - creep).max(0.0);
            let state = toy_state(t, arm_q, twine_deg.to_radians());
            let d = seq.update(&state, force, dt);
            trace.push((t, d.phase, force, twine_deg, d.setpoint_n));
            twine_deg = d.command.twine_motor_rad.to_degrees();
            arm_q = d.command.arm_q;
            creep += creep_per_s * force * dt;
            if d.phase == Phase::Done {
                break;
            }
        }
        (seq, trace)
    }

    #[test]
    fn a_settled_grasp_lifts_once_in_the_band_for_the_dwell() {
        let settled = SettleConfig { enabled: true, band_pct: 5.0, dwell_s: 1.0, timeout_s: 15.0 };
        let task = TaskConfig { settled_grasp: settled, ..TaskConfig::default() };
        let (seq, trace) = run_creeping(task, 0.0, 10_000);
        let grasp: Vec<_> = trace.iter().filter(|r| r.1 == Phase::Grasp).collect();
        let outcome = seq.grasp_outcome().unwrap();
        assert_eq!(outcome.end, GraspEnd::Settled);
        // The toy's loop time constant is 1 / (Kp 20 × 0.02 N/°) = 2.5 s: 95 % after 7.5 s, plus the dwell.
        assert!(outcome.duration_s < 12.0, "settled before the paper's 15 s: {outcome:?}");
        // The last dwell's ticks were all in the band, and the lift followed.
        let dwell = grasp.iter().rev().take(100);
        assert!(dwell.clone().all(|r| (r.2 - 1.0).abs() <= 0.05), "left the band in the dwell");
        let phases: Vec<Phase> = trace.iter().map(|r| r.1).collect();
        assert!(phases.contains(&Phase::Lift) && phases.last() == Some(&Phase::Done));
    }

    #[test]
    fn a_grasp_that_never_settles_lets_go_at_home_without_lifting() {
        // A 0.1 % band is below what this loop reaches at a creep of 1 % of the force per second.
        let settled = SettleConfig { enabled: true, band_pct: 0.1, dwell_s: 2.0, timeout_s: 8.0 };
        let task = TaskConfig { settled_grasp: settled, ..TaskConfig::default() };
        let (seq, trace) = run_creeping(task.clone(), 0.2, 10_000);
        assert_eq!(seq.grasp_outcome().map(|g| g.end), Some(GraspEnd::TimedOut));
        assert!((seq.grasp_outcome().unwrap().duration_s - 8.0).abs() < 0.011);
        let phases: Vec<Phase> = trace.iter().map(|r| r.1).collect();
        assert!(!phases.iter().any(|p| p.arm_moving()), "the arm must not move after a failed grasp");
        assert_eq!(phases.last(), Some(&Phase::Done));
        assert_eq!(seq.motion_start_s(), None);
        // Released: the twine back at zero at the end.
        assert_eq!(trace.last().unwrap().3, 0.0);
    }

    #[test]
    fn the_integral_stops_growing_at_the_twine_travels_end() {
        // A spy around the paper's PID: each tick's blocked flag and the integral after it.
        #[derive(Debug)]
        struct Watched(Pid, std::sync::Arc<std::sync::Mutex<Vec<(bool, f64)>>>);
        impl ForceController for Watched {
            fn update(&mut self, ctx: &ControlContext) -> f64 {
                let u = self.0.update(ctx.setpoint_n, ctx.force_n, ctx.dt_s, ctx.blocked);
                self.1.lock().unwrap().push((ctx.blocked, self.0.integral()));
                u
            }
            fn reset(&mut self) {
                self.0.reset();
            }
            fn max_speed_deg_s(&self) -> f64 {
                90.0
            }
        }
        let seen = std::sync::Arc::new(std::sync::Mutex::new(vec![]));
        let task = TaskConfig {
            grasp_s: 300.0,
            hold: HoldConfig { enabled: false, ..HoldConfig::default() },
            ..Default::default()
        };
        let pid = Watched(Pid::new(PidConfig::default()), seen.clone());
        let mut seq = TaskSequencer::new(task, GripperConfig::default(), Box::new(pid), 1.0, true);
        // A creep of 5 % of the force per second runs the 211° travel out within the grasp.
        let (dt, mut twine_deg, mut creep) = (0.01, 0.0_f64, 0.0);
        for i in 0..20_000 {
            let force = (0.02 * (twine_deg - 60.0) - creep).max(0.0);
            let state = toy_state(i as f64 * dt, [0.0; ARM_JOINTS], twine_deg.to_radians());
            let d = seq.update(&state, force, dt);
            twine_deg = d.command.twine_motor_rad.to_degrees();
            creep += 0.05 * force * dt;
        }
        let end = seq.hold_record().travel_end_s.expect("the travel ran out");
        assert!(end < 150.0, "{end}");
        let seen = seen.lock().unwrap();
        let at_end: Vec<&(bool, f64)> = seen.iter().skip_while(|(blocked, _)| !blocked).collect();
        assert!(at_end.len() > 1000, "blocked for {} ticks", at_end.len());
        let first = at_end[0].1;
        assert!(
            at_end.iter().all(|(blocked, integral)| *blocked && *integral == first),
            "the integral moved while blocked"
        );
    }

    #[test]
    fn a_long_grasp_lets_go_and_rewraps_where_a_held_one_runs_out_of_travel() {
        // 200 s of grasp on a plant that creeps by 2 % of its force per second: held at the
        // setpoint the twine reaches its travel's end (60° + 5 N / 0.02 N/°). Let go at 30 s, the
        // creep stops where it was (0.6 N), and the re-wrap 10 s before the move needs 60° +
        // 1.6 N / 0.02 N/° = 140°: the travel is not used up, and the grip is back at the setpoint
        // when the arm moves. (The toy's loop, time constant 2.5 s, is three to five times slower
        // than the twin's: the re-wrap leaves it 8 s instead of 5 to rise after its close.)
        let long = |hold: HoldConfig| TaskConfig { grasp_s: 200.0, hold, ..TaskConfig::default() };
        let (held, _) = run_creeping(long(HoldConfig { enabled: false, ..HoldConfig::default() }), 0.02, 40_000);
        assert!(held.hold_record().travel_end_s.is_some());
        let hold = HoldConfig { rewrap_settle_s: 8.0, ..HoldConfig::default() };
        let (released, trace) = run_creeping(long(hold), 0.02, 40_000);
        let record = released.hold_record();
        assert_eq!(record.releases, 1);
        assert_eq!(record.travel_end_s, None, "{record:?}");
        assert!(record.max_grasp_travel < 0.8, "{record:?}");
        let lift_start = trace.iter().find(|r| r.1 == Phase::Lift).unwrap();
        assert!((lift_start.2 - 1.0).abs() < 0.1, "force at the lift {}", lift_start.2);
        // Unwound to the straight finger from 30 s into the grasp to the re-wrap, which starts the
        // close from the twine let go at (about 138° at 15 °/s, 9 s) and 8 s before the lift.
        let at = |t: f64| trace.iter().find(|r| r.0 >= t).unwrap();
        let start = grasp_start(&trace);
        assert_eq!(at(start + 40.0).3, 0.0);
        assert_eq!(at(lift_start.0 - 17.5).3, 0.0);
        assert!(at(lift_start.0 - 1.0).3 > 130.0);
    }

    fn grasp_start(trace: &[(f64, Phase, f64, f64, f64)]) -> f64 {
        trace.iter().find(|r| r.1 == Phase::Grasp).unwrap().0
    }

    #[test]
    fn phases_run_in_order_and_the_grasp_converges() {
        let (phases, trace) = run_toy(true, 0.0);
        use Phase::*;
        assert_eq!(phases, vec![Home, Grow, Wrap, Grasp, Lift, Transfer, Lower, Release, Done]);
        let grasp_end = trace.iter().rfind(|(_, p, _)| *p == Grasp).unwrap();
        assert!((grasp_end.2 - 1.0).abs() < 0.02, "force at end of grasp {}", grasp_end.2);
    }

    #[test]
    fn without_feedback_the_twine_is_frozen_while_the_arm_moves() {
        let (_, with) = run_toy(true, 0.05);
        let (_, without) = run_toy(false, 0.05);
        let last_moving = |tr: &[(f64, Phase, f64)]| tr.iter().rfind(|(_, p, _)| p.arm_moving()).unwrap().2;
        // Creep erodes the open-loop grip; the closed loop holds it near the setpoint, short by
        // the ramp-following error of an integrating loop: 0.05 N/s / (Kp 20 × 0.02 N/°) = 0.125 N.
        assert!(last_moving(&without) < 0.3, "{}", last_moving(&without));
        assert!((last_moving(&with) - 0.875).abs() < 0.05, "{}", last_moving(&with));
    }

    #[test]
    fn without_minimum_durations_the_moves_are_planned_at_the_limits() {
        let duration = |trace: &[(f64, Phase, f64)], phase: Phase| {
            let times: Vec<f64> = trace.iter().filter(|(_, p, _)| *p == phase).map(|(t, _, _)| *t).collect();
            times.last().unwrap() - times.first().unwrap()
        };
        let (_, stretched, _) = run_toy_with(TaskConfig::default(), true, 0.0);
        let fast_task = TaskConfig { minimum_durations: false, ..TaskConfig::default() };
        let (phases, fast, arm) = run_toy_with(fast_task, true, 0.0);
        assert!(phases.contains(&Phase::Done));
        // The lift's largest joint travel is 20° (wrist): 2 √(20/15) = 2.31 s against the 11 s minimum.
        let lift = duration(&fast, Phase::Lift);
        assert!((lift - 2.31).abs() < 0.02 && duration(&stretched, Phase::Lift) > 10.9, "lift {lift} s");
        // The commanded joints reach the 15 °/s² limit (second differences of the commands).
        let dt = 0.01;
        let peak = arm
            .windows(3)
            .flat_map(|w| (0..ARM_JOINTS).map(move |j| ((w[2][j] - 2.0 * w[1][j] + w[0][j]) / (dt * dt)).abs()))
            .fold(0.0, f64::max)
            .to_degrees();
        assert!((peak - 15.0).abs() < 0.5, "peak joint acceleration {peak} °/s²");
    }

    #[test]
    fn the_controller_is_told_the_lift_ahead() {
        #[derive(Debug)]
        struct Spy(std::sync::Arc<std::sync::Mutex<Vec<(Phase, MoveOutlook)>>>);
        impl ForceController for Spy {
            fn update(&mut self, ctx: &ControlContext) -> f64 {
                self.0.lock().unwrap().push((ctx.phase, ctx.outlook));
                0.0
            }
            fn reset(&mut self) {}
            fn max_speed_deg_s(&self) -> f64 {
                90.0
            }
        }
        let seen = std::sync::Arc::new(std::sync::Mutex::new(vec![]));
        let task = TaskConfig { minimum_durations: false, ..TaskConfig::default() };
        let mut seq = TaskSequencer::new(task, GripperConfig::default(), Box::new(Spy(seen.clone())), 1.0, true);
        seq.enter(Phase::Grasp, 0.0, radians(&TaskConfig::default().home_deg));
        let state = toy_state(5.0, [0.0; ARM_JOINTS], 0.0);
        seq.update(&state, 0.5, 0.01);
        let (phase, outlook) = seen.lock().unwrap()[0];
        assert_eq!(phase, Phase::Grasp);
        assert!((outlook.time_to_motion_s - 10.0).abs() < 1e-9, "{outlook:?}");
        assert!((outlook.peak_accel_rad_s2.to_degrees() - 15.0).abs() < 1e-9, "{outlook:?}");
    }
}
