//! `tendril physics-check`: builds a scene from a scenario and runs a scripted grasp, printing the
//! readout, to help tune the finger.

use super::{FingerConfig, ObjectConfig, PhysicsConfig, PhysicsError, SceneModel, SceneSpec};
use serde::Deserialize;
use tendril_config::{Checker, Validate};
use tendril_ur5e::kinematics as ur5e;

/// The script: grow, twine, hold, lift (time 0 = start; printed times are simulated seconds).
#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct CheckScenario {
    /// `[physics]`.
    pub physics: PhysicsConfig,
    /// `[finger]`.
    pub finger: FingerConfig,
    /// `[object]`.
    pub object: ObjectConfig,
    /// `[check]`.
    pub check: CheckScript,
}

/// `[check]`: the scripted grasp.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CheckScript {
    /// Growth commanded at t = 0 \[m\].
    pub growth_m: f64,
    /// Twine wound in once the strip is grown \[m\].
    pub twine_m: f64,
    /// Winding speed of that ramp [m/s] (a steady wrap; full motor speed flings the strip's tip).
    pub wind_speed_m_s: f64,
    /// Hold before lifting \[s\].
    pub hold_s: f64,
    /// Lift height of the hand after the hold \[m\] (straight up, joint targets by inverse kinematics).
    pub lift_m: f64,
    /// Duration of the lift ramp \[s\].
    pub lift_duration_s: f64,
    /// Time after the lift starts \[s\].
    pub after_lift_s: f64,
    /// Print period \[s\].
    pub print_every_s: f64,
    /// Pad-force setpoint \[N\] of a plain integral loop on the twine, active after the twine ramp;
    /// 0 = open loop (the twine stays where the ramp left it). A stand-in for the PID, for tuning only.
    pub pad_setpoint_n: f64,
    /// Gain of that loop [m of tendon per N per s].
    pub loop_gain_m_per_n_s: f64,
    /// Stop the loop when the lift starts and hold the twine there (the paper's "without feedback"
    /// runs: grasp to the setpoint, then move with the motor position fixed).
    pub freeze_at_lift: bool,
}

impl Default for CheckScript {
    fn default() -> Self {
        CheckScript {
            growth_m: 0.14,
            twine_m: 0.03,
            wind_speed_m_s: 0.0075,
            hold_s: 3.0,
            lift_m: 0.1,
            lift_duration_s: 2.0,
            after_lift_s: 3.0,
            print_every_s: 0.25,
            pad_setpoint_n: 0.0,
            loop_gain_m_per_n_s: 0.002,
            freeze_at_lift: false,
        }
    }
}

impl Validate for CheckScenario {
    fn validate(&self, at: &mut Checker) {
        at.section("physics", &self.physics);
        at.section("finger", &self.finger);
        at.section("object", &self.object);
        at.non_negative("check.growth_m", self.check.growth_m);
        at.non_negative("check.twine_m", self.check.twine_m);
        at.positive("check.wind_speed_m_s", self.check.wind_speed_m_s);
        at.non_negative("check.hold_s", self.check.hold_s);
        at.finite("check.lift_m", self.check.lift_m);
        at.positive("check.lift_duration_s", self.check.lift_duration_s);
        at.non_negative("check.after_lift_s", self.check.after_lift_s);
        at.positive("check.print_every_s", self.check.print_every_s);
        at.non_negative("check.pad_setpoint_n", self.check.pad_setpoint_n);
        at.non_negative("check.loop_gain_m_per_n_s", self.check.loop_gain_m_per_n_s);
    }
}

