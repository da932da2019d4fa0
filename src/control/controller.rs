//! The force-controller seam, in the manner of ros2_control's controller interface: the task
//! sequencer owns a [`ForceController`] and, each tick the controller is on, hands it a
//! [`ControlContext`] (setpoint, force estimate, tick period, phase, travel-limit flag and the
//! arm's planned motion) and takes back a twine motor speed [°/s].
//!
//! The scenario section `[controller]` is a [`ControllerConfig`]: `type = "pid"` (the default
//! when `type` is left out, so every scenario written before the seam reads unchanged) plus that
//! type's keys. Adding a controller is one file implementing [`ForceController`] plus one
//! [`ControllerConfig`] variant (its name in [`ControllerConfig::TYPES`], its arm in
//! `deserialize`, `validate` and [`ControllerConfig::build`]).

use super::pid::{Pid, PidConfig};
use super::task::Phase;
use crate::hardware::ARM_JOINTS;
use crate::scenario::{Checker, Validate};
use serde::{Deserialize, Deserializer, Serialize};

/// What the task knows of the arm's planned motion at this tick (zero while the arm holds still).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ArmMotion {
    /// Planned joint velocities [rad/s].
    pub qd_rad_s: [f64; ARM_JOINTS],
    /// Planned joint accelerations [rad/s²].
    pub qdd_rad_s2: [f64; ARM_JOINTS],
}

/// Everything a force controller is told each tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControlContext {
    /// Force setpoint \[N\].
    pub setpoint_n: f64,
    /// Compensated force estimate \[N\] (the sensor's, never the true force).
    pub force_n: f64,
    /// Tick period \[s\].
    pub dt_s: f64,
    /// The task phase this tick belongs to.
    pub phase: Phase,
    /// The tendon is at a travel limit in the direction the controller pushes (towards the
    /// setpoint): an integrating controller should not wind up.
    pub blocked: bool,
    /// The arm's planned joint velocities and accelerations at this tick.
    pub arm: ArmMotion,
}

/// A force controller: force estimate in, twine motor speed out.
///
/// `Send` so a run (and its sequencer) can move to a worker thread; `Debug` so the sequencer
/// can print itself.
pub trait ForceController: Send + std::fmt::Debug {
    /// One tick: the twine motor speed [°/s], within ±[`ForceController::max_speed_deg_s`].
    fn update(&mut self, ctx: &ControlContext) -> f64;

    /// Forgets all memory (integral, filters): called when force control starts (the grasp)
    /// and, without feedback while moving, when the arm starts to move.
    fn reset(&mut self);

    /// The largest speed the controller commands [°/s]; the release uncurls at this speed.
    fn max_speed_deg_s(&self) -> f64;
}

impl ForceController for Pid {
    fn update(&mut self, ctx: &ControlContext) -> f64 {
        Pid::update(self, ctx.setpoint_n, ctx.force_n, ctx.dt_s, ctx.blocked)
    }

    fn reset(&mut self) {
        Pid::reset(self);
    }

    fn max_speed_deg_s(&self) -> f64 {
        self.config().max_speed_deg_s
    }
}

/// The force controller's configuration (TOML `[controller]`): `type` picks the controller, the
/// other keys are that type's. `type` defaults to `"pid"`.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum ControllerConfig {
    /// `type = "pid"`: the paper's PID on the force error ([`PidConfig`]'s keys).
    Pid(PidConfig),
}

impl Default for ControllerConfig {
    fn default() -> Self {
        ControllerConfig::Pid(PidConfig::default())
    }
}

impl ControllerConfig {
    /// The known values of `type`.
    pub const TYPES: &'static [&'static str] = &["pid"];

    /// The value of `type` for this configuration.
    pub fn type_name(&self) -> &'static str {
        match self {
            ControllerConfig::Pid(_) => "pid",
        }
    }

    /// The PID's configuration, if this is one (summaries report its gains).
    pub fn pid(&self) -> Option<&PidConfig> {
        match self {
            ControllerConfig::Pid(c) => Some(c),
        }
    }

    /// A controller at rest for this configuration.
    pub fn build(&self) -> Box<dyn ForceController> {
        match self {
            ControllerConfig::Pid(c) => Box::new(Pid::new(*c)),
        }
    }
}

impl Validate for ControllerConfig {
    fn validate(&self, at: &mut Checker) {
        // The variant's keys sit directly in `[controller]`, so no extra section level.
        match self {
            ControllerConfig::Pid(c) => c.validate(at),
        }
    }
}

