//! `drivespec check`: recorded traffic against the spec. Parsing, the list of files, running
//! them on a thread pool, progress and printing; the work is in `drivespec_check`.
//!
//! Files are checked in parallel and reported in path order whatever the timing: results
//! are printed (text, NDJSON) as soon as every file before them is done, and a file starts
//! only while fewer than [`WINDOW_PER_JOB`] × jobs files wait to be printed, so memory does
//! not grow with the number of files.

use crate::interrupt::Interrupt;
use crate::{Context, Format, Outcome};
use anyhow::{anyhow, bail, Context as _, Result};
use drivespec_check::profinet::Manual;
use drivespec_check::run::{
    check_frames, check_path, Device, InputFormat, LiveFrame, Progress, RunOptions,
};
use drivespec_check::{ndjson, render, Policy, Report};
use drivespec_spec::hex::parse_int;
use drivespec_spec::Spec;
use rayon::iter::{ParallelBridge, ParallelIterator};
use std::collections::BTreeMap;
use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Condvar, Mutex};
use std::time::{Duration, Instant, UNIX_EPOCH};

/// Longest wait for a frame before the stop flag and the `--duration` end are looked at
/// again. A choice: Ctrl-C is noticed within it, and an idle interface costs 10 wake-ups a
/// second.
const LIVE_POLL: Duration = Duration::from_millis(100);

/// Files finished but not yet printed, at most, per job.
const WINDOW_PER_JOB: usize = 4;

/// File name endings of recordings taken from a folder (after an optional `.gz`).
const RECORDING_EXTENSIONS: [&str; 10] = [
    "pcap", "pcapng", "cap", "raw", "bin", "socat", "txt", "log", "jsonl", "csv",
];

/// Arguments of `drivespec check`.
#[derive(clap::Args)]
pub struct CheckArgs {
    /// Recordings to check: pcap/pcapng (PROFINET or serial link types), raw serial bytes,
    /// socat dumps, serial text, IO-Link JSON lines or CSV; gzip-compressed or not. A folder
    /// stands for the recordings in it and its subfolders (.pcap, .pcapng, .cap, .raw, .bin,
    /// .socat, .txt, .log, .jsonl, .csv, each also with .gz); files are reported sorted by
    /// path.
    #[arg(required_unless_present = "live", value_name = "FILE|DIR")]
    files: Vec<PathBuf>,
    /// Check the frames of this network interface as they arrive (a mirror port) instead of
    /// recordings: PSD4xx checks, the same reports. Needs root or the capabilities
    /// cap_net_raw,cap_net_admin+ep; Ctrl-C ends the check and reports what was received.
    #[arg(long, value_name = "IFACE", conflicts_with_all = ["files", "jobs", "input_format"])]
    live: Option<String>,
    /// With --live: end the check after this long (`90s`, `10m`, `500ms`).
    #[arg(long, value_name = "D", requires = "live", conflicts_with = "files", value_parser = crate::interrupt::parse_duration)]
    duration: Option<Duration>,
    /// Files checked at the same time (default: the number of cores).
    #[arg(short = 'j', long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..))]
    jobs: Option<u16>,
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
    /// One JSON object per finding and line, schema drivespec-check-finding/1, and a summary
    /// line.
    Ndjson,
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

/// Whether a file found in a folder is a recording, by its name.
fn is_recording(path: &Path) -> bool {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let name = name.strip_suffix(".gz").unwrap_or(&name);
    name.rsplit_once('.')
        .is_some_and(|(_, ext)| RECORDING_EXTENSIONS.contains(&ext))
}

/// Adds the recordings under `dir` (subfolders too; symbolic links to folders are not
/// followed) to `out`; folders that cannot be listed go to `errors`.
fn walk(dir: &Path, out: &mut Vec<PathBuf>, errors: &mut Vec<String>) {
    let entries = match std::fs::read_dir(dir) {
        Ok(e) => e,
        Err(e) => {
            errors.push(format!("cannot read folder {}: {e}", dir.display()));
            return;
        }
    };
    for entry in entries {
        match entry {
            Ok(e) => {
                let path = e.path();
                if e.file_type().is_ok_and(|t| t.is_dir()) {
                    walk(&path, out, errors);
                } else if is_recording(&path) {
                    out.push(path);
                }
            }
            Err(e) => errors.push(format!("cannot read folder {}: {e}", dir.display())),
        }
    }
}

/// The files to check, sorted by path: files as given, folders expanded.
fn expand(args: &[PathBuf], errors: &mut Vec<String>) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for a in args {
        if a.is_dir() {
            let before = files.len() + errors.len();
            walk(a, &mut files, errors);
            if files.len() + errors.len() == before {
                errors.push(format!("{}: no recordings in this folder", a.display()));
            }
        } else {
            files.push(a.clone());
        }
    }
    files.sort();
    files.dedup();
    files
}

