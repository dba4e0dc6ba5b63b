//! `drivespec check`: recorded traffic against the spec. Parsing, progress and
//! printing only; the work is in `drivespec_check`.

use crate::interrupt::Interrupt;
use crate::{Context, Format, Outcome};
use anyhow::{anyhow, bail, Context as _, Result};
use drivespec_check::profinet::Manual;
use drivespec_check::run::{check_path, Device, InputFormat, Progress, RunOptions};
use drivespec_check::{render, Policy, Report};
use drivespec_spec::hex::parse_int;
use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};

/// Arguments of `drivespec check`.
#[derive(clap::Args)]
pub struct CheckArgs {
    /// Recordings to check: pcap/pcapng (PROFINET or serial link types), raw serial bytes,
    /// socat dumps, serial text, IO-Link JSON lines or CSV; gzip-compressed or not.
    #[arg(required = true, value_name = "FILE")]
    files: Vec<PathBuf>,
    /// Device family (detected from the recording when not given).
    #[arg(long, value_enum)]
    device: Option<DeviceArg>,
    /// Device model for per-model ranges (`PSD426`, `PSE335-14`).
    #[arg(long)]
    model: Option<String>,
    /// Recording format (detected when `auto`).
    #[arg(long, value_enum, default_value_t = FormatArg::Auto)]
    input_format: FormatArg,
    /// HPD line speed: a Pr26 code (0-10) or bits per second; enables the time-out checks.
    #[arg(long)]
    baud: Option<u32>,
    /// PSD4xx FrameID: `OUT[,IN]` (one value for both directions), decimal or 0x hex.
    #[arg(long, value_name = "ID[,ID]", requires = "offset")]
    frame_id: Option<String>,
    /// PSD4xx module offset in the C_SDU: `OUT[,IN]`.
    #[arg(long, value_name = "N[,N]", requires = "frame_id")]
    offset: Option<String>,
    /// Module or submodule ident number of the PSD4xx in the Connect.
    #[arg(long, value_name = "IDENT")]
    module_ident: Option<String>,
    /// Do not search cyclic frames for PSD4xx process data without a Connect.
    #[arg(long)]
    no_search: bool,
    /// List at most N violations per file, and at most 100 of one requirement (all are
    /// counted).
    #[arg(long, value_name = "N", default_value_t = drivespec_check::DEFAULT_MAX_VIOLATIONS)]
    max_violations: u64,
    /// Warnings (`should` findings) fail the run too.
    #[arg(long)]
    strict: bool,
    /// Fail a file in which the checks of this family did not run (no drive found); the
    /// family given with `--device` is required as well.
    #[arg(long, value_enum, value_name = "FAMILY")]
    require: Vec<DeviceArg>,
    /// Report format on stdout (the global `--format json` selects json too).
    #[arg(long, value_enum)]
    report: Option<ReportArg>,
    /// Also write check.txt, check.json, check.xml (JUnit) and check.html into DIR.
    #[arg(long, value_name = "DIR")]
    report_dir: Option<PathBuf>,
}

/// `--device`.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum DeviceArg {
    /// Parker HPD, serial line.
    Hpd,
    /// PSD4xx, PROFINET.
    Psd4xx,
    /// PSx3xx, IO-Link.
    Psx3xx,
}

/// `--input-format`.
#[derive(Clone, Copy, clap::ValueEnum)]
pub enum FormatArg {
    /// Detect from the first bytes.
    Auto,
    /// Classic pcap.
    Pcap,
    /// pcapng.
    Pcapng,
    /// Raw serial bytes.
    Raw,
    /// socat -v -x dump.
    Socat,
    /// Serial text format (TIME DIR HEX).
    Text,
    /// IO-Link JSON lines.
    Jsonl,
    /// IO-Link CSV.
    Csv,
}

/// `--report`.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ReportArg {
    /// Text summary.
    Text,
    /// JSON, schema drivespec-check/1.
    Json,
    /// JUnit XML, one test case per requirement checked.
    Junit,
    /// HTML with timeline plots.
    Html,
}

fn number(text: &str) -> Result<u64> {
    let t = text.trim();
    parse_int(t).map_err(|_| anyhow!("{t:?} is not a number (decimal or 0x hex)"))
}

fn pair(text: &str, what: &str) -> Result<(u64, u64)> {
    let mut parts = text.split(',');
    let a = number(parts.next().unwrap_or("")).with_context(|| what.to_string())?;
    let b = match parts.next() {
        Some(p) => number(p).with_context(|| what.to_string())?,
        None => a,
    };
    if parts.next().is_some() {
        bail!("{what}: at most two values, OUT,IN");
    }
    Ok((a, b))
}

fn device(d: DeviceArg) -> Device {
    match d {
        DeviceArg::Hpd => Device::Hpd,
        DeviceArg::Psd4xx => Device::Psd4xx,
        DeviceArg::Psx3xx => Device::Psx3xx,
    }
}

