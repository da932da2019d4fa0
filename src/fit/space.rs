//! The parameters a fit or a tune searches: scenario keys with bounds and a scale, mapped to the
//! unit cube the optimizer works in.

use serde::Deserialize;

/// How a parameter's range is searched.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Scale {
    /// Evenly in the value (the default).
    #[default]
    Linear,
    /// Evenly in the logarithm of the value (bounds must be > 0): for quantities known to within a
    /// factor, such as a time constant or a stiffness.
    Log,
}

/// A `[parameters."KEY"]` table as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParameterSpec {
    /// Lower bound.
    pub min: f64,
    /// Upper bound.
    pub max: f64,
    /// `"linear"` (default) or `"log"`.
    #[serde(default)]
    pub scale: Scale,
    /// Where the search starts (default: the middle of the range on its scale), for example the
    /// twin's current calibration.
    pub start: Option<f64>,
    /// Whether the key takes whole numbers (`finger.segments`); default: real numbers.
    #[serde(default)]
    pub integer: bool,
}

/// One parameter of the search: a scenario key and its range.
#[derive(Debug, Clone, PartialEq)]
pub struct Parameter {
    /// Dotted scenario key (`finger.relaxation_time_s`).
    pub key: String,
    /// Lower bound.
    pub min: f64,
    /// Upper bound.
    pub max: f64,
    /// Search scale.
    pub scale: Scale,
    /// Start value.
    pub start: f64,
    /// Whole numbers only.
    pub integer: bool,
}

impl Parameter {
    /// Checks a spec's bounds (finite, min < max, > 0 on a log scale, start inside) and builds the
    /// parameter; the error is the reason, for the caller to name the file and key.
    pub fn from_spec(key: &str, spec: &ParameterSpec) -> Result<Parameter, String> {
        let ParameterSpec { min, max, scale, start, integer } = *spec;
        if !min.is_finite() || !max.is_finite() {
            return Err(format!("bounds must be finite numbers, got min = {min}, max = {max}"));
        }
        if min >= max {
            return Err(format!("empty or inverted bounds: min = {min} must be below max = {max}"));
        }
        if scale == Scale::Log && min <= 0.0 {
            return Err(format!("a log scale needs min > 0, got {min}"));
        }
        let mut p = Parameter { key: key.into(), min, max, scale, start: f64::NAN, integer };
        let start = start.unwrap_or_else(|| p.from_unit(0.5));
        if !(min..=max).contains(&start) {
            return Err(format!("start = {start} is outside [{min}, {max}]"));
        }
        p.start = start;
        Ok(p)
    }

    fn warp(&self, v: f64) -> f64 {
        match self.scale {
            Scale::Linear => v,
            Scale::Log => v.ln(),
        }
    }

    /// The value's place in the range on the parameter's scale: 0 at `min`, 1 at `max`.
    pub fn to_unit(&self, v: f64) -> f64 {
        (self.warp(v) - self.warp(self.min)) / (self.warp(self.max) - self.warp(self.min))
    }

    /// The value at `u` (clamped to [0, 1]) of the range, rounded for an integer key.
    pub fn from_unit(&self, u: f64) -> f64 {
        let u = u.clamp(0.0, 1.0);
        let w = self.warp(self.min) + u * (self.warp(self.max) - self.warp(self.min));
        let v = match self.scale {
            Scale::Linear => w,
            Scale::Log => w.exp(),
        }
        .clamp(self.min, self.max);
        if self.integer { v.round() } else { v }
    }

    /// The value as the TOML a scenario takes (an integer for an integer key).
    pub fn toml_value(&self, v: f64) -> toml::Value {
        if self.integer { toml::Value::Integer(v.round() as i64) } else { toml::Value::Float(v) }
    }

    /// The `--set` override that puts `v` at this key (its scenario key, without a scope).
    pub fn override_at(&self, v: f64) -> tendril_config::Override {
        tendril_config::Override { key: self.scenario_key().into(), value: self.toml_value(v) }
    }

    /// The scope of a key written `NAME:KEY` (a fit's target or recording name), which the
    /// parameter applies to alone; None for a key that applies to every run. Scenario keys hold no
    /// `:`, so the first one separates the scope.
    pub fn scope(&self) -> Option<&str> {
        self.key.split_once(':').map(|(scope, _)| scope)
    }

    /// The scenario key, without the scope.
    pub fn scenario_key(&self) -> &str {
        self.key.split_once(':').map_or(&self.key, |(_, key)| key)
    }

    /// Whether the parameter applies to the run named `name` (unscoped ones apply to every run).
    pub fn applies_to(&self, name: &str) -> bool {
        self.scope().is_none_or(|scope| scope == name)
    }
}

/// Whether two points are the same up to the rounding of the unit-cube mapping (1e-9 relative).
pub fn same_point(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() <= 1e-9 * x.abs().max(y.abs()).max(1e-300))
}