/// What printing needs of each file as it finishes, in path order.
struct Sink {
    format: ReportArg,
    /// Reports kept for the formats written at the end (JSON, JUnit, HTML, `--report-dir`).
    kept: Vec<Report>,
    keep: bool,
    /// Timelines are kept only for the HTML page.
    timelines: bool,
    summary: ndjson::Summary,
    passed: bool,
    failed: u64,
    errors: Vec<String>,
}

impl Sink {
    fn new(format: ReportArg, report_dir: bool) -> Sink {
        Sink {
            format,
            kept: Vec::new(),
            keep: report_dir || !matches!(format, ReportArg::Text | ReportArg::Ndjson),
            timelines: report_dir || format == ReportArg::Html,
            summary: ndjson::Summary::new(),
            passed: true,
            failed: 0,
            errors: Vec::new(),
        }
    }

    /// Prints or keeps one file's result.
    fn take(&mut self, file: &Path, result: Result<Report, String>) -> Result<()> {
        let mut r = match result {
            Ok(r) => r,
            Err(message) => {
                if self.format == ReportArg::Ndjson {
                    let name = file.display().to_string();
                    say_raw!("{}", self.summary.unreadable_line(&name, &message))?;
                }
                self.errors.push(message);
                return Ok(());
            }
        };
        if let Some(e) = &r.error {
            self.errors
                .push(format!("{}: {}", file.display(), e.message));
        }
        self.passed &= r.passed();
        self.failed += u64::from(r.verdict == drivespec_check::Verdict::Fail);
        match self.format {
            ReportArg::Text => say_raw!("{}", render::text(std::slice::from_ref(&r)))?,
            ReportArg::Ndjson => say_raw!("{}", self.summary.report_lines(&r))?,
            _ => {}
        }
        if self.keep {
            if !self.timelines {
                r.timelines = Vec::new();
            }
            self.kept.push(r);
        }
        Ok(())
    }

    /// Prints what is printed at the end: the documents of the whole run, or the summary.
    fn finish(&self, files: usize) -> Result<()> {
        match self.format {
            ReportArg::Text if files > 1 => say_raw!(
                "{files} files: {} failed, {} unreadable\n",
                self.failed,
                self.errors.len()
            )?,
            ReportArg::Text => {}
            ReportArg::Ndjson => say_raw!("{}", self.summary.line())?,
            ReportArg::Json => say_raw!("{}", render::json(&self.kept))?,
            ReportArg::Junit => say_raw!("{}", render::junit(&self.kept))?,
            ReportArg::Html => say_raw!("{}", render::html(&self.kept))?,
        }
        Ok(())
    }
}

/// Checks one file; an error names the file.
fn check_one(
    spec: &Spec,
    file: &Path,
    options: &RunOptions,
    mut bar: Option<Bar>,
) -> Result<Report, String> {
    check_path(spec, file, options, &mut |p| {
        if let Some(b) = bar.as_mut() {
            b.show(p);
        }
    })
    .map_err(|e| e.to_string())
}

/// Files released to the workers: a file starts only while fewer than `window` files wait
/// to be printed.
struct Gate {
    printed: Mutex<usize>,
    moved: Condvar,
    window: usize,
}

impl Gate {
    /// Waits until file `index` may start.
    fn enter(&self, index: usize) {
        let mut printed = self.printed.lock().unwrap_or_else(|e| e.into_inner());
        while index >= *printed + self.window {
            printed = self.moved.wait(printed).unwrap_or_else(|e| e.into_inner());
        }
    }

    /// Records that files before `next` are printed.
    fn advance(&self, next: usize) {
        *self.printed.lock().unwrap_or_else(|e| e.into_inner()) = next;
        self.moved.notify_all();
    }

