//! `drivespec spec …`: list, show and check the spec.

use crate::Outcome;
use anyhow::Result;
use clap::{Args, Subcommand};
use drivespec_spec::Spec;
use std::path::PathBuf;

/// Arguments of `drivespec spec`.
#[derive(Args)]
pub struct SpecArgs {
    /// Load the spec from this folder instead of the built-in one.
    #[arg(long, global = true, value_name = "DIR")]
    spec: Option<PathBuf>,
    #[command(subcommand)]
    command: SpecCommand,
}

#[derive(Subcommand)]
enum SpecCommand {
    /// Validate the spec; one line per problem.
    Check,
}

pub fn run(args: SpecArgs) -> Result<Outcome> {
    match args.command {
        SpecCommand::Check => {
            let loaded = match &args.spec {
                Some(dir) => Spec::load_dir(dir),
                None => Spec::builtin(),
            };
            match loaded {
                Ok(_) => {
                    println!("spec ok");
                    Ok(Outcome::Pass)
                }
                Err(errors) => {
                    for p in &errors.0 {
                        println!("{p}");
                    }
                    Ok(Outcome::Fail)
                }
            }
        }
    }
}
