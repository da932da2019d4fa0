//! The virtual UR5e's safety system: which streamed joint targets make it enter a protective stop.
//!
//! A real UR5e's controller checks every motion against its joint position and speed limits and
//! stops the arm (protective stop) instead of executing a violation. The virtual one does the
//! same for the targets the follow program would `servoj` to:
//! - a non-finite target;
//! - a target outside the joint's working range: ±360° for every joint (UR5e technical
//!   specifications), the elbow ±180° (its travel in UR's own robot description, the forearm
//!   would otherwise pass through the upper arm);
//! - a target farther from the arm's present position than the joint can travel at its top speed
//!   (180°/s on every UR5e joint) within `servoj`'s lookahead time (0.1 s in our program): about
//!   0.31 rad. Our client's targets are at most one control tick's step (under 0.01 rad) ahead.
//!
//! Why the check exists: 100 rad targets used to be followed at the twin's top joint speed and
//! made the physics diverge, which ended `serve` for every client.

use std::f64::consts::{PI, TAU};

/// Working range of each joint \[rad\]: ±360° except the elbow, ±180°.
pub const JOINT_RANGE_RAD: [f64; 6] = [TAU, TAU, PI, TAU, TAU, TAU];
/// Top joint speed of the UR5e \[rad/s\] (180°/s on every joint).
pub const MAX_JOINT_SPEED_RAD_S: f64 = PI;
/// `servoj`'s lookahead time in our follow program \[s\].
pub const SERVO_LOOKAHEAD_S: f64 = 0.1;

/// Why `target` would trip a protective stop with the arm at `actual`, or `None` if it is allowed.
pub fn violation(target: &[f64; 6], actual: &[f64; 6]) -> Option<String> {
    let max_step = MAX_JOINT_SPEED_RAD_S * SERVO_LOOKAHEAD_S;
    for j in 0..6 {
        let (t, a) = (target[j], actual[j]);
        if !t.is_finite() {
            return Some(format!("joint {j} target is not a number ({t})"));
        }
        if t.abs() > JOINT_RANGE_RAD[j] {
            return Some(format!(
                "joint {j} target {t:.4e} rad outside its range ±{:.0}°",
                JOINT_RANGE_RAD[j].to_degrees()
            ));
        }
        if (t - a).abs() > max_step {
            return Some(format!(
                "joint {j} target {t:.4} rad is {:.3} rad from the arm ({a:.4} rad): beyond {:.0}°/s within the {:.1} s lookahead",
                (t - a).abs(),
                MAX_JOINT_SPEED_RAD_S.to_degrees(),
                SERVO_LOOKAHEAD_S
            ));
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hostile_targets_are_violations_and_small_steps_are_not() {
        let home = [-PI / 2.0, -PI / 2.0, PI / 2.0, -PI / 2.0, -PI / 2.0, 0.0];
        assert_eq!(violation(&home, &home), None);
        let mut step = home;
        step.iter_mut().for_each(|v| *v += 0.01);
        assert_eq!(violation(&step, &home), None);
        for bad in [100.0, 1e308, f64::NAN, f64::INFINITY, -f64::INFINITY] {
            for j in 0..6 {
                let mut t = home;
                t[j] = bad;
                assert!(violation(&t, &home).is_some(), "joint {j} = {bad}");
            }
        }
        // Within range but too far to reach within the lookahead.
        let mut far = home;
        far[0] += 0.5;
        assert!(violation(&far, &home).unwrap().contains("lookahead"));
        // The elbow's range is ±180°, the others' ±360°.
        let (mut elbow, mut base) = (home, home);
        elbow[2] = 3.2;
        base[0] = 6.2;
        assert!(violation(&elbow, &elbow).unwrap().contains("range"));
        assert_eq!(violation(&base, &base), None);
    }
}
