//! The virtual UR5e's joint setpoint between program cycles, as the twin samples it at the end of
//! each physics step.
//!
//! The program runs a 2 ms controller cycle; the twin's physics steps at its own step (2.5 ms by
//! default). Whatever the two clocks, the setpoint the servos get must move as the program's
//! commands do: a constant-speed stream of `servoj` targets must reach the physics as a
//! constant-speed setpoint. It once did not: each target was reached one cycle after it was given
//! and held there until the next, so a 2.5 ms step ending after the hold began moved by one
//! cycle's way and the next by one and a half. The 10 ms beat of the two clocks (their least
//! common multiple) made the setpoint's speed swing between 0.1 and 1.7 times the commanded one at
//! 100 Hz during the short lift, which rattled the pad against the object: the pad force changed
//! by 0.07-0.10 N from step to step and lost contact for single steps (against 1 mN per step on the
//! simulated path), and the real path's estimate in the lift read 0.16-1.1 N where the twin's read
//! 0.54-0.58 N (measured; docs/cell/timing.md#what-made-the-lift-shake-and-where-it-was-fixed).

use std::collections::VecDeque;
use tendril_urscript::interp::CONTROL_PERIOD_S;

/// What the arm's setpoint follows.
#[derive(Debug, Clone, PartialEq)]
pub enum ArmPath {
    /// A generated trajectory (`movej`, `movel`, `speedj`, `stopj`): `q` at twin time `at_s`,
    /// moving at `qd` and extrapolated at that speed for at most `max_ahead_s` past `at_s` (the
    /// program gives a new point every cycle).
    Track {
        /// Joint angles at `at_s` \[rad\].
        q: [f64; 6],
        /// Their speed \[rad/s\].
        qd: [f64; 6],
        /// Twin time of `q` \[s\].
        at_s: f64,
        /// How far past `at_s` the setpoint moves on \[s\].
        max_ahead_s: f64,
    },
    /// `servoj` targets: straight lines through the targets (joint angles \[rad\], the twin time
    /// \[s\] the setpoint passes them: [`servo_delay_s`] after the cycle that gave them), oldest
    /// first, starting where the setpoint was; held at the last.
    Servo(VecDeque<([f64; 6], f64)>),
}

/// How long after the cycle that gives a `servoj` target the setpoint passes through it \[s\]:
/// one program cycle (servoj's `t`, over which a controller spreads a target), plus how far past
/// the latest cycle the twin may have to sample the path. The twin commands the setpoint for the
/// end of the physics step it is about to take, which ends less than a twin tick and half a step
/// after the latest cycle (a step is taken once a tick's wait passes its middle). With this delay
/// the setpoint is always between two targets already given, never extrapolated: 4.25 ms at the
/// default 1 ms twin tick and 2.5 ms step.
pub fn servo_delay_s(twin_period_s: f64, timestep_s: f64) -> f64 {
    CONTROL_PERIOD_S + twin_period_s + 0.5 * timestep_s
}

impl ArmPath {
    /// The path after a new `servoj` target `q` \[rad\], given at twin time `given_s` and passed
    /// `delay_s` later, with the setpoint last commanded `last` (angles \[rad\], twin time \[s\]).
    /// It continues the targets already followed; it starts from where the setpoint was when it
    /// followed none, or when the last was passed before `last` (it was held since: no jump).
    pub fn servo(previous: Option<ArmPath>, q: [f64; 6], given_s: f64, delay_s: f64, last: ([f64; 6], f64)) -> ArmPath {
        let mut knots = match previous {
            Some(ArmPath::Servo(knots)) if knots.back().is_some_and(|k| k.1 > last.1) => knots,
            _ => VecDeque::from([last]),
        };
        // Targets passed before the last command are behind the setpoint for good.
        while knots.len() > 1 && knots[1].1 <= last.1 {
            knots.pop_front();
        }
        knots.push_back((q, (given_s + delay_s).max(last.1)));
        ArmPath::Servo(knots)
    }

