//! `tendril keys`: the scenario key reference.

use std::process::ExitCode;

/// Arguments of `tendril keys` (none: it prints the whole reference).
#[derive(Debug, clap::Args)]
pub struct KeysArgs {}

pub fn run(_: KeysArgs) -> anyhow::Result<ExitCode> {
    let text = crate::keys::markdown().map_err(|e| anyhow::anyhow!("the key reference: {e}"))?;
    super::emit(&text);
    Ok(ExitCode::SUCCESS)
}
