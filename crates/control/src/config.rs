//! [`ControllerConfig`]: the `[controller]` section, which force controller a run uses and its
//! keys, and the controller it builds.

use super::controller::ForceController;
use super::feedforward::{Feedforward, FeedforwardConfig};
use super::pid::{Pid, PidConfig};
use super::slip_margin::{SlipMargin, SlipMarginConfig};
use serde::{Deserialize, Deserializer, Serialize};
use tendril_config::{Checker, Validate};

/// The force controller's configuration (TOML `[controller]`): `type` picks the controller, the
/// other keys are that type's. `type` defaults to `"pid"`.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum ControllerConfig {
    /// `type = "pid"`: the paper's PID on the force error ([`PidConfig`]'s keys).
    Pid(PidConfig),
    /// `type = "feedforward"`: the PID on a setpoint raised ahead of and during the arm's moves
    /// ([`FeedforwardConfig`]'s keys, [`crate::feedforward`]).
    Feedforward(FeedforwardConfig),
    /// `type = "slip_margin"`: a grip kept a margin above the friction limit of the planned load
    /// ([`SlipMarginConfig`]'s keys, [`crate::slip_margin`]).
    SlipMargin(SlipMarginConfig),
}

impl Default for ControllerConfig {
    fn default() -> Self {
        ControllerConfig::Pid(PidConfig::default())
    }
}

impl ControllerConfig {
    /// The known values of `type`.
    pub const TYPES: &'static [&'static str] = &["pid", "feedforward", "slip_margin"];

    /// The value of `type` for this configuration.
    pub fn type_name(&self) -> &'static str {
        match self {
            ControllerConfig::Pid(_) => "pid",
            ControllerConfig::Feedforward(_) => "feedforward",
            ControllerConfig::SlipMargin(_) => "slip_margin",
        }
    }

    /// The configuration of the PID in this controller, if it has one (summaries report its
    /// gains): the PID's own, and the feedback PID of `feedforward` and `slip_margin`.
    pub fn pid(&self) -> Option<PidConfig> {
        match self {
            ControllerConfig::Pid(c) => Some(*c),
            ControllerConfig::Feedforward(c) => Some(c.pid()),
            ControllerConfig::SlipMargin(c) => Some(c.pid()),
        }
    }

    /// A controller at rest for this configuration.
    pub fn build(&self) -> Box<dyn ForceController> {
        match self {
            ControllerConfig::Pid(c) => Box::new(Pid::new(*c)),
            ControllerConfig::Feedforward(c) => Box::new(Feedforward::new(*c)),
            ControllerConfig::SlipMargin(c) => Box::new(SlipMargin::new(*c)),
        }
    }
}

impl Validate for ControllerConfig {
    fn validate(&self, at: &mut Checker) {
        // The variant's keys sit directly in `[controller]`, so no extra section level.
        match self {
            ControllerConfig::Pid(c) => c.validate(at),
            ControllerConfig::Feedforward(c) => c.validate(at),
            ControllerConfig::SlipMargin(c) => c.validate(at),
        }
    }
}

