//! `triad calib` (not yet implemented).

/// Arguments of `triad calib`.
#[derive(clap::Args)]
pub struct CalibArgs {}

/// Runs `triad calib`.
pub fn run(_args: CalibArgs) -> anyhow::Result<std::process::ExitCode> {
    anyhow::bail!("`triad calib` is not implemented yet")
}
