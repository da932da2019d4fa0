//! What a `JointState` command on `joint_commands` asks of the twin, checked: the arm's six joints
//! by position (all six, as ros2_control's topic-based hardware interfaces send a system's
//! joints), the growth and twine motors by position or velocity.

use tendril_cell::ARM_JOINTS;
use tendril_ros2::config::JointNames;
use tendril_ros2msg::JointState;

/// A motor's target.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MotorTarget {
    /// Angle \[rad\].
    Position(f64),
    /// Speed \[rad/s\], integrated into the goal position by the twin while it is fresh.
    Velocity(f64),
}

/// One command, checked.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RosCommand {
    /// Its stamp \[s\].
    pub stamp_s: f64,
    /// The arm's six joint targets \[rad\], when it names the arm.
    pub arm: Option<[f64; ARM_JOINTS]>,
    /// Growth and twine motor targets, when it names them.
    pub motors: [Option<MotorTarget>; 2],
}

/// `m` as a command to the joints `names`, or why it is refused.
pub fn parse_command(m: &JointState, names: &JointNames) -> Result<RosCommand, String> {
    let all = names.all();
    let n = m.name.len();
    for (field, len) in [("position", m.position.len()), ("velocity", m.velocity.len())] {
        if len != 0 && len != n {
            return Err(format!("{n} joint names but {len} {field}s: a non-empty list has one value per name"));
        }
    }
    if m.position.is_empty() && m.velocity.is_empty() && n > 0 {
        return Err(
            "no positions or velocities: the twin takes position commands (velocity for the motors), not efforts"
                .into(),
        );
    }
    if let Some(v) = m.position.iter().chain(&m.velocity).find(|v| !v.is_finite()) {
        return Err(format!("a target of {v} is not finite"));
    }
    let mut slot = [None::<usize>; ARM_JOINTS + 2];
    for (i, name) in m.name.iter().enumerate() {
        let Some(j) = all.iter().position(|a| a == name) else {
            return Err(format!("joint `{name}` is not one of the twin's ({})", all.join(", ")));
        };
        if slot[j].replace(i).is_some() {
            return Err(format!("joint `{name}` is named twice"));
        }
    }
    let arm_named = slot[..ARM_JOINTS].iter().filter(|s| s.is_some()).count();
    let arm = match arm_named {
        0 => None,
        ARM_JOINTS if !m.position.is_empty() => {
            Some(std::array::from_fn(|j| m.position[slot[j].expect("all six named")]))
        }
        ARM_JOINTS => return Err("the arm takes position commands: the message has velocities only".into()),
        k => {
            return Err(format!(
                "the command names {k} of the arm's {ARM_JOINTS} joints: command all six (ros2_control's topic-based interfaces send every joint of a system)"
            ));
        }
    };
    let motor = |j: usize| {
        slot[j].map(|i| {
            if m.position.is_empty() {
                MotorTarget::Velocity(m.velocity[i])
            } else {
                MotorTarget::Position(m.position[i])
            }
        })
    };
    Ok(RosCommand { stamp_s: m.header.stamp.as_secs_f64(), arm, motors: [motor(ARM_JOINTS), motor(ARM_JOINTS + 1)] })
}

/// How long a motor velocity command holds without a new one \[s\]: 0.1 s, ten ticks of a
/// 100 Hz commander (`tendril_cell::BLIND_TICKS`): a commander that stops stops the motor.
pub const VELOCITY_HOLD_S: f64 = 0.1;

/// The motors' velocity drives: each motor's speed \[rad/s\], when it came (twin time \[s\]) and
/// the goal it has moved to \[rad\], kept unrounded (a tick's way is a fraction of an MX-106's
/// position unit at the speeds a gripper uses).
#[derive(Debug, Default, Clone, PartialEq)]
pub struct MotorDrives {
    velocity: [Option<(f64, f64, f64)>; 2],
}

