//! `drivespec fuzz`: argument parsing and printing around `drivespec_fuzz`
//! (crates/fuzz/README.md).

use crate::interrupt::{parse_duration, Interrupt};
use crate::{json, Context, Format, Outcome};
use anyhow::{bail, Context as _, Result};
use drivespec_conform::dut::Dut;
use drivespec_conform::select::{closest, did_you_mean};
use drivespec_conform::suite::Settings;
use drivespec_conform::Progress;
use drivespec_fuzz::{self as fuzz, Device, Layer, Options, Replay, ReplayOutcome};
use drivespec_spec::FamilyId;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Schema of `drivespec fuzz --format json` on stdout (crates/conform/README.md).
const SUMMARY_SCHEMA: &str = "drivespec-fuzz-summary/1";

/// Fuzz a device under test with sequences generated from the spec (exit 1 on findings).
#[derive(clap::Args)]
pub struct FuzzArgs {
    /// Family: hpd, psd4xx or psx3xx.
    family: String,
    /// Device under test: sim[:MODEL], serial:PATH?baud=N, tcp:HOST:PORT, exec:'COMMAND ARGS',
    /// profinet:IFACE/NAME (with --layer profinet).
    #[arg(long, default_value = "sim")]
    dut: String,
    /// Layer the inputs act at: application (the family's own messages) or profinet (DCP,
    /// Connect, records and RT frames to a PSD4xx IO device, each sequence followed by a
    /// liveness probe). A replay file's own layer is the default for --replay and --minimize.
    #[arg(long, value_name = "LAYER", value_parser = ["application", "profinet"])]
    layer: Option<String>,
    /// Device model.
    #[arg(long)]
    model: Option<String>,
    /// Seed of the generator: the same seed sends the same sequences.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Sequences to run (default 1000 when --duration is not given).
    #[arg(long, value_name = "N", conflicts_with = "duration")]
    iterations: Option<u64>,
    /// Wall-clock budget: 90s, 10m, 2h (a plain number is seconds).
    #[arg(long, value_name = "TIME", value_parser = parse_duration)]
    duration: Option<Duration>,
    /// Stop the whole run (fuzzing and minimising) after this long, write the reports of what
    /// ran and exit 124: 90s, 10m, 2h.
    #[arg(long, value_name = "TIME", value_parser = parse_duration)]
    timeout: Option<Duration>,
    /// Folder of the reports and replay files.
    #[arg(long, default_value = "reports/fuzz", value_name = "DIR")]
    out: PathBuf,
    /// Reproduce a replay file against the device (exit 1 if it still fails).
    #[arg(long, value_name = "FILE", conflicts_with_all = ["minimize", "iterations", "duration"])]
    replay: Option<PathBuf>,
    /// Minimise a replay file against the device; writes DIR/<name>.min.json.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["iterations", "duration"])]
    minimize: Option<PathBuf>,
    /// Serial address of the device (HPD Pr27).
    #[arg(long, default_value_t = 0)]
    address: u8,
    /// Extra time allowed for each answer on real transports, in ms.
    #[arg(long, value_name = "MS")]
    slack_ms: Option<u64>,
    /// Distinct findings to minimise and keep (later ones are only counted).
    #[arg(long, default_value_t = 20, value_name = "N")]
    max_findings: usize,
    /// Runs one minimisation may take.
    #[arg(long, default_value_t = 400, value_name = "N")]
    minimize_runs: u64,
    /// No progress output.
    #[arg(long)]
    quiet: bool,
}

