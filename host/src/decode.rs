//! `triad decode` (not yet implemented).

/// Arguments of `triad decode`.
#[derive(clap::Args)]
pub struct DecodeArgs {}

/// Runs `triad decode`.
pub fn run(_args: DecodeArgs) -> anyhow::Result<std::process::ExitCode> {
    anyhow::bail!("`triad decode` is not implemented yet")
}
