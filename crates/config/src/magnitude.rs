//! A check every scenario key passes before its own range check: numbers must be finite and of
//! a magnitude a bench-top cell can mean.

/// Largest magnitude of any floating-point value in a scenario, in its key's SI unit.
///
/// Why: no quantity of this cell comes near it (the largest are bus speeds of a few 10⁶ bit/s,
/// which are integers, and stiffnesses of 10⁴ N/m); a value of 10⁹ s, Hz, N or m is a typo or a
/// probe, and values like 10³⁰⁰ overflow to infinity in the first product. Each key then has its
/// own, tighter, physical bound in its section's `validate`.
pub const MAX_MAGNITUDE: f64 = 1e9;

/// The first number in `table` that is not finite or exceeds [`MAX_MAGNITUDE`], as (dotted key,
/// reason). Arrays are searched too (`task.home_deg`, `object.position_m`). Integers count too
/// (an integer is accepted where a float is expected), except the top-level `seed`, which spans
/// all of `u64`.
pub fn check_magnitudes(table: &toml::Table) -> Option<(String, String)> {
    fn walk(key: &str, value: &toml::Value) -> Option<(String, String)> {
        match value {
            toml::Value::Integer(i) if key != "seed" && i.unsigned_abs() as f64 > MAX_MAGNITUDE => Some((
                key.into(),
                format!("{i} is beyond any quantity of the cell (|value| <= {MAX_MAGNITUDE:e} in SI units)"),
            )),
            toml::Value::Float(x) if !x.is_finite() => Some((key.into(), format!("must be a finite number, got {x}"))),
            toml::Value::Float(x) if x.abs() > MAX_MAGNITUDE => Some((
                key.into(),
                format!("{x:e} is beyond any quantity of the cell (|value| <= {MAX_MAGNITUDE:e} in SI units)"),
            )),
            toml::Value::Array(items) => items.iter().find_map(|v| walk(key, v)),
            toml::Value::Table(t) => {
                t.iter().find_map(|(k, v)| walk(&if key.is_empty() { k.clone() } else { format!("{key}.{k}") }, v))
            }
            _ => None,
        }
    }
    table.iter().find_map(|(k, v)| walk(k, v))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_the_key_of_a_non_finite_or_huge_value() {
        let t: toml::Table = "a = 1.0\n[b]\nc = [1.0, nan]\n".parse().unwrap();
        assert_eq!(check_magnitudes(&t).map(|(k, _)| k).as_deref(), Some("b.c"));
        let t: toml::Table = "[task]\ngrasp_s = 1e10\n".parse().unwrap();
        let (key, reason) = check_magnitudes(&t).unwrap();
        assert!(key == "task.grasp_s" && reason.contains("beyond"), "{key}: {reason}");
        let t: toml::Table = "a = 1e9\nb = -1e9\nseed = 9000000000000000000\n".parse().unwrap();
        assert_eq!(check_magnitudes(&t), None);
        let t: toml::Table = "[physics]\niterations = 9000000000000000000\n".parse().unwrap();
        assert_eq!(check_magnitudes(&t).map(|(k, _)| k).as_deref(), Some("physics.iterations"));
    }
}
