//! What every physics backend does the same way between the cell's commands and its solver: the
//! motors' speed limit, the arm's interpolation between control ticks (the prescribed arm moves
//! along it, the servoed arm's setpoints follow it), and the object's position and slip relative to
//! the hand.

use super::PhysicsError;
use super::config::{FingerConfig, PhysicsConfig};
use nalgebra::{Isometry3, Point3, Vector3};

/// Commanded motors and arm, turned into per-step setpoints.
#[derive(Debug, Clone)]
pub struct Drive {
    /// Commanded growth and twine [m].
    motor_target: [f64; 2],
    /// The servos' current setpoints [m]: they move towards the targets at the motor speed.
    motor_setpoint: [f64; 2],
    arm_target: [f64; 6],
    /// The arm's current setpoint angles [rad] (the rate-limited commanded angles).
    arm_q: [f64; 6],
    /// Simulated time of the latest arm command and the interval since the one before [s]; the
    /// move to a new target is spread over that interval (see [`Drive::advance`]).
    arm_command_s: Option<f64>,
    arm_command_period_s: f64,
    length_m: f64,
    twine_max_m: f64,
    motor_max_speed_m_s: f64,
    arm_max_speed_rad_s: f64,
}

/// The setpoints for one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepSetpoints {
    /// Growth and twine servo setpoints \[m\].
    pub motors: [f64; 2],
    /// Arm setpoint angles at the end of the step \[rad\].
    pub arm_q: [f64; 6],
}

impl Drive {
    /// A drive at rest: arm at `arm_q0`, finger retracted and slack.
    pub fn new(physics: &PhysicsConfig, finger: &FingerConfig, arm_q0: [f64; 6]) -> Drive {
        Drive {
            motor_target: [0.0; 2],
            motor_setpoint: [0.0; 2],
            arm_target: arm_q0,
            arm_q: arm_q0,
            arm_command_s: None,
            arm_command_period_s: 0.0,
            length_m: finger.length_m,
            twine_max_m: finger.twine_max_m,
            motor_max_speed_m_s: finger.motor_max_speed_m_s,
            arm_max_speed_rad_s: physics.arm_max_speed_rad_s,
        }
    }

    /// Commands the finger growth \[m\], clamped to 0..finger.length_m.
    pub fn set_growth(&mut self, growth_m: f64) -> Result<(), PhysicsError> {
        if !growth_m.is_finite() {
            return Err(PhysicsError::BadInput { what: "growth", value: growth_m });
        }
        self.motor_target[0] = growth_m.clamp(0.0, self.length_m);
        Ok(())
    }

    /// Commands the tendon wound in \[m\], clamped to 0..finger.twine_max_m.
    pub fn set_twine(&mut self, twine_m: f64) -> Result<(), PhysicsError> {
        if !twine_m.is_finite() {
            return Err(PhysicsError::BadInput { what: "twine", value: twine_m });
        }
        self.motor_target[1] = twine_m.clamp(0.0, self.twine_max_m);
        Ok(())
    }

    /// Commands the arm joint targets \[rad\] at simulated time `now_s`.
    pub fn set_arm_target(&mut self, q: [f64; 6], now_s: f64) -> Result<(), PhysicsError> {
        if let Some(v) = q.iter().find(|v| !v.is_finite()) {
            return Err(PhysicsError::BadInput { what: "arm target", value: *v });
        }
        self.arm_target = q;
        self.arm_command_period_s = self.arm_command_s.map_or(0.0, |t| now_s - t);
        self.arm_command_s = Some(now_s);
        Ok(())
    }

    /// The arm target last commanded \[rad\].
    pub fn arm_target(&self) -> [f64; 6] {
        self.arm_target
    }

    /// The arm's current setpoint angles \[rad\].
    pub fn arm_q(&self) -> [f64; 6] {
        self.arm_q
    }

    /// The twine servo's current setpoint \[m\].
    pub fn twine_setpoint_m(&self) -> f64 {
        self.motor_setpoint[1]
    }

    /// Advances the setpoints over the step that starts at `t0_s` and lasts `dt_s`.
    ///
    /// Motors: each setpoint moves towards its target by at most the motor speed times the step.
    /// Arm: a controller commands a new target every control tick (several steps); the
    /// remaining way is spread evenly over the steps left until the next command is due, so the
    /// hand moves at the commanded velocity. Jumping to each target in one step and then standing
    /// still shook the hand at the control rate (at 100 Hz during the transfer, ±0.15 m/s every
    /// 5 ms, tens of m/s²) and knocked held objects out of the grip. A target set once, or every
    /// step, is approached at the speed limit.
    pub fn advance(&mut self, t0_s: f64, dt_s: f64) -> StepSetpoints {
        let max = self.motor_max_speed_m_s * dt_s;
        for (setpoint, target) in self.motor_setpoint.iter_mut().zip(self.motor_target) {
            *setpoint += (target - *setpoint).clamp(-max, max);
        }
        let max = self.arm_max_speed_rad_s * dt_s;
        let due = self.arm_command_s.map_or(t0_s, |t| t + self.arm_command_period_s);
        let share = (dt_s / (due - t0_s).max(dt_s)).min(1.0);
        for k in 0..6 {
            self.arm_q[k] += ((self.arm_target[k] - self.arm_q[k]) * share).clamp(-max, max);
        }
        StepSetpoints { motors: self.motor_setpoint, arm_q: self.arm_q }
    }
}

/// The object's grip centre seen from the hand.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GripInHand {
    /// Grip centre in the hand frame \[m\].
    pub position_m: [f64; 3],
    /// Speed of the grip centre relative to the hand point it coincides with [m/s].
    pub slip_speed_m_s: f64,
}

/// Where the grip centre `p` (moving at `v_grip`) is in the hand and how fast it slips, from the
/// hand's pose and its linear (`v_hand`, at the hand origin) and angular (`w_hand`) velocity.
pub fn grip_in_hand(
    hand: &Isometry3<f64>,
    v_hand: Vector3<f64>,
    w_hand: Vector3<f64>,
    p: Vector3<f64>,
    v_grip: Vector3<f64>,
) -> GripInHand {
    let v_hand_at = v_hand + w_hand.cross(&(p - hand.translation.vector));
    GripInHand {
        position_m: (hand.inverse() * Point3::from(p)).coords.into(),
        slip_speed_m_s: (v_grip - v_hand_at).norm(),
    }
}
