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

/// The TOML value for `seed`: an integer where TOML can hold it, else its decimal string.
pub fn to_toml(seed: u64) -> toml::Value {
    i64::try_from(seed).map_or_else(|_| toml::Value::String(seed.to_string()), toml::Value::Integer)
}

#[cfg(test)]
mod tests {
    #[derive(serde::Deserialize)]
    struct S {
        #[serde(deserialize_with = "super::deserialize")]
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
    }
}
