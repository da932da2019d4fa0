//! Scenario settings a produce item needs, filled in before the table is deserialised so that a
//! run's recorded scenario names the value it ran with.

/// Sets `physics.integrator` to `"discrete"` when the object is a produce item (its resolved
/// `object.file` holds a flex, `tendril_twin::physics::produce`) and the scenario does not set
/// one: MuJoCo 3.17 integrates a flex's elasticity implicitly only in its discrete integrator, and
/// the default `implicitfast` refuses it. A scenario that sets another integrator is left alone
/// (the scene refuses the implicit ones with their key).
pub fn fill_produce_defaults(table: &mut toml::Table) {
    let file = table.get("object").and_then(|o| o.get("file")).and_then(|f| f.as_str());
    let Some(text) = file.and_then(|f| std::fs::read_to_string(f).ok()) else { return };
    if !tendril_twin::physics::produce::is_produce(&text) {
        return;
    }
    let physics = table.entry("physics").or_insert_with(|| toml::Value::Table(toml::Table::new()));
    if let Some(physics) = physics.as_table_mut() {
        physics.entry("integrator").or_insert_with(|| toml::Value::String("discrete".into()));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_produce_item_gets_the_discrete_integrator_unless_the_scenario_sets_one() {
        let dir = tempfile::tempdir().unwrap();
        let item = dir.path().join("berry.xml");
        std::fs::write(&item, r#"<mujoco><worldbody><flexcomp name="produce" type="ellipsoid"/></worldbody></mujoco>"#)
            .unwrap();
        let rigid = dir.path().join("dowel.xml");
        std::fs::write(&rigid, "<mujoco/>").unwrap();
        let filled = |file: &std::path::Path, physics: &str| {
            let mut t: toml::Table =
                format!("[object]\nfile = {:?}\n{physics}", file.display().to_string()).parse().unwrap();
            fill_produce_defaults(&mut t);
            t.get("physics").and_then(|p| p.get("integrator")).and_then(|i| i.as_str()).map(String::from)
        };
        assert_eq!(filled(&item, "").as_deref(), Some("discrete"));
        assert_eq!(filled(&item, "[physics]\nintegrator = \"euler\"").as_deref(), Some("euler"));
        assert_eq!(filled(&rigid, ""), None);
    }
}
