//! `--set key.path=value` overrides, applied to the parsed TOML before deserialisation so
//! they go through exactly the same checks as the file.

use super::error::ScenarioError;

/// One `--set` argument: a dotted key and a TOML value.
#[derive(Debug, Clone, PartialEq)]
pub struct Override {
    /// Dotted key path, e.g. `controller.kp`.
    pub key: String,
    /// The value, parsed as a TOML literal (`20`, `true`, `"hammer"`); text that is not a TOML
    /// literal is taken as a string, so `--set object=hammer` works unquoted.
    pub value: toml::Value,
}

impl Override {
    /// `physics.models_dir` from a command line's `--models DIR`: relative to the working
    /// directory, as paths on a command line are (in a scenario file they are relative to the file).
    pub fn models_dir(dir: &std::path::Path) -> Override {
        let dir = std::path::absolute(dir).unwrap_or_else(|_| dir.to_path_buf());
        Override { key: "physics.models_dir".into(), value: toml::Value::String(dir.display().to_string()) }
    }
}

impl std::str::FromStr for Override {
    type Err = ScenarioError;

    fn from_str(arg: &str) -> Result<Self, Self::Err> {
        let bad = |reason: &str| ScenarioError::BadOverride { arg: arg.to_string(), reason: reason.to_string() };
        let (key, raw) = arg.split_once('=').ok_or_else(|| bad("expected KEY=VALUE"))?;
        let key = key.trim();
        if key.is_empty() || key.split('.').any(|part| part.is_empty()) {
            return Err(bad("the key must be a dotted path such as controller.kp"));
        }
        let raw = raw.trim();
        let value = format!("v = {raw}")
            .parse::<toml::Table>()
            .ok()
            .and_then(|mut t| t.remove("v"))
            .unwrap_or_else(|| toml::Value::String(raw.to_string()));
        Ok(Override { key: key.to_string(), value })
    }
}

/// Sets each override's value at its dotted path, creating intermediate tables as needed.
pub fn apply_overrides(table: &mut toml::Table, overrides: &[Override]) -> Result<(), ScenarioError> {
    for o in overrides {
        let parts: Vec<&str> = o.key.split('.').collect();
        let (last, parents) = parts.split_last().expect("FromStr rejects empty keys");
        let mut node = &mut *table;
        for (depth, part) in parents.iter().enumerate() {
            let entry = node.entry(part.to_string()).or_insert_with(|| toml::Value::Table(toml::Table::new()));
            node = entry.as_table_mut().ok_or_else(|| ScenarioError::BadOverride {
                arg: format!("{}={}", o.key, o.value),
                reason: format!("`{}` is a value, not a section", parts[..=depth].join(".")),
            })?;
        }
        node.insert(last.to_string(), o.value.clone());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_numbers_booleans_and_bare_words() {
        let o: Override = "controller.kp=20".parse().unwrap();
        assert_eq!(o.value, toml::Value::Integer(20));
        let o: Override = "feedback = false".parse().unwrap();
        assert_eq!(o.value, toml::Value::Boolean(false));
        let o: Override = "object=hammer".parse().unwrap();
        assert_eq!(o.value, toml::Value::String("hammer".into()));
    }

    #[test]
    fn rejects_missing_equals_and_empty_key_parts() {
        assert!("controller.kp".parse::<Override>().is_err());
        assert!("controller..kp=1".parse::<Override>().is_err());
    }

    #[test]
    fn creates_sections_and_refuses_to_descend_into_values() {
        let mut t: toml::Table = "seed = 1".parse().unwrap();
        apply_overrides(&mut t, &["a.b.c=2.5".parse().unwrap()]).unwrap();
        assert_eq!(t["a"]["b"]["c"].as_float(), Some(2.5));
        let err = apply_overrides(&mut t, &["seed.x=1".parse().unwrap()]).unwrap_err();
        assert!(err.to_string().contains("`seed` is a value"), "{err}");
    }
}
