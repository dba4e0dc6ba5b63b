//! `drivespec man`: the manual pages in roff, from the command's own definition
//! (`clap_mangen`).

use crate::Outcome;
use anyhow::{Context as _, Result};
use std::path::{Path, PathBuf};

/// Print the man page drivespec(1) to standard output, or write every page to a folder.
#[derive(clap::Args)]
pub struct ManArgs {
    /// Write drivespec.1 and one page per subcommand (drivespec-conform.1, …) into this
    /// folder instead, and print their paths.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
}

/// Runs `drivespec man`.
pub fn run(args: ManArgs, cmd: clap::Command) -> Result<Outcome> {
    let mut cmd = cmd.disable_help_subcommand(true);
    cmd.build();
    match args.out {
        None => say_raw!("{}", render(&cmd)?)?,
        Some(dir) => {
            std::fs::create_dir_all(&dir)
                .with_context(|| format!("cannot create {}", dir.display()))?;
            write_pages(&cmd, &dir)?;
        }
    }
    Ok(Outcome::Pass)
}

/// Writes the page of `cmd` and of each of its subcommands into `dir`, printing each path.
fn write_pages(cmd: &clap::Command, dir: &Path) -> Result<()> {
    let man = clap_mangen::Man::new(cmd.clone());
    let path = dir.join(man.get_filename());
    std::fs::write(&path, render(cmd)?)
        .with_context(|| format!("cannot write {}", path.display()))?;
    say!("{}", path.display())?;
    for sub in cmd.get_subcommands().filter(|s| !s.is_hide_set()) {
        write_pages(sub, dir)?;
    }
    Ok(())
}

/// The roff text of the page of `cmd`.
fn render(cmd: &clap::Command) -> Result<String> {
    let mut page = Vec::new();
    clap_mangen::Man::new(cmd.clone())
        .render(&mut page)
        .context("cannot render the man page")?;
    Ok(String::from_utf8_lossy(&page).into_owned())
}
