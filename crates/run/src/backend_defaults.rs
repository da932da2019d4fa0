//! Scenario settings whose default depends on the physics backend, filled in before the table is
//! deserialised so that a run's recorded scenario names the value it ran with.

use tendril_twin::physics::Backend;

/// Sets `physics.arm_mode` to the backend's default ([`Backend::default_arm_mode`]) when the
/// scenario does not set it. A table without a `[physics]` section or with an unknown backend is
/// left alone (deserialisation reports the latter with its key).
pub fn fill_backend_defaults(table: &mut toml::Table) {
    let Some(physics) = table.get_mut("physics").and_then(|p| p.as_table_mut()) else { return };
    let backend = match physics.get("backend") {
        None => Backend::default(),
        Some(toml::Value::String(name)) => match name.parse::<Backend>() {
            Ok(backend) => backend,
            Err(_) => return,
        },
        Some(_) => return,
    };
    physics.entry("arm_mode").or_insert_with(|| toml::Value::String(backend.default_arm_mode().name().into()));
}

#[cfg(test)]
mod tests {
    use super::*;

    fn filled(text: &str) -> toml::Table {
        let mut table: toml::Table = text.parse().unwrap();
        fill_backend_defaults(&mut table);
        table
    }

    #[test]
    fn each_backend_gets_its_arm_mode_unless_the_scenario_sets_one() {
        assert_eq!(filled("[physics]")["physics"]["arm_mode"].as_str(), Some("dynamic"));
        assert_eq!(filled("[physics]\nbackend = \"rapier\"")["physics"]["arm_mode"].as_str(), Some("kinematic"));
        let set = "[physics]\nbackend = \"mujoco\"\narm_mode = \"kinematic\"";
        assert_eq!(filled(set)["physics"]["arm_mode"].as_str(), Some("kinematic"));
    }

    #[test]
    fn tables_without_physics_or_with_a_bad_backend_are_left_alone() {
        assert!(filled("seed = 1").get("physics").is_none());
        assert!(filled("[physics]\nbackend = \"bullet\"")["physics"].get("arm_mode").is_none());
        assert!(filled("[physics]\nbackend = 3")["physics"].get("arm_mode").is_none());
    }
}