impl<'de> Deserialize<'de> for ControllerConfig {
    /// Reads the section as a table, takes `type` (default `"pid"`) and deserialises the other
    /// keys as that type's configuration, unknown keys refused. (Serde's internally tagged enums
    /// neither default the tag nor keep `deny_unknown_fields`.) Errors inside the section keep
    /// their dotted key through [`tendril_config::deserialize_section`].
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let mut table = toml::Table::deserialize(deserializer)?;
        let kind = match table.remove("type") {
            None => "pid".to_string(),
            Some(toml::Value::String(s)) => s,
            Some(other) => {
                return Err(tendril_config::section_error(
                    "type",
                    &format!("must be a string, one of {}, got {other}", known_types()),
                ));
            }
        };
        match kind.as_str() {
            "pid" => tendril_config::deserialize_section(table).map(ControllerConfig::Pid),
            "feedforward" => tendril_config::deserialize_section(table).map(ControllerConfig::Feedforward),
            "slip_margin" => tendril_config::deserialize_section(table).map(ControllerConfig::SlipMargin),
            _ => Err(tendril_config::section_error(
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
    use crate::controller::{ArmMotion, ControlContext, MoveOutlook};
    use serde::{Deserialize, Serialize};
    use std::path::Path;
    use tendril_cell::Phase;
    use tendril_config::ScenarioError;

    /// A file with a `[controller]` section, as a scenario has one.
    #[derive(Debug, Deserialize, Serialize)]
    #[serde(deny_unknown_fields)]
    struct WithController {
        #[serde(default)]
        controller: ControllerConfig,
    }

    impl Validate for WithController {
        fn validate(&self, at: &mut Checker) {
            at.section("controller", &self.controller);
        }
    }

    fn load(controller: &str) -> Result<WithController, ScenarioError> {
        tendril_config::from_str(&format!("[controller]\n{controller}\n"), Path::new("t.toml"), &[])
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
        let again: WithController = tendril_config::from_str(&text, Path::new("again.toml"), &[]).unwrap();
        assert_eq!(again.controller, scenario.controller);
    }

    #[test]
    fn the_new_types_read_their_keys_and_refuse_others() {
        let ff = load("type = \"feedforward\"\nmargin = 0.08\nlead_s = 3.0\nkp = 15.0").unwrap().controller;
        let expected = FeedforwardConfig { margin: 0.08, lead_s: 3.0, kp: 15.0, ..FeedforwardConfig::default() };
        assert_eq!(ff, ControllerConfig::Feedforward(expected));
        assert_eq!(ff.type_name(), "feedforward");
        assert_eq!(ff.pid().map(|p| p.kp), Some(15.0));
        let sm = load("type = \"slip_margin\"\nmargin = 0.05\nlever_m = 0.5").unwrap().controller;
        let expected = SlipMarginConfig { margin: 0.05, lever_m: 0.5, ..SlipMarginConfig::default() };
        assert_eq!(sm, ControllerConfig::SlipMargin(expected));
        assert_eq!(sm.type_name(), "slip_margin");
        // Each type's keys only.
        let (key, _) = refused_at("type = \"feedforward\"\nlever_m = 0.5");
        assert_eq!(key, "controller.lever_m");
        let (key, _) = refused_at("type = \"slip_margin\"\naccel_gain = 0.5");
        assert_eq!(key, "controller.accel_gain");
        let (key, _) = refused_at("lead_s = 1.0");
        assert_eq!(key, "controller.lead_s");
        let (_, reason) = refused_at("type = \"nope\"");
        assert!(reason.contains("`feedforward`") && reason.contains("`slip_margin`"), "{reason}");
    }

    #[test]
    fn the_new_types_refuse_out_of_range_values_by_key() {
        for (text, key) in [
            ("type = \"feedforward\"\nmargin = -0.1", "controller.margin"),
            ("type = \"feedforward\"\nlead_s = 1e9", "controller.lead_s"),
            ("type = \"feedforward\"\naccel_gain = nan", "controller.accel_gain"),
            ("type = \"feedforward\"\nkp = -1.0", "controller.kp"),
            ("type = \"slip_margin\"\nmargin = 2.0", "controller.margin"),
            ("type = \"slip_margin\"\nstatic_margin = -1.0", "controller.static_margin"),
            ("type = \"slip_margin\"\nlever_m = 5.0", "controller.lever_m"),
            ("type = \"slip_margin\"\nforce_gain_n_per_deg = inf", "controller.force_gain_n_per_deg"),
            ("type = \"slip_margin\"\nmax_speed_deg_s = 0.0", "controller.max_speed_deg_s"),
            ("type = \"slip_margin\"\nmax_release_deg_s = -1.0", "controller.max_release_deg_s"),
            ("type = \"feedforward\"\nmax_release_deg_s = 1000.0", "controller.max_release_deg_s"),
        ] {
            let (k, reason) = refused_at(text);
            assert_eq!(k, key, "{text}: {reason}");
        }
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
                outlook: MoveOutlook::default(),
            };
            assert_eq!(boxed.update(&ctx).to_bits(), direct.update(1.0, force_n, 0.01, ctx.blocked).to_bits());
        }
    }
}