/// Parses the `[parameters]` table (key → spec); `what` names the table in messages.
pub fn parameters(
    file: &std::path::Path,
    specs: &std::collections::BTreeMap<String, ParameterSpec>,
) -> Result<Vec<Parameter>, tendril_config::ScenarioError> {
    if specs.is_empty() {
        return Err(tendril_config::ScenarioError::Invalid {
            file: file.into(),
            key: "parameters".into(),
            reason: "names no parameter: add a [parameters.\"KEY\"] table with min and max".into(),
        });
    }
    specs
        .iter()
        .map(|(key, spec)| {
            Parameter::from_spec(key, spec).map_err(|reason| tendril_config::ScenarioError::Invalid {
                file: file.into(),
                key: format!("parameters.\"{key}\""),
                reason,
            })
        })
        .collect()
}

/// Checks that every parameter's bounds and start are valid values of its key in each scenario
/// (`(file, table)`: where the scenario came from, its parsed table): a key that does not exist,
/// or a bound outside the key's valid range, is an error naming `spec_file` and the parameter.
pub fn check_bounds(
    spec_file: &std::path::Path,
    params: &[Parameter],
    scenarios: &[(&std::path::Path, &toml::Table)],
) -> Result<(), tendril_config::ScenarioError> {
    for p in params {
        for (which, v) in [("min", p.min), ("max", p.max), ("start", p.start)] {
            for (file, table) in scenarios {
                let mut t = (*table).clone();
                let checked = tendril_config::apply_overrides(&mut t, &[p.override_at(v)]).and_then(|()| {
                    tendril_config::from_table::<tendril_run::scenario::PickPlaceScenario>(t, file).map(|_| ())
                });
                if let Err(e) = checked {
                    let reason = match e {
                        tendril_config::ScenarioError::Invalid { reason, .. }
                            if reason.starts_with("unknown field") =>
                        {
                            format!("not a scenario key: {reason} (in {})", file.display())
                        }
                        tendril_config::ScenarioError::Invalid { key, reason, .. } if key == p.key => {
                            format!("{which} = {v} is not a valid value of the key: {reason} (in {})", file.display())
                        }
                        tendril_config::ScenarioError::Invalid { key, reason, .. }
                            if p.key.starts_with(&key) || key == "(top level)" =>
                        {
                            format!("not a scenario key: {reason} (in {})", file.display())
                        }
                        other => format!("{which} = {v} makes the scenario invalid: {other}"),
                    };
                    return Err(tendril_config::ScenarioError::Invalid {
                        file: spec_file.into(),
                        key: format!("parameters.\"{}\"", p.key),
                        reason,
                    });
                }
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(min: f64, max: f64, scale: Scale) -> ParameterSpec {
        ParameterSpec { min, max, scale, start: None, integer: false }
    }

    #[test]
    fn unit_round_trip_on_both_scales() {
        let p = Parameter::from_spec("a", &spec(5.0, 60.0, Scale::Log)).unwrap();
        assert!((p.start - (5.0f64 * 60.0).sqrt()).abs() < 1e-9, "{}", p.start);
        for v in [5.0, 15.0, 60.0] {
            assert!((p.from_unit(p.to_unit(v)) - v).abs() < 1e-9);
        }
        let q = Parameter::from_spec("b", &spec(0.6, 1.6, Scale::Linear)).unwrap();
        assert!((q.from_unit(0.25) - 0.85).abs() < 1e-12);
        assert_eq!(q.from_unit(-3.0), 0.6);
        assert_eq!(q.from_unit(7.0), 1.6);
    }

    #[test]
    fn a_scoped_key_applies_to_its_runs_alone() {
        let p = Parameter::from_spec("hammer:object.friction", &spec(0.5, 1.5, Scale::Linear)).unwrap();
        assert_eq!((p.scope(), p.scenario_key()), (Some("hammer"), "object.friction"));
        assert!(p.applies_to("hammer") && !p.applies_to("crimper"));
        assert_eq!(p.override_at(1.0).key, "object.friction");
        let q = Parameter::from_spec("finger.relaxed_fraction", &spec(0.01, 0.5, Scale::Log)).unwrap();
        assert!(q.scope().is_none() && q.applies_to("crimper") && q.applies_to("hammer"));
    }

    #[test]
    fn bad_bounds_are_refused_with_the_reason() {
        assert!(Parameter::from_spec("a", &spec(2.0, 1.0, Scale::Linear)).unwrap_err().contains("inverted"));
        assert!(Parameter::from_spec("a", &spec(1.0, 1.0, Scale::Linear)).unwrap_err().contains("empty"));
        assert!(Parameter::from_spec("a", &spec(0.0, 1.0, Scale::Log)).unwrap_err().contains("log"));
        assert!(Parameter::from_spec("a", &spec(f64::NAN, 1.0, Scale::Linear)).unwrap_err().contains("finite"));
        let mut s = spec(1.0, 2.0, Scale::Linear);
        s.start = Some(3.0);
        assert!(Parameter::from_spec("a", &s).unwrap_err().contains("outside"));
    }
}