fn options(args: &CheckArgs) -> Result<RunOptions> {
    let mut require: Vec<String> = args
        .require
        .iter()
        .chain(args.device.iter())
        .map(|d| device(*d).as_str().to_owned())
        .collect();
    require.sort();
    require.dedup();
    let mut o = RunOptions {
        device: args.device.map(device),
        policy: Policy {
            strict: args.strict,
            require,
        },
        format: match args.input_format {
            FormatArg::Auto => InputFormat::Auto,
            FormatArg::Pcap => InputFormat::Pcap,
            FormatArg::Pcapng => InputFormat::Pcapng,
            FormatArg::Raw => InputFormat::Raw,
            FormatArg::Socat => InputFormat::Socat,
            FormatArg::Text => InputFormat::Text,
            FormatArg::Jsonl => InputFormat::Jsonl,
            FormatArg::Csv => InputFormat::Csv,
        },
        ..RunOptions::default()
    };
    o.hpd.baud = args.baud;
    o.hpd.max_violations = Some(args.max_violations);
    o.pn.max_violations = Some(args.max_violations);
    o.psx.max_violations = Some(args.max_violations);
    o.pn.psd.model = args.model.clone();
    o.psx.model = args.model.clone();
    o.pn.search = !args.no_search;
    if let (Some(f), Some(off)) = (&args.frame_id, &args.offset) {
        let (of, inf) = pair(f, "--frame-id")?;
        let (oo, io) = pair(off, "--offset")?;
        let id = |v: u64| {
            u16::try_from(v).map_err(|_| anyhow!("--frame-id {v} is not a 16-bit FrameID"))
        };
        let at = |v: u64| usize::try_from(v).map_err(|_| anyhow!("--offset {v} is too large"));
        o.pn.manual = Some(Manual {
            out_frame: id(of)?,
            in_frame: id(inf)?,
            out_offset: at(oo)?,
            in_offset: at(io)?,
        });
    }
    if let Some(m) = &args.module_ident {
        let v = number(m).context("--module-ident")?;
        o.pn.module_ident =
            Some(u32::try_from(v).map_err(|_| anyhow!("--module-ident {v} is not 32-bit"))?);
    }
    Ok(o)
}

/// Progress on stderr for large files: a bar on a terminal, plain lines when CI=true.
struct Bar {
    ci: bool,
    tty: bool,
    name: String,
    last: u64,
}

impl Bar {
    fn show(&mut self, p: Progress) {
        let Some(total) = p.total.filter(|t| *t >= 8 << 20) else {
            return;
        };
        let pct = p.bytes.saturating_mul(100) / total.max(1);
        if self.ci {
            if pct >= self.last + 10 || (pct == 100 && self.last < 100) {
                self.last = pct - pct % 10;
                eprintln!(
                    "{}: {pct}% ({} MB of {} MB)",
                    self.name,
                    p.bytes >> 20,
                    total >> 20
                );
            }
        } else if self.tty && pct != self.last {
            self.last = pct;
            let filled = usize::try_from(pct / 4).unwrap_or(25).min(25);
            eprint!(
                "\r{} [{}{}] {pct:>3}%",
                self.name,
                "#".repeat(filled),
                " ".repeat(25 - filled)
            );
            if pct >= 100 {
                eprintln!();
            }
            let _ = std::io::stderr().flush();
        }
    }
}

fn write_reports(dir: &Path, reports: &[Report]) -> Result<()> {
    let files: Vec<(std::path::PathBuf, String)> = [
        ("check.txt", render::text(reports)),
        ("check.json", render::json(reports)),
        ("check.xml", render::junit(reports)),
        ("check.html", render::html(reports)),
    ]
    .into_iter()
    .map(|(name, text)| (dir.join(name), text))
    .collect();
    drivespec_report::write_set(&files)?;
    Ok(())
}

/// Runs `drivespec check`.
pub fn run(args: CheckArgs, ctx: &Context) -> Result<Outcome> {
    let spec = ctx.spec()?;
    let interrupt = Interrupt::install(None)?;
    let mut options = options(&args)?;
    options.stop = interrupt.flag();
    let format = args.report.unwrap_or(match ctx.format {
        Format::Json => ReportArg::Json,
        _ => ReportArg::Text,
    });
    let ci = std::env::var("CI").is_ok_and(|v| v == "true");
    let tty = std::io::stderr().is_terminal();
    let mut reports = Vec::new();
    let mut errors = Vec::new();
    for file in &args.files {
        if interrupt.stopped() {
            break;
        }
        let mut bar = Bar {
            ci,
            tty,
            name: file.display().to_string(),
            last: 0,
        };
        match check_path(&spec, file, &options, &mut |p| bar.show(p)) {
            Ok(r) => {
                if let Some(e) = &r.error {
                    errors.push(format!("{}: {}", file.display(), e.message));
                }
                reports.push(r);
            }
            Err(e) => errors.push(e.to_string()),
        }
    }
    let out = match format {
        ReportArg::Text => render::text(&reports),
        ReportArg::Json => render::json(&reports),
        ReportArg::Junit => render::junit(&reports),
        ReportArg::Html => render::html(&reports),
    };
    say_raw!("{out}")?;
    if let Some(dir) = &args.report_dir {
        write_reports(dir, &reports)?;
    }
    if let (Some(code), Some(cause)) = (interrupt.exit_code(), interrupt.cause()) {
        eprintln!("drivespec: interrupted by {cause}: the report covers what was read");
        return Ok(Outcome::Stopped(code));
    }
    if !errors.is_empty() {
        bail!("{}", errors.join("\ndrivespec: "));
    }
    Ok(if reports.iter().all(Report::passed) {
        Outcome::Pass
    } else {
        Outcome::Fail
    })
}
