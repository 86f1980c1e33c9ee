//! `triad completions SHELL` and `triad man`: shell completions and man
//! pages generated from the very argument definitions the binary parses
//! (`clap_complete`, `clap_mangen`), so they cannot drift from it.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context;

use crate::plumbing::outfile;
use crate::plumbing::stdio::{self, note};

/// Arguments of `triad completions`.
#[derive(clap::Args)]
pub struct CompletionsArgs {
    /// The shell whose completion script to print.
    pub shell: clap_complete::Shell,
}

/// Arguments of `triad man`.
#[derive(clap::Args)]
pub struct ManArgs {
    /// Write `triad.1` and one page per subcommand (`triad-sim.1`, ...) into
    /// this directory instead of printing `triad.1` on stdout.
    #[arg(long, value_name = "DIR")]
    pub out_dir: Option<PathBuf>,
}

/// Prints the completion script of `cli` for the asked shell.
pub fn completions(args: CompletionsArgs, mut cli: clap::Command) -> anyhow::Result<ExitCode> {
    // Rendered whole first: the generator panics on a write error (a closed pipe).
    let mut script = Vec::new();
    let name = cli.get_name().to_string();
    clap_complete::generate(args.shell, &mut cli, name, &mut script);
    stdio::print(script)?;
    Ok(ExitCode::SUCCESS)
}

/// Prints `cli`'s man page, or writes every page into `--out-dir`.
pub fn man(args: ManArgs, cli: clap::Command) -> anyhow::Result<ExitCode> {
    match args.out_dir {
        None => {
            let mut page = Vec::new();
            clap_mangen::Man::new(cli).render(&mut page)?;
            stdio::print(page)?;
        }
        Some(dir) => {
            for path in write_pages(cli, &dir)? {
                note!("{}", path.display());
            }
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// The man pages of `cli`: (file name, roff text), the command's first and
/// then its subcommands' at every depth (`triad-calib-fit.1`).
pub fn pages(cli: clap::Command) -> anyhow::Result<Vec<(String, Vec<u8>)>> {
    let mut cli = cli.disable_help_subcommand(true);
    // Building names the subcommands as the user types them (`triad-sim`).
    cli.build();
    let mut out = Vec::new();
    let mut stack = vec![cli];
    while let Some(command) = stack.pop() {
        stack.extend(
            command
                .get_subcommands()
                .filter(|s| !s.is_hide_set())
                .cloned(),
        );
        let man = clap_mangen::Man::new(command);
        let mut text = Vec::new();
        man.render(&mut text)?;
        out.push((man.get_filename(), text));
    }
    Ok(out)
}

/// Writes the pages of `cli` into `dir` (made if missing), each whole or not
/// at all ([`outfile::write_whole`]); returns their paths.
pub fn write_pages(cli: clap::Command, dir: &Path) -> anyhow::Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir).with_context(|| format!("{}: cannot create", dir.display()))?;
    let mut written = Vec::new();
    for (name, text) in pages(cli)? {
        let path = dir.join(&name);
        outfile::write_whole(&path, &text)?;
        written.push(path);
    }
    Ok(written)
}
