//! `triad correct` (not yet implemented).

/// Arguments of `triad correct`.
#[derive(clap::Args)]
pub struct CorrectArgs {}

/// Runs `triad correct`.
pub fn run(_args: CorrectArgs) -> anyhow::Result<std::process::ExitCode> {
    anyhow::bail!("`triad correct` is not implemented yet")
}
