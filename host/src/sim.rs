//! `triad sim` (not yet implemented).

/// Arguments of `triad sim`.
#[derive(clap::Args)]
pub struct SimArgs {}

/// Runs `triad sim`.
pub fn run(_args: SimArgs) -> anyhow::Result<std::process::ExitCode> {
    anyhow::bail!("`triad sim` is not implemented yet")
}
