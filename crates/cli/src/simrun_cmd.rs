//! `drivespec sim-run`: plays a script of timed commands and environment changes on a
//! family's reference model and prints the trace (the library does the work:
//! `drivespec_psd4xx::script`, `drivespec_psx3xx::script`, grammar in `drivespec_positioner::script`).

use crate::{input, json, Context, Format, Outcome};
use anyhow::{bail, Context as _, Result};
use drivespec_positioner::script::{RunOptions, Trace};
use drivespec_psd4xx::model::DriveConfig;
use drivespec_psd4xx::script as psd_script;
use drivespec_spec::{FamilyId, Readings};
use std::path::PathBuf;

/// Run a script on a reference model and print what a conforming drive would do.
#[derive(clap::Args)]
pub struct SimRunArgs {
    /// Device family: psd4xx or psx3xx.
    device: String,
    /// Device model, matched forgivingly.
    #[arg(long)]
    model: String,
    /// The script (format in the README, "Simulated runs"); `-` reads stdin.
    #[arg(long, value_name = "FILE")]
    script: PathBuf,
    /// A trace line every MS ms besides the changes (0: changes only).
    #[arg(long, value_name = "MS", default_value_t = 100)]
    every: u64,
    /// Bus cycle in µs: one output image per cycle.
    #[arg(long, value_name = "US", default_value_t = 1000)]
    cycle_us: u64,
    /// Another reading of a selectable erratum (`drivespec spec errata`), e.g.
    /// `psx-ref-sign=physical-minus-written`; repeatable.
    #[arg(long, value_name = "OPTION=READING")]
    reading: Vec<String>,
}

/// Runs `drivespec sim-run`; exit 1 when an `expect` line fails.
pub fn run(args: SimRunArgs, ctx: &Context) -> Result<Outcome> {
    let text = input::read_text(&args.script, input::MAX_TEXT)?;
    if args.cycle_us == 0 {
        bail!("--cycle-us 0: the bus cycle is at least 1 µs");
    }
    let spec = ctx.spec()?;
    let family = FamilyId::parse(&args.device);
    let mut readings = Readings::default();
    if let Some(f) = family {
        for choice in &args.reading {
            let (option, reading) = choice
                .split_once('=')
                .with_context(|| format!("--reading {choice:?}: expected OPTION=READING"))?;
            readings
                .choose(spec.family(f), option.trim(), reading.trim())
                .with_context(|| format!("--reading {choice:?}"))?;
        }
    }
    let opts = RunOptions {
        every_ms: args.every,
        cycle_us: args.cycle_us,
        ..RunOptions::default()
    };
    let trace = match family {
        Some(FamilyId::Psd4xx) => {
            let config = DriveConfig::new(&args.model).with_readings(readings);
            psd_script::run_text(&spec, config, &text, &opts)
                .with_context(|| format!("script {}", args.script.display()))?
        }
        Some(FamilyId::Psx3xx) => {
            let config =
                drivespec_psx3xx::model::DriveConfig::new(&args.model).with_readings(readings);
            let trace = drivespec_psx3xx::script::run_text(&spec, config, &text, &opts)
                .with_context(|| format!("script {}", args.script.display()))?;
            return print(ctx, &trace);
        }
        _ => bail!(
            "sim-run {:?}: not available; families with a script runner: psd4xx, psx3xx",
            args.device
        ),
    };
    print(ctx, &trace)
}

/// Prints a trace; fails when an expectation failed.
fn print<E: std::fmt::Display + serde::Serialize>(
    ctx: &Context,
    trace: &Trace<E>,
) -> Result<Outcome> {
    match ctx.format {
        Format::Text => say_raw!("{}", trace.to_text())?,
        Format::Json => say!("{}", json(trace))?,
    }
    Ok(if trace.failed == 0 {
        Outcome::Pass
    } else {
        Outcome::Fail
    })
}
