//! The per-object table a detector chooses settings from (`[detector] table`): for each object
//! class, the scenario keys it sets, `setpoint_n` and the `[controller]` keys. `tendril tune`
//! writes one from its results (`DIR/table.toml`); `scenarios/object-table.toml` is the paper's
//! three objects'.
//!
//! ```toml
//! [classes.crimper]
//! setpoint_n = 0.6
//! "controller.kp" = 80.0
//! "controller.ki" = 2.0
//! [fallback]                 # optional: the settings when the detector reports nothing
//! setpoint_n = 1.0
//! ```
//!
//! A new object is a new `[classes.NAME]` table (NAME as the scenario's `object.name`): nothing to
//! rebuild.

use std::collections::BTreeMap;
use std::path::Path;
use tendril_config::{Checker, Validate};
use tendril_control::ControllerConfig;

/// One class's keys: dotted scenario keys and their values.
pub type ClassKeys = BTreeMap<String, toml::Value>;

/// A per-object table, read.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ObjectTable {
    /// Each class's keys, by class name.
    pub classes: BTreeMap<String, ClassKeys>,
    /// The keys used when the detector reports nothing.
    pub fallback: Option<ClassKeys>,
}

impl ObjectTable {
    /// Reads the table at `path`; the error names the file and what is wrong.
    pub fn read(path: &Path) -> Result<ObjectTable, String> {
        let text = std::fs::read_to_string(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
        ObjectTable::parse(&text).map_err(|e| format!("{}: {e}", path.display()))
    }

    /// Parses a table's text.
    pub fn parse(text: &str) -> Result<ObjectTable, String> {
        let mut table: toml::Table = text.parse().map_err(|e: toml::de::Error| e.message().to_string())?;
        let keys = |name: &str, value: toml::Value| match value {
            toml::Value::Table(t) => Ok(t.into_iter().collect::<ClassKeys>()),
            other => Err(format!("`{name}` must be a table of scenario keys, got {}", other.type_str())),
        };
        let classes = match table.remove("classes") {
            Some(toml::Value::Table(c)) => {
                c.into_iter().map(|(name, v)| Ok((name.clone(), keys(&format!("classes.{name}"), v)?))).collect()
            }
            Some(other) => Err(format!("`classes` must be a table of classes, got {}", other.type_str())),
            None => Err("no [classes.NAME] table: the table names no object".to_string()),
        }?;
        let fallback = table.remove("fallback").map(|v| keys("fallback", v)).transpose()?;
        if let Some(unknown) = table.keys().next() {
            return Err(format!("unknown key `{unknown}` (expected `classes` and `fallback`)"));
        }
        Ok(ObjectTable { classes, fallback })
    }

    /// The class names, in the table's (alphabetical) order.
    pub fn class_names(&self) -> Vec<String> {
        self.classes.keys().cloned().collect()
    }

    /// What is wrong with the table's rows, as (the row's dotted key, the reason): a key other
    /// than `setpoint_n` and `controller.*`, a setpoint that is not a positive number, controller
    /// keys that do not make a valid controller.
    pub fn faults(&self) -> Vec<(String, String)> {
        let mut faults = Vec::new();
        let rows = self
            .classes
            .iter()
            .map(|(n, k)| (format!("classes.{n}"), k))
            .chain(self.fallback.iter().map(|k| ("fallback".to_string(), k)));
        for (row, keys) in rows {
            let mut controller = toml::Table::new();
            for (key, value) in keys {
                if key == "setpoint_n" {
                    if !value
                        .as_float()
                        .or(value.as_integer().map(|i| i as f64))
                        .is_some_and(|f| f.is_finite() && f > 0.0)
                    {
                        faults.push((format!("{row}.setpoint_n"), format!("must be a number > 0, got {value}")));
                    }
                } else if let Some(inner) = key.strip_prefix("controller.") {
                    controller.insert(inner.to_string(), value.clone());
                } else {
                    faults.push((
                        format!("{row}.{key}"),
                        "a class sets `setpoint_n` and `controller.*` keys only".to_string(),
                    ));
                }
            }
            match toml::Value::Table(controller).try_into::<ControllerConfig>() {
                Ok(c) => {
                    let mut at = Checker::default();
                    c.validate(&mut at);
                    faults.extend(at.errors().iter().map(|(k, r)| (format!("{row}.controller.{k}"), r.clone())));
                }
                Err(e) => faults.push((format!("{row}.controller"), e.message().to_string())),
            }
        }
        faults
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_table_reads_its_classes_and_fallback() {
        let t = ObjectTable::parse(
            "[classes.crimper]\nsetpoint_n = 0.6\n\"controller.kp\" = 80.0\n[classes.hammer]\nsetpoint_n = 1.6\n\
             [fallback]\nsetpoint_n = 1.0\n",
        )
        .unwrap();
        assert_eq!(t.class_names(), ["crimper", "hammer"]);
        assert_eq!(t.classes["crimper"]["controller.kp"], toml::Value::Float(80.0));
        assert!(t.fallback.is_some());
        assert!(t.faults().is_empty(), "{:?}", t.faults());
    }

    #[test]
    fn bad_rows_are_named_by_their_keys() {
        let t = ObjectTable::parse(
            "[classes.crimper]\nsetpoint_n = -0.6\n\"controller.kp\" = -1.0\n\"finger.segments\" = 4\n",
        )
        .unwrap();
        let keys: Vec<String> = t.faults().into_iter().map(|(k, _)| k).collect();
        assert!(keys.contains(&"classes.crimper.setpoint_n".to_string()), "{keys:?}");
        assert!(keys.contains(&"classes.crimper.finger.segments".to_string()), "{keys:?}");
        assert!(keys.contains(&"classes.crimper.controller.kp".to_string()), "{keys:?}");
        assert!(ObjectTable::parse("[fallback]\nsetpoint_n = 1.0\n").unwrap_err().contains("no [classes.NAME]"));
        assert!(ObjectTable::parse("[classes]\nhammer = 3\n").unwrap_err().contains("classes.hammer"));
    }
}