/// Runs `drivespec fuzz`.
pub fn run(args: FuzzArgs, ctx: &Context) -> Result<Outcome> {
    let Some(family) = FamilyId::parse(&args.family) else {
        bail!(
            "unknown family {:?} (hpd, psd4xx or psx3xx){}",
            args.family,
            did_you_mean(&closest(&args.family, ["hpd", "psd4xx", "psx3xx"]))
        )
    };
    let dut: Dut = args.dut.parse()?;
    let file = args.replay.as_ref().or(args.minimize.as_ref());
    let replay = file.map(|f| Replay::load(f)).transpose()?;
    let layer = match (args.layer.as_deref(), &replay) {
        (Some("profinet"), _) => Layer::Profinet,
        (Some(_), _) => Layer::Application,
        (None, Some(r)) => r.layer,
        (None, None) => Layer::Application,
    };
    let interrupt = Interrupt::install(args.timeout)?;
    let opts = Options {
        family,
        layer,
        dut,
        settings: Settings {
            address: args.address,
            seed: args.seed,
            model: args.model,
            slack_us: args.slack_ms.map(|ms| ms.saturating_mul(1000)),
            bit_rate: None,
            brake: None,
            readings: Vec::new(),
        },
        iterations: args.iterations,
        duration: args.duration,
        out_dir: args.out.clone(),
        no_reports: false,
        progress: if args.quiet {
            Progress::Quiet
        } else {
            Progress::Auto
        },
        max_findings: args.max_findings,
        minimize_runs: args.minimize_runs,
        command: "drivespec fuzz".to_owned(),
        stop: interrupt.flag(),
    };
    let spec = ctx.spec()?;
    // The socket loop of a PROFINET device under test is this side's.
    let wire = || -> Result<Option<Device>> {
        match (&opts.layer, &opts.dut) {
            (Layer::Profinet, Dut::Profinet { iface, name }) => Ok(Some(Device::Profinet(
                Box::new(crate::fuzz_profinet::RawWire::open(iface, name)?),
            ))),
            _ => Ok(None),
        }
    };
    if let (Some(file), Some(r)) = (&args.replay, &replay) {
        let out = match wire()? {
            Some(d) => fuzz::replay_on_device(&spec, &opts, r, d)?,
            None => fuzz::replay(&spec, &opts, r)?,
        };
        print_replay(ctx, file, &out)?;
        return Ok(if out.exit_code() == 0 {
            Outcome::Pass
        } else {
            Outcome::Fail
        });
    }
    if let (Some(file), Some(r)) = (&args.minimize, &replay) {
        return minimize(ctx, &opts, &spec, file, r, wire()?);
    }
    let mut err = std::io::stderr();
    let summary = match wire()? {
        Some(d) => fuzz::run_on_device(&spec, &opts, d, &mut err)?,
        None => fuzz::run(&spec, &opts, &mut err)?,
    };
    let s = &summary.stats;
    match ctx.format {
        Format::Json => say!(
            "{}",
            json(&serde_json::json!({
                "schema": SUMMARY_SCHEMA,
                "summary": summary.report.summary,
                "sequences": s.sequences,
                "inputs": s.inputs,
                "findings": s.findings,
                "reports": summary.written,
            }))
        )?,
        Format::Text => {
            say!(
                "{} sequence(s), {} input(s), {} finding(s) against {} (seed {}, stopped by {})",
                s.sequences,
                s.inputs,
                s.findings.len(),
                summary.report.run.transport,
                s.seed,
                s.stopped_by
            )?;
            for f in &s.findings {
                say!(
                    "{}: {} in {} step(s), seen {} time(s){}",
                    f.id,
                    f.signature,
                    f.steps,
                    f.occurrences,
                    f.file
                        .as_ref()
                        .map(|p| format!("; replay: {p}"))
                        .unwrap_or_default()
                )?;
            }
            for w in &summary.written {
                say!("report: {}", w.display())?;
            }
            if let Some(cause) = interrupt.cause() {
                say!("interrupted by {cause}: the reports cover the sequences run")?;
            }
        }
    }
    if let Some(code) = interrupt.exit_code() {
        return Ok(Outcome::Stopped(code));
    }
    Ok(if summary.exit_code() == 0 {
        Outcome::Pass
    } else {
        Outcome::Fail
    })
}

fn minimize(
    ctx: &Context,
    opts: &Options,
    spec: &drivespec_spec::Spec,
    file: &Path,
    r: &Replay,
    device: Option<Device>,
) -> Result<Outcome> {
    let min = match device {
        Some(d) => fuzz::minimize_on_device(spec, opts, r, d)?,
        None => fuzz::minimize(spec, opts, r)?,
    };
    let Some(min) = min else {
        match ctx.format {
            Format::Json => say!("{}", json(&serde_json::json!({ "fails": false })))?,
            Format::Text => say!(
                "{}: passes against {}: nothing to minimise",
                file.display(),
                opts.dut
            )?,
        }
        return Ok(Outcome::Pass);
    };
    let stem = file
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "replay".to_owned());
    let path = opts.out_dir.join(format!("{stem}.min.json"));
    min.save(&path)
        .with_context(|| format!("writing the minimised replay {}", path.display()))?;
    let sig = min
        .finding
        .as_ref()
        .map(|f| f.signature.clone())
        .unwrap_or_default();
    match ctx.format {
        Format::Json => say!(
            "{}",
            json(&serde_json::json!({
                "fails": true,
                "signature": sig,
                "steps": min.steps.len(),
                "from": r.steps.len(),
                "file": path,
            }))
        )?,
        Format::Text => say!(
            "{sig}: {} step(s) (from {}) written to {}",
            min.steps.len(),
            r.steps.len(),
            path.display()
        )?,
    }
    Ok(Outcome::Fail)
}

fn print_replay(ctx: &Context, file: &Path, out: &ReplayOutcome) -> Result<()> {
    let verdict = match &out.fault {
        Some((class, sig, step)) => format!("fails at step {step}: {sig} ({})", class.as_str()),
        None => "passes".to_owned(),
    };
    match ctx.format {
        Format::Json => say!(
            "{}",
            json(&serde_json::json!({
                "file": file,
                "fails": out.fault.is_some(),
                "signature": out.fault.as_ref().map(|f| f.1.clone()),
                "same_as_recorded": out.same_as_recorded,
                "same_finding": out.same_finding,
                "exchanges": out.exchanges,
            }))
        )?,
        Format::Text => {
            let hex = |h: &Option<String>| match h.as_deref() {
                Some("") => "silence".to_owned(),
                Some(h) => h.to_owned(),
                None => "-".to_owned(),
            };
            for e in &out.exchanges {
                let mark = match e.ok {
                    Some(true) => "ok ",
                    Some(false) => "BAD",
                    None => "   ",
                };
                say!(
                    "{mark} #{:<3} +{:>8} µs  sent {}",
                    e.step,
                    e.at_us,
                    e.sent.as_deref().unwrap_or("-")
                )?;
                if e.expected.is_some() || e.got.is_some() {
                    say!(
                        "               reference {}\n               device    {}",
                        hex(&e.expected),
                        hex(&e.got)
                    )?;
                }
                if let Some(n) = &e.note {
                    say!("               note      {n}")?;
                }
            }
            say!("{}: {verdict}", file.display())?;
            say!(
                "{}",
                if out.same_as_recorded {
                    "the exchange is byte for byte the recorded one"
                } else {
                    "the exchange differs from the recorded one"
                }
            )?;
        }
    }
    Ok(())
}