/// Runs the script, printing one line per print period; returns the first physics error.
pub fn run(s: &CheckScenario) -> Result<(), PhysicsError> {
    let spec = SceneSpec {
        physics: s.physics.clone(),
        finger: s.finger.clone(),
        object: Some(s.object.clone()),
        extra_pads: Vec::new(),
        arm_q0: ur5e::HOME,
        produce: Default::default(),
    };
    let mut scene = SceneModel::build(&spec)?.start()?;
    let c = &s.check;
    // Growth runs at the motor's speed; the twine ramp starts 0.5 s after it is done.
    let t_twine = c.growth_m / s.finger.motor_max_speed_m_s + 0.5;
    let t_wind = c.twine_m / c.wind_speed_m_s;
    let t_lift = t_twine + t_wind + c.hold_s;
    let end = t_lift + c.after_lift_s;
    let every = (c.print_every_s / scene.timestep()).round().max(1.0) as usize;
    println!("t_s pad_N grip_N contacts twine_m creep_m tension_N obj_in_hand_z_mm slip_mm_s hand_z_m");
    let mut k = 0usize;
    let z0 = scene.readout().object_in_hand_m[2];
    scene.set_growth(c.growth_m)?;
    let start = ur5e::forward(&ur5e::HOME);
    let mut seed = ur5e::HOME;
    let mut twine = 0.0;
    while scene.time() < end {
        let t = scene.time();
        let frozen = c.freeze_at_lift && t >= t_lift;
        if c.pad_setpoint_n > 0.0 && t > t_twine + t_wind && !frozen {
            let error = c.pad_setpoint_n - scene.readout().pad_force_n;
            twine += c.loop_gain_m_per_n_s * error * scene.timestep();
        } else if c.pad_setpoint_n == 0.0 {
            twine = c.twine_m * ((t - t_twine) / t_wind).clamp(0.0, 1.0);
        }
        scene.set_twine(twine)?;
        if t >= t_lift {
            let frac = ((t - t_lift) / c.lift_duration_s).min(1.0);
            // Smooth (cosine) profile: zero velocity at both ends.
            let dz = c.lift_m * 0.5 * (1.0 - (std::f64::consts::PI * frac).cos());
            let mut target = start;
            target.translation.vector.z += dz;
            if let Some(q) = ur5e::inverse_near(&target, &seed) {
                seed = q;
                scene.set_arm_target(q)?;
            }
        }
        scene.step()?;
        k += 1;
        if k.is_multiple_of(every) {
            let r = scene.readout();
            println!(
                "{:.3} {:.4} {:.4} {} {:.5} {:.5} {:.3} {:.3} {:.3} {:.4} {:.2} {:.2} {:.3} {:.3?}",
                r.time_s,
                r.pad_force_n,
                r.grip_force_n,
                r.grip_contacts,
                r.twine_m,
                r.creep_m,
                r.tendon_tension_n,
                (r.object_in_hand_m[2] - z0) * 1e3,
                r.slip_speed_m_s * 1e3,
                r.hand_pos_m[2],
                r.object_in_hand_m[0] * 1e3,
                r.object_in_hand_m[1] * 1e3,
                r.object_quat[1],
                r.arm_q
            );
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;
    use tendril_config::{ScenarioError, from_str};

    fn load(text: &str) -> Result<CheckScenario, ScenarioError> {
        from_str(text, Path::new("t.toml"), &[])
    }

    #[test]
    fn sections_parse_with_defaults_and_reject_bad_keys() {
        let s =
            load("[physics]\ntimestep_s = 0.002\ncone = \"pyramidal\"\n[object]\nname = \"hammer\"\nfriction = 0.6\n")
                .unwrap();
        assert_eq!(s.physics.timestep_s, 0.002);
        assert_eq!(s.physics.cone, super::super::Cone::Pyramidal);
        assert_eq!(s.object.name.as_deref(), Some("hammer"));
        assert_eq!(s.finger, FingerConfig::default());
        let err = load("[finger]\nrelaxed_fraction = 1.5\n").unwrap_err().to_string();
        assert!(err.contains("finger.relaxed_fraction"), "{err}");
        let err = load("[physics]\ntimestep = 0.002\n").unwrap_err().to_string();
        assert!(err.contains("timestep"), "{err}");
        let err = load("[object]\nname = \"spoon\"\n").unwrap_err().to_string();
        assert!(err.contains("object.name"), "{err}");
    }
}