    /// The setpoint at twin time `t_s` \[s\].
    pub fn at(&self, t_s: f64) -> [f64; 6] {
        match self {
            ArmPath::Track { q, qd, at_s, max_ahead_s } => {
                let ahead = (t_s - at_s).clamp(0.0, *max_ahead_s);
                std::array::from_fn(|j| q[j] + qd[j] * ahead)
            }
            ArmPath::Servo(knots) => {
                let after = knots.iter().position(|k| k.1 > t_s).unwrap_or(knots.len());
                match (after.checked_sub(1).map(|i| knots[i]), knots.get(after).copied()) {
                    (Some((q0, t0)), Some((q1, t1))) => {
                        let f = (t_s - t0) / (t1 - t0);
                        std::array::from_fn(|j| q0[j] + (q1[j] - q0[j]) * f)
                    }
                    (Some((q, _)), None) | (None, Some((q, _))) => q,
                    (None, None) => unreachable!("a servo path has a knot"),
                }
            }
        }
    }

    /// Whether the setpoint no longer moves after twin time `t_s` (the path can be dropped).
    pub fn settled_after(&self, t_s: f64) -> bool {
        match self {
            ArmPath::Track { qd, .. } => qd.iter().all(|v| *v == 0.0),
            ArmPath::Servo(knots) => knots.back().is_none_or(|k| t_s >= k.1),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Servo targets at a constant speed every 2 ms cycle, sampled as the twin samples them (the
    /// end of each 2.5 ms step, commanded on a 1 ms tick once the tick passes the step's middle):
    /// the setpoint's way per step, divided by the step's share of the speed.
    fn step_ratios(timestep_s: f64) -> Vec<f64> {
        let (period_s, speed) = (1e-3, 0.05);
        let delay = servo_delay_s(period_s, timestep_s);
        let (mut path, mut physics_s, mut commanded) = (None, 0.0, ([0.0; 6], 0.0));
        let mut ratios = Vec::new();
        for k in 1..400u32 {
            let now_s = f64::from(k - 1) * period_s;
            if (now_s / CONTROL_PERIOD_S).fract().abs() < 1e-9 {
                let q = [speed * now_s; 6];
                path = Some(ArmPath::servo(path.take(), q, now_s, delay, commanded));
            }
            if f64::from(k) * period_s - physics_s > 0.5 * timestep_s {
                let p = path.as_ref().unwrap();
                let q = p.at(physics_s + timestep_s);
                if k > 40 {
                    ratios.push((q[0] - commanded.0[0]) / (speed * timestep_s));
                }
                physics_s += timestep_s;
                commanded = (q, physics_s);
            }
        }
        ratios
    }

    #[test]
    fn a_constant_speed_servo_stream_reaches_the_physics_at_a_constant_speed_whatever_the_step() {
        for timestep_s in [0.625e-3, 1.25e-3, 2.5e-3, 5e-3] {
            let ratios = step_ratios(timestep_s);
            assert!(!ratios.is_empty());
            for r in &ratios {
                assert!((r - 1.0).abs() < 1e-9, "step {timestep_s}: the setpoint moved {r} times the commanded way");
            }
        }
    }

    #[test]
    fn a_servo_path_starts_where_the_setpoint_is_and_holds_its_target() {
        let last = ([0.1; 6], 1.0);
        let p = ArmPath::servo(None, [0.2; 6], 1.0, 0.004, last);
        assert_eq!(p.at(1.0), [0.1; 6]);
        assert!((p.at(1.002)[0] - 0.15).abs() < 1e-12);
        assert_eq!(p.at(1.01), [0.2; 6], "held once passed");
        assert!(p.settled_after(1.004) && !p.settled_after(1.003));
        // A target after a long pause starts from the held target at the last command, not from
        // the target's old time (which would jump the setpoint most of the way at once).
        let later = ArmPath::servo(Some(p), [0.3; 6], 5.0, 0.004, ([0.2; 6], 5.0));
        assert_eq!(later, ArmPath::Servo([([0.2; 6], 5.0), ([0.3; 6], 5.004)].into()));
        assert_eq!(later.at(5.0), [0.2; 6]);
        assert!((later.at(5.002)[0] - 0.25).abs() < 1e-12);
    }
}
