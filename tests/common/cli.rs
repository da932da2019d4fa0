//! The `tendril` binary as a user calls it, from the project's folder.

use std::process::{Command, Output};

/// `tendril` as a command to give arguments to and start, in the project's folder.
pub fn tendril_command() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_tendril"));
    c.current_dir(env!("CARGO_MANIFEST_DIR"));
    c
}

/// Runs `tendril ARGS` in the project's folder and waits for it.
pub fn tendril(args: &[&str]) -> Output {
    tendril_command().args(args).output().expect("the binary runs")
}

/// Its standard error as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}