impl MotorDrives {
    /// The motors' position targets \[rad\] after `commands`, at twin time `now_s`, a tick `dt_s`
    /// after the last, from `targets`: a position command sets its motor's target; a velocity
    /// command moves it each tick while it is at most [`VELOCITY_HOLD_S`] old. `None` when no
    /// command drives a motor this tick.
    pub fn targets(
        &mut self,
        commands: &[RosCommand],
        now_s: f64,
        dt_s: f64,
        mut targets: [f64; 2],
    ) -> Option<[f64; 2]> {
        let mut driven = false;
        for c in commands {
            for (m, target) in c.motors.iter().enumerate() {
                match target {
                    Some(MotorTarget::Position(rad)) => {
                        targets[m] = *rad;
                        self.velocity[m] = None;
                        driven = true;
                    }
                    Some(MotorTarget::Velocity(v)) => {
                        let goal = self.velocity[m].map_or(targets[m], |(_, _, goal)| goal);
                        self.velocity[m] = Some((*v, now_s, goal));
                    }
                    None => {}
                }
            }
        }
        for (m, v) in self.velocity.iter_mut().enumerate() {
            match v {
                Some((rad_s, at, goal)) if now_s - *at <= VELOCITY_HOLD_S => {
                    *goal += *rad_s * dt_s;
                    targets[m] = *goal;
                    driven = true;
                }
                _ => *v = None,
            }
        }
        driven.then_some(targets)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn command(names: &[&str], position: &[f64], velocity: &[f64]) -> JointState {
        JointState {
            name: names.iter().map(|s| s.to_string()).collect(),
            position: position.to_vec(),
            velocity: velocity.to_vec(),
            ..JointState::default()
        }
    }

    #[test]
    fn commands_are_read_by_name_and_bad_ones_refused_with_the_reason() {
        let names = JointNames::default();
        let arm: Vec<&str> = names.arm.iter().map(String::as_str).collect();
        let mut all = arm.clone();
        all.extend(["twine_motor_joint", "growth_motor_joint"]);
        let c = parse_command(&command(&all, &[0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0], &[]), &names).unwrap();
        assert_eq!(c.arm, Some([0.0, 1.0, 2.0, 3.0, 4.0, 5.0]));
        assert_eq!(c.motors, [Some(MotorTarget::Position(7.0)), Some(MotorTarget::Position(6.0))]);
        let c = parse_command(&command(&["twine_motor_joint"], &[], &[0.5]), &names).unwrap();
        assert_eq!((c.arm, c.motors), (None, [None, Some(MotorTarget::Velocity(0.5))]));
        for (m, why) in [
            (command(&["gripper"], &[0.0], &[]), "joint `gripper` is not one of the twin's"),
            (command(&arm[..3], &[0.0; 3], &[]), "names 3 of the arm's 6 joints"),
            (command(&arm, &[0.0; 5], &[]), "6 joint names but 5 positions"),
            (command(&["twine_motor_joint"], &[f64::NAN], &[]), "is not finite"),
            (command(&["twine_motor_joint", "twine_motor_joint"], &[0.0, 0.0], &[]), "named twice"),
            (command(&arm, &[], &[0.1; 6]), "the arm takes position commands"),
            (
                JointState { name: vec!["twine_motor_joint".into()], effort: vec![1.0], ..JointState::default() },
                "not efforts",
            ),
        ] {
            let e = parse_command(&m, &names).unwrap_err();
            assert!(e.contains(why), "{e}");
        }
    }

    #[test]
    fn a_velocity_drive_moves_its_goal_unrounded_and_stops_when_its_commands_stop() {
        let mut drives = MotorDrives::default();
        let twine = |v| RosCommand { stamp_s: 0.0, arm: None, motors: [None, Some(MotorTarget::Velocity(v))] };
        let mut targets = [1.0, 2.0];
        // 0.2 rad/s at a 1 ms tick: 0.2 mrad a tick, an eighth of an MX-106 position unit.
        for k in 0..100 {
            let commands = if k % 10 == 0 { vec![twine(0.2)] } else { Vec::new() };
            targets = drives.targets(&commands, k as f64 * 1e-3, 1e-3, targets).unwrap();
        }
        assert!((targets[1] - 2.02).abs() < 1e-12, "{targets:?}");
        assert_eq!(targets[0], 1.0);
        // No command for longer than the hold: the motor keeps its goal.
        assert_eq!(drives.targets(&[], 0.2, 1e-3, targets), None);
        let position = RosCommand { stamp_s: 0.0, arm: None, motors: [Some(MotorTarget::Position(0.5)), None] };
        assert_eq!(drives.targets(&[position], 0.3, 1e-3, targets), Some([0.5, targets[1]]));
    }
}
