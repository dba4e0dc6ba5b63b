//! `drivespec`: the command-line front end. Parsing and printing only; the work is in the libraries.

/// `println!` that returns the write error instead of panicking ([`StdoutClosed`]).
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        writeln!(std::io::stdout().lock(), $($arg)*).map_err($crate::StdoutClosed)
    }};
}

/// `print!` that returns the write error instead of panicking ([`StdoutClosed`]).
macro_rules! say_raw {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let mut out = std::io::stdout().lock();
        write!(out, $($arg)*)
            .and_then(|()| out.flush())
            .map_err($crate::StdoutClosed)
    }};
}

mod check_cmd;
mod completions_cmd;
mod conform_cmd;
mod fuzz_cmd;
mod fuzz_profinet;
mod hpd_cmd;
mod input;
mod interrupt;
mod man_cmd;
mod pd_cmd;
mod sim_cmd;
mod sim_profinet;
mod simrun_cmd;
mod spec_build;
mod spec_cmd;

use anyhow::{anyhow, bail, Result};
use clap::{CommandFactory, Parser, Subcommand};
use drivespec_spec::Spec;
use std::path::PathBuf;
use std::process::ExitCode;

/// Conformance test suite and protocol fuzzer for PSD4xx, PSx3xx and HPD drives.
#[derive(Parser)]
#[command(name = "drivespec", version = env!("DRIVESPEC_VERSION"))]
struct Cli {
    /// Load the spec from this folder instead of the built-in one.
    #[arg(long, global = true, value_name = "DIR")]
    spec: Option<PathBuf>,
    /// Output format.
    #[arg(long, global = true, value_enum, default_value_t = Format::Text)]
    format: Format,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Browse and check the machine-readable spec.
    Spec(spec_cmd::SpecArgs),
    /// Decode bytes or a line capture, field by field.
    Decode {
        #[command(subcommand)]
        device: DecodeDevice,
    },
    /// Build a message from named fields and print its bytes.
    Encode {
        #[command(subcommand)]
        device: EncodeDevice,
    },
    /// Run the conformance suite against a device under test (exit 1 on failures).
    Conform(conform_cmd::ConformArgs),
    /// Fuzz a device under test with spec-generated sequences (exit 1 on findings).
    Fuzz(fuzz_cmd::FuzzArgs),
    /// Serve a reference model on TCP, a pseudo-terminal or stdin/stdout, with optional faults.
    Sim(sim_cmd::SimArgs),
    /// Play a script of timed commands on a reference model and print the trace.
    SimRun(simrun_cmd::SimRunArgs),
    /// Check recorded traffic (pcap/pcapng, serial dumps, IO-Link logs) against the spec.
    Check(check_cmd::CheckArgs),
    /// Assemble and disassemble PLC programs.
    Plc {
        #[command(subcommand)]
        device: PlcDevice,
    },
    /// Print the shell completion script (bash, zsh, fish, elvish, powershell).
    Completions(completions_cmd::CompletionsArgs),
    /// Print the man page, or write every page to a folder with --out.
    Man(man_cmd::ManArgs),
}

#[derive(Subcommand)]
enum DecodeDevice {
    /// HPD serial messages (manual 4.1).
    Hpd(hpd_cmd::DecodeArgs),
    /// PSD4xx PROFINET process images with the PKW channel (bus description 3.5, 3.8).
    Psd4xx(pd_cmd::Psd4xxDecode),
    /// PSx3xx IO-Link process images (instruction manual 3.3).
    Psx3xx(pd_cmd::Psx3xxDecode),
}

#[derive(Subcommand)]
enum EncodeDevice {
    /// HPD serial messages (manual 4.1).
    Hpd(hpd_cmd::EncodeArgs),
    /// PSD4xx PROFINET process images (bus description 3.5, 3.8).
    Psd4xx(pd_cmd::Psd4xxEncode),
    /// PSx3xx IO-Link process images (instruction manual 3.3).
    Psx3xx(pd_cmd::Psx3xxEncode),
}

#[derive(Subcommand)]
enum PlcDevice {
    /// The HPD pico-PLC (manual 3.8.1, 4.1).
    Hpd(hpd_cmd::PlcArgs),
}

