//! `drivespec completions SHELL`: the shell completion script, from the command's own
//! definition (`clap_complete`).

use crate::Outcome;
use anyhow::Result;
use clap_complete::Shell;

/// Print the completion script of a shell to standard output.
#[derive(clap::Args)]
pub struct CompletionsArgs {
    /// Shell: bash, zsh, fish, elvish or powershell.
    shell: Shell,
}

/// Runs `drivespec completions`.
pub fn run(args: CompletionsArgs, mut cmd: clap::Command) -> Result<Outcome> {
    // Rendered into memory first: the generator panics on a write error, the printing
    // below reports it (a closed pipe ends quietly).
    let mut script = Vec::new();
    let name = cmd.get_name().to_owned();
    clap_complete::generate(args.shell, &mut cmd, name, &mut script);
    say_raw!("{}", String::from_utf8_lossy(&script))?;
    Ok(Outcome::Pass)
}
