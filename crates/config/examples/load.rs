//! A configuration type of your own, loaded with overrides and refused with its key:
//! `cargo run -p tendril-config --example load -- kp=250`.

use serde::Deserialize;
use std::path::Path;
use tendril_config::{Checker, Override, Validate};

/// A controller's gains (TOML `[pid]`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Gains {
    kp: f64,
    #[serde(default)]
    ki: f64,
}

impl Validate for Gains {
    fn validate(&self, at: &mut Checker) {
        at.in_range("kp", self.kp, 0.0, 100.0);
        at.in_range("ki", self.ki, 0.0, 10.0);
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct File {
    pid: Gains,
}

impl Validate for File {
    fn validate(&self, at: &mut Checker) {
        at.section("pid", &self.pid);
    }
}

fn main() {
    let text = "[pid]\nkp = 20.0\n";
    let sets: Vec<Override> = std::env::args().skip(1).map(|a| format!("pid.{a}").parse().unwrap()).collect();
    match tendril_config::from_str::<File>(text, Path::new("gains.toml"), &sets) {
        Ok(f) => println!("kp {} ki {}", f.pid.kp, f.pid.ki),
        Err(e) => println!("{e}"),
    }
}