/// Output format of a command.
#[derive(Clone, Copy, clap::ValueEnum)]
pub enum Format {
    /// Text for people.
    Text,
    /// JSON, stable and documented in the README.
    Json,
}

/// What a command found: exit 0 = pass, 1 = violations or failures found, 124/130/143 =
/// stopped by the time limit, SIGINT or SIGTERM.
pub enum Outcome {
    /// Nothing wrong.
    Pass,
    /// Violations or failures found.
    Fail,
    /// Stopped by a signal or the time limit, with the exit code that says which.
    Stopped(u8),
}

/// What every command gets: where the spec comes from and how to print.
pub struct Context {
    /// `--spec DIR`.
    pub spec_dir: Option<PathBuf>,
    /// `--format`.
    pub format: Format,
}

impl Context {
    /// Loads the spec; an invalid spec is unreadable input.
    pub fn spec(&self) -> Result<Spec> {
        let loaded = match &self.spec_dir {
            Some(dir) if !dir.is_dir() => {
                bail!("cannot read spec folder {}: not a directory", dir.display())
            }
            Some(dir) => Spec::load_dir(dir),
            None => Spec::builtin(),
        };
        loaded.map_err(|e| {
            let first = e.0.first().map(ToString::to_string).unwrap_or_default();
            anyhow!(
                "the spec is invalid ({} problems; run `drivespec spec check`): {first}",
                e.0.len()
            )
        })
    }
}

pub use drivespec_report::json;

/// Whether to colour what goes to `stream`: a terminal, and `NO_COLOR` unset or empty.
pub fn colour(stream: &impl std::io::IsTerminal) -> bool {
    stream.is_terminal() && std::env::var_os("NO_COLOR").is_none_or(|v| v.is_empty())
}

/// Standard output could not be written: a reader that went away (a broken pipe ends the
/// command quietly with exit 0) or a write error (exit 2).
#[derive(Debug, thiserror::Error)]
#[error("cannot write to standard output: {0}")]
pub struct StdoutClosed(std::io::Error);

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
    let ctx = Context {
        spec_dir: cli.spec,
        format: cli.format,
    };
    let result = match cli.command {
        Command::Spec(args) => spec_cmd::run(args, &ctx),
        Command::Conform(args) => conform_cmd::run(args, &ctx),
        Command::Fuzz(args) => fuzz_cmd::run(args, &ctx),
        Command::Check(args) => check_cmd::run(args, &ctx),
        Command::Sim(args) => sim_cmd::run(args, &ctx),
        Command::SimRun(args) => simrun_cmd::run(args, &ctx),
        Command::Decode { device } => match device {
            DecodeDevice::Hpd(args) => hpd_cmd::decode(args, &ctx),
            DecodeDevice::Psd4xx(args) => pd_cmd::decode_psd4xx(args, &ctx),
            DecodeDevice::Psx3xx(args) => pd_cmd::decode_psx3xx(args, &ctx),
        },
        Command::Encode { device } => match device {
            EncodeDevice::Hpd(args) => hpd_cmd::encode(args, &ctx),
            EncodeDevice::Psd4xx(args) => pd_cmd::encode_psd4xx(args, &ctx),
            EncodeDevice::Psx3xx(args) => pd_cmd::encode_psx3xx(args, &ctx),
        },
        Command::Plc {
            device: PlcDevice::Hpd(args),
        } => hpd_cmd::plc(args, &ctx),
        Command::Completions(args) => completions_cmd::run(args, Cli::command()),
        Command::Man(args) => man_cmd::run(args, Cli::command()),
    };
    match result {
        Ok(Outcome::Pass) => ExitCode::SUCCESS,
        Ok(Outcome::Fail) => ExitCode::from(1),
        Ok(Outcome::Stopped(code)) => ExitCode::from(code),
        Err(e) => match e.downcast_ref::<StdoutClosed>() {
            Some(StdoutClosed(io)) if io.kind() == std::io::ErrorKind::BrokenPipe => {
                ExitCode::SUCCESS
            }
            _ => {
                eprintln!("drivespec: {e:#}");
                ExitCode::from(2)
            }
        },
    }
}
