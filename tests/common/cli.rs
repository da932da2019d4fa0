//! The `tendril` binary as a user calls it, from the project's folder.

use std::process::{Command, Output};

/// Runs `tendril ARGS` in the project's folder and waits for it.
pub fn tendril(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tendril"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(args)
        .output()
        .expect("the binary runs")
}

/// Its standard error as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}
