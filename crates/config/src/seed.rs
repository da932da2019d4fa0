//! Seeds span all of `u64`, but a TOML integer is an `i64`: seeds above `i64::MAX` are written as
//! decimal strings (`seed = "18446744073709551615"`, which `--set seed=…` and `--seed` produce).

use serde::{Deserialize, Deserializer};

/// Deserialises a seed from a non-negative integer or a decimal string of a `u64`.
pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<u64, D::Error> {
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum Raw {
        Int(i64),
        Text(String),
    }
    match Raw::deserialize(d)? {
        Raw::Int(i) => u64::try_from(i).map_err(|_| serde::de::Error::custom(format!("must be >= 0, got {i}"))),
        Raw::Text(s) => s
            .trim()
            .parse()
            .map_err(|_| serde::de::Error::custom(format!("must be a whole number from 0 to {}, got {s:?}", u64::MAX))),
    }
}

/// Serialises a seed as [`deserialize`] reads it: an integer up to `i64::MAX` (TOML's largest),
/// a decimal string above, so `scenario.toml` round-trips every seed.
pub fn serialize<S: serde::Serializer>(seed: &u64, s: S) -> Result<S::Ok, S::Error> {
    match i64::try_from(*seed) {
        Ok(i) => s.serialize_i64(i),
        Err(_) => s.serialize_str(&seed.to_string()),
    }
}

/// The TOML value for `seed`: an integer where TOML can hold it, else its decimal string.
pub fn to_toml(seed: u64) -> toml::Value {
    i64::try_from(seed).map_or_else(|_| toml::Value::String(seed.to_string()), toml::Value::Integer)
}

#[cfg(test)]
mod tests {
    #[derive(serde::Deserialize, serde::Serialize)]
    struct S {
        #[serde(deserialize_with = "super::deserialize", serialize_with = "super::serialize")]
        seed: u64,
    }

    #[test]
    fn accepts_every_u64_and_refuses_negatives() {
        let s: S = toml::from_str("seed = \"18446744073709551615\"").unwrap();
        assert_eq!(s.seed, u64::MAX);
        let s: S = toml::from_str("seed = 7").unwrap();
        assert_eq!(s.seed, 7);
        assert!(toml::from_str::<S>("seed = -1").is_err());
        assert!(toml::from_str::<S>("seed = \"x\"").is_err());
        assert_eq!(super::to_toml(u64::MAX), toml::Value::String(u64::MAX.to_string()));
        for seed in [0, 7, i64::MAX as u64, i64::MAX as u64 + 1, u64::MAX] {
            let back: S = toml::from_str(&toml::to_string(&S { seed }).unwrap()).unwrap();
            assert_eq!(back.seed, seed);
        }
    }
}