impl<'de> Deserialize<'de> for ControllerConfig {
    /// Reads the section as a table, takes `type` (default `"pid"`) and deserialises the other
    /// keys as that type's configuration, unknown keys refused. (Serde's internally tagged enums
    /// neither default the tag nor keep `deny_unknown_fields`.) Errors inside the section keep
    /// their dotted key through [`crate::scenario::deserialize_section`].
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let mut table = toml::Table::deserialize(deserializer)?;
        let kind = match table.remove("type") {
            None => "pid".to_string(),
            Some(toml::Value::String(s)) => s,
            Some(other) => {
                return Err(crate::scenario::section_error(
                    "type",
                    &format!("must be a string, one of {}, got {other}", known_types()),
                ));
            }
        };
        match kind.as_str() {
            "pid" => crate::scenario::deserialize_section(table).map(ControllerConfig::Pid),
            _ => Err(crate::scenario::section_error(
                "type",
                &format!("unknown controller type `{kind}`; known types: {}", known_types()),
            )),
        }
    }
}

fn known_types() -> String {
    ControllerConfig::TYPES.iter().map(|t| format!("`{t}`")).collect::<Vec<_>>().join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::scenario::PickPlaceScenario;
    use crate::scenario::ScenarioError;
    use std::path::Path;

    fn load(controller: &str) -> Result<PickPlaceScenario, ScenarioError> {
        let text = format!("name = \"t\"\nsetpoint_n = 1.0\n[object]\nname = \"hammer\"\n[controller]\n{controller}\n");
        crate::scenario::from_str(&text, Path::new("t.toml"), &[])
    }

    fn refused_at(controller: &str) -> (String, String) {
        match load(controller) {
            Err(ScenarioError::Invalid { key, reason, .. }) => (key, reason),
            other => panic!("{controller}: not refused: {other:?}"),
        }
    }

    #[test]
    fn type_pid_explicit_and_omitted_are_the_same() {
        let explicit = load("type = \"pid\"\nkp = 7.0\nki = 0.5").unwrap().controller;
        let omitted = load("kp = 7.0\nki = 0.5").unwrap().controller;
        assert_eq!(explicit, omitted);
        let expected = PidConfig { kp: 7.0, ki: 0.5, ..PidConfig::default() };
        assert_eq!(omitted, ControllerConfig::Pid(expected));
        assert_eq!(load("").unwrap().controller, ControllerConfig::default());
    }

    #[test]
    fn unknown_type_names_the_key_and_the_known_types() {
        let (key, reason) = refused_at("type = \"lqr\"");
        assert_eq!(key, "controller.type");
        assert!(reason.contains("lqr") && reason.contains("`pid`"), "{reason}");
        let (key, reason) = refused_at("type = 3");
        assert_eq!(key, "controller.type");
        assert!(reason.contains("`pid`"), "{reason}");
    }

    #[test]
    fn a_key_the_type_does_not_have_is_refused_by_name() {
        let (key, reason) = refused_at("type = \"pid\"\nslip_margin = 0.2");
        assert_eq!(key, "controller.slip_margin");
        assert!(reason.contains("slip_margin"), "{reason}");
        let (key, _) = refused_at("kq = 1.0");
        assert_eq!(key, "controller.kq");
        let (key, reason) = refused_at("kp = \"fast\"");
        assert_eq!(key, "controller.kp");
        assert!(reason.contains("invalid type"), "{reason}");
    }

    #[test]
    fn out_of_range_values_are_refused_as_before() {
        let (key, reason) = refused_at("kp = -1.0");
        assert_eq!(key, "controller.kp");
        assert!(reason.contains("between"), "{reason}");
        let (key, _) = refused_at("type = \"pid\"\nmax_speed_deg_s = 1000.0");
        assert_eq!(key, "controller.max_speed_deg_s");
    }

    #[test]
    fn the_type_is_written_back_and_reads_again() {
        let scenario = load("kp = 7.0").unwrap();
        let text = toml::to_string(&scenario).unwrap();
        assert!(text.contains("type = \"pid\""), "{text}");
        let again: PickPlaceScenario = crate::scenario::from_str(&text, Path::new("again.toml"), &[]).unwrap();
        assert_eq!(again.controller, scenario.controller);
    }

    #[test]
    fn the_pid_behind_the_trait_is_the_pid() {
        let config = PidConfig { kp: 20.0, ki: 0.05, kd: 0.3, ..PidConfig::default() };
        let mut direct = Pid::new(config);
        let mut boxed = ControllerConfig::Pid(config).build();
        assert_eq!(boxed.max_speed_deg_s(), 90.0);
        for i in 0..200 {
            let force_n = 0.01 * f64::from(i);
            let ctx = ControlContext {
                setpoint_n: 1.0,
                force_n,
                dt_s: 0.01,
                phase: Phase::Grasp,
                blocked: i % 7 == 0,
                arm: ArmMotion::default(),
            };
            assert_eq!(boxed.update(&ctx).to_bits(), direct.update(1.0, force_n, 0.01, ctx.blocked).to_bits());
        }
    }
}