    /// Lets every file start (printing stopped).
    fn open(&self) {
        self.advance(usize::MAX / 2);
    }
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
    let jobs = args.jobs.map_or_else(
        || std::thread::available_parallelism().map_or(1, usize::from),
        usize::from,
    );
    if let Some(iface) = &args.live {
        return run_live(iface, &spec, &args, &options, &interrupt, format);
    }
    let mut sink = Sink::new(format, args.report_dir.is_some());
    let files = expand(&args.files, &mut sink.errors);
    let ci = std::env::var("CI").is_ok_and(|v| v == "true");
    // A bar redrawn by several files at once would be unreadable: bars only one at a time.
    let tty = std::io::stderr().is_terminal() && (jobs == 1 || files.len() == 1);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs)
        .build()
        .context("cannot start the worker threads")?;
    let gate = Gate {
        printed: Mutex::new(0),
        moved: Condvar::new(),
        window: jobs.saturating_mul(WINDOW_PER_JOB),
    };
    let stop = AtomicBool::new(false);
    let (tx, rx) = mpsc::channel::<(usize, Result<Report, String>)>();
    let printed = std::thread::scope(|s| {
        let (spec, options, files, gate, stop) = (&spec, &options, &files, &gate, &stop);
        s.spawn(move || {
            pool.install(|| {
                files
                    .iter()
                    .enumerate()
                    .par_bridge()
                    .for_each_with(tx, |tx, (i, file)| {
                        gate.enter(i);
                        if stop.load(Ordering::Relaxed) || options.stop.load(Ordering::Relaxed) {
                            return;
                        }
                        let bar = (ci || tty).then(|| Bar {
                            ci,
                            tty,
                            name: file.display().to_string(),
                            last: 0,
                        });
                        let _ = tx.send((i, check_one(spec, file, options, bar)));
                    });
            });
        });
        let mut waiting = BTreeMap::new();
        let mut next = 0usize;
        for (i, result) in rx {
            waiting.insert(i, result);
            while let Some(result) = waiting.remove(&next) {
                let file = files.get(next).map_or(Path::new("-"), PathBuf::as_path);
                if let Err(e) = sink.take(file, result) {
                    stop.store(true, Ordering::Relaxed);
                    gate.open();
                    return Err(e);
                }
                next += 1;
                gate.advance(next);
            }
        }
        Ok(())
    });
    printed?;
    conclude(&sink, files.len(), &args, &interrupt)
}

/// Prints the end of the run, writes `--report-dir` and gives the outcome (stopped, setup
/// error, pass or fail).
fn conclude(sink: &Sink, files: usize, args: &CheckArgs, interrupt: &Interrupt) -> Result<Outcome> {
    sink.finish(files)?;
    if let Some(dir) = &args.report_dir {
        write_reports(dir, &sink.kept)?;
    }
    if let (Some(code), Some(cause)) = (interrupt.exit_code(), interrupt.cause()) {
        eprintln!("drivespec: interrupted by {cause}: the report covers what was read");
        return Ok(Outcome::Stopped(code));
    }
    if !sink.errors.is_empty() {
        bail!("{}", sink.errors.join("\ndrivespec: "));
    }
    Ok(if sink.passed {
        Outcome::Pass
    } else {
        Outcome::Fail
    })
}

/// `drivespec check --live IFACE`: the frames of the interface, checked as they arrive until
/// `--duration` ends or a signal stops the run.
fn run_live(
    iface: &str,
    spec: &Spec,
    args: &CheckArgs,
    options: &RunOptions,
    interrupt: &Interrupt,
    format: ReportArg,
) -> Result<Outcome> {
    let mut sock = drivespec_wire::RawSocket::open(iface, drivespec_wire::OpenOptions::default())?;
    let deadline = args.duration.map(|d| Instant::now() + d);
    eprintln!(
        "drivespec: checking the frames on {iface}{}",
        match args.duration {
            Some(d) => format!(" for {} ms", d.as_millis()),
            None => " until Ctrl-C".to_owned(),
        }
    );
    let mut failure = None;
    let frames = std::iter::from_fn(|| loop {
        if options.stop.load(Ordering::Relaxed) {
            return None;
        }
        let wait = match deadline {
            Some(d) => d.checked_duration_since(Instant::now())?.min(LIVE_POLL),
            None => LIVE_POLL,
        };
        match sock.recv(wait) {
            Ok(Some(r)) => {
                let time = r.at.duration_since(UNIX_EPOCH).unwrap_or_default();
                let time = u64::try_from(time.as_micros()).unwrap_or(u64::MAX);
                return Some(LiveFrame {
                    time,
                    data: r.frame,
                });
            }
            Ok(None) => continue,
            Err(e) => {
                failure = Some(e);
                return None;
            }
        }
    });
    let report = check_frames(spec, iface, frames, options)?;
    let mut sink = Sink::new(format, args.report_dir.is_some());
    sink.take(Path::new(iface), Ok(report))?;
    if let Some(e) = failure {
        sink.errors.push(e.to_string());
    }
    conclude(&sink, 1, args, interrupt)
}
