//! `drivespec`: the command-line front end. Parsing and printing only; the work is in the libraries.

mod spec_cmd;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Conformance test suite and protocol fuzzer for PSD4xx, PSx3xx and HPD drives.
#[derive(Parser)]
#[command(name = "drivespec", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Browse and check the machine-readable spec.
    Spec(spec_cmd::SpecArgs),
}

/// Output format of a command.
#[derive(Clone, Copy, clap::ValueEnum)]
pub enum Format {
    /// Text for people.
    Text,
    /// JSON, stable and documented in the README.
    Json,
}

/// What a command found: exit 0 = pass, 1 = violations or failures found.
pub enum Outcome {
    /// Nothing wrong.
    Pass,
    /// Violations or failures found.
    Fail,
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            let _ = e.print();
            return match e.kind() {
                clap::error::ErrorKind::DisplayHelp | clap::error::ErrorKind::DisplayVersion => {
                    ExitCode::SUCCESS
                }
                _ => ExitCode::from(2),
            };
        }
    };
    let result = match cli.command {
        Command::Spec(args) => spec_cmd::run(args),
    };
    match result {
        Ok(Outcome::Pass) => ExitCode::SUCCESS,
        Ok(Outcome::Fail) => ExitCode::from(1),
        Err(e) => {
            eprintln!("drivespec: {e:#}");
            ExitCode::from(2)
        }
    }
}
