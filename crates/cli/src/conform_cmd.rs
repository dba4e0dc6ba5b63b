//! `drivespec conform`: argument parsing and printing around `drivespec_conform::run`.

use crate::interrupt::{parse_duration, Interrupt};
use crate::{json, Context, Format, Outcome};
use anyhow::{bail, Result};
use drivespec_conform::dut::Dut;
use drivespec_conform::report::Status;
use drivespec_conform::runner::{paint, RED};
use drivespec_conform::select::LevelFilter;
use drivespec_conform::select::{closest, did_you_mean};
use drivespec_conform::suite::Settings;
use drivespec_conform::{Options, Progress};
use drivespec_sim::reference::BrakeKind;
use drivespec_spec::FamilyId;
use std::path::PathBuf;
use std::time::Duration;

/// Schema of `drivespec conform --format json` on stdout (crates/conform/README.md).
const SUMMARY_SCHEMA: &str = "drivespec-conform-summary/1";

/// Schema of `drivespec conform --list --format json` (crates/conform/README.md).
const LIST_SCHEMA: &str = "drivespec-conform-list/1";

/// Run the conformance suite against a device under test.
#[derive(clap::Args)]
pub struct ConformArgs {
    /// Family: hpd, psd4xx, psx3xx or all.
    family: String,
    /// Device under test: sim[:MODEL], serial:PATH?baud=N, tcp:HOST:PORT, exec:'COMMAND ARGS'.
    #[arg(long, default_value = "sim")]
    dut: String,
    /// Device model.
    #[arg(long)]
    model: Option<String>,
    /// psx3xx: the device's brake option, snap or holding (manual 5.11–5.13; an ordering
    /// option no ISDU entry reports). The model must be one the spec offers it for.
    #[arg(long, value_name = "KIND")]
    brake: Option<String>,
    /// Run only cases matching this glob (repeatable; `*` also matches `/`).
    #[arg(long = "case", value_name = "GLOB")]
    case: Vec<String>,
    /// Skip cases matching this glob (repeatable).
    #[arg(long, value_name = "GLOB")]
    skip: Vec<String>,
    /// Run `must` cases only, or `must` and `should` cases.
    #[arg(long, value_enum, default_value_t = LevelArg::Should)]
    level: LevelArg,
    /// Known failures, each with a reason (TOML `[[failure]] case = …, reason = …`).
    #[arg(long, value_name = "FILE")]
    expect: Option<PathBuf>,
    /// List the selected cases and run nothing.
    #[arg(long)]
    list: bool,
    /// Stop at the first unexpected failure.
    #[arg(long)]
    fail_fast: bool,
    /// Run a case that fails unexpectedly up to N more times (real hardware noise); a case
    /// that then passes is reported as flaky, with its first failure.
    #[arg(long, value_name = "N", default_value_t = 0)]
    retries: u32,
    /// Seed of the values the cases pick.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Serial address of the device (HPD Pr27).
    #[arg(long, default_value_t = 0)]
    address: u8,
    /// Make one erratum strict: only READING of the erratum with OPTION is accepted
    /// (repeatable; every reading of the other errata is accepted and reported).
    #[arg(long = "reading", value_name = "OPTION=READING")]
    reading: Vec<String>,
    /// Extra time allowed for each answer on real transports, in ms.
    #[arg(long, value_name = "MS")]
    slack_ms: Option<u64>,
    /// Folder of the reports.
    #[arg(long, default_value = "reports", value_name = "DIR")]
    report_dir: PathBuf,
    /// JUnit XML file (default DIR/conform.junit.xml).
    #[arg(long, value_name = "FILE")]
    junit: Option<PathBuf>,
    /// JSON report file (default DIR/conform.json).
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
    /// HTML report file (default DIR/conform.html).
    #[arg(long, value_name = "FILE")]
    html: Option<PathBuf>,
    /// Print only the failures, as they happen, and the summary.
    #[arg(long, conflicts_with = "verbose")]
    quiet: bool,
    /// Print one line per case, passing or not.
    #[arg(long)]
    verbose: bool,
    /// Stop the run after this long (90s, 10m, 2h), write the reports of the cases that ran
    /// (the rest `not-run`) and exit 124.
    #[arg(long, value_name = "TIME", value_parser = parse_duration)]
    timeout: Option<Duration>,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum LevelArg {
    Must,
    Should,
}

/// Runs `drivespec conform`.
pub fn run(args: ConformArgs, ctx: &Context) -> Result<Outcome> {
    let families = if args.family.eq_ignore_ascii_case("all") {
        Vec::new()
    } else {
        match FamilyId::parse(&args.family) {
            Some(f) => vec![f],
            None => bail!(
                "unknown family {:?} (hpd, psd4xx, psx3xx or all){}",
                args.family,
                did_you_mean(&closest(&args.family, ["hpd", "psd4xx", "psx3xx", "all"]))
            ),
        }
    };
    let dut: Dut = args.dut.parse()?;
    let spec = ctx.spec()?;
    let readings = strict_readings(&spec, &families, &args.reading)?;
    let brake = match &args.brake {
        Some(text) if families != [FamilyId::Psx3xx] => {
            bail!("--brake {text}: the brake is an option of the psx3xx drives; run `drivespec conform psx3xx --brake {text}`")
        }
        Some(text) => Some(brake_kind(&spec, text)?),
        None => None,
    };
    let interrupt = Interrupt::install(args.timeout)?;
    let opts = Options {
        families,
        dut,
        settings: Settings {
            address: args.address,
            seed: args.seed,
            model: args.model,
            slack_us: args.slack_ms.map(|ms| ms.saturating_mul(1000)),
            bit_rate: None,
            brake,
            readings,
        },
        case: args.case,
        skip: args.skip,
        level: match args.level {
            LevelArg::Must => LevelFilter::Must,
            LevelArg::Should => LevelFilter::Should,
        },
        expect: args.expect,
        list: args.list,
        fail_fast: args.fail_fast,
        retries: args.retries,
        report_dir: args.report_dir,
        junit: args.junit,
        json: args.json,
        html: args.html,
        no_reports: false,
        progress: if args.quiet {
            Progress::Quiet
        } else if args.verbose {
            Progress::Verbose
        } else {
            Progress::Auto
        },
        colour: crate::colour(&std::io::stderr()),
        command: "drivespec conform".to_owned(),
        stop: interrupt.flag(),
    };
    let mut err = std::io::stderr();
    let summary = drivespec_conform::run(&spec, &opts, &mut err)?;
    if opts.list {
        match ctx.format {
            Format::Json => say!(
                "{}",
                json(&serde_json::json!({
                    "schema": LIST_SCHEMA,
                    "cases": summary.listed,
                }))
            )?,
            Format::Text => {
                for c in &summary.listed {
                    say!("{:<48} {:<6} {}", c.id, c.level.as_str(), c.description)?;
                }
                say!("{} case(s)", summary.listed.len())?;
            }
        }
        return Ok(Outcome::Pass);
    }
    let r = &summary.report;
    let s = r.summary;
    match ctx.format {
        Format::Json => say!(
            "{}",
            json(&serde_json::json!({
                "schema": SUMMARY_SCHEMA,
                "summary": s,
                "failures": r.cases.iter().filter(|c| c.status == Status::Fail).map(|c| {
                    serde_json::json!({
                        "id": c.id,
                        "requirement": c.failure.as_ref().and_then(|f| f.broken()).map(|b| &b.id),
                        "message": c.failure.as_ref().map(|f| &f.message),
                        "replay": c.replay,
                    })
                }).collect::<Vec<_>>(),
                "reports": summary.written,
            }))
        )?,
        Format::Text => {
            recap(r)?;
            for c in r.cases.iter().filter(|c| c.status == Status::Fixed) {
                say!(
                    "fixed: {} passes; remove it from the expectations file",
                    c.id
                )?;
            }
            for k in &r.stale_expectations {
                say!("stale expectation: {} matches no selected case", k.case)?;
            }
            let mut seen: Vec<(String, usize)> = Vec::new();
            for f in r.cases.iter().flat_map(|c| &c.findings) {
                let line = f.line();
                match seen.iter_mut().find(|(l, _)| *l == line) {
                    Some((_, n)) => *n += 1,
                    None => seen.push((line, 1)),
                }
            }
            for (line, n) in &seen {
                say!("acceptable: {line} ({n} case(s))")?;
            }
            say!(
                "{} passed ({} acceptable), {} failed, {} skipped ({} expected failures, {} fixed, {} not run) of {} cases against {}",
                s.passed, s.acceptable, s.failed, s.skipped, s.expected_failures, s.fixed, s.not_run, s.total, r.run.transport
            )?;
            for c in r.cases.iter().filter(|c| c.status == Status::Flaky) {
                let first = c.failure.as_ref().map_or("", |f| f.message.as_str());
                say!(
                    "flaky: {} failed, then passed when run again ({first})",
                    c.id
                )?;
            }
            if s.flaky > 0 {
                say!("{} flaky case(s): passed only when run again", s.flaky)?;
            }
            for c in &r.coverage_summary {
                say!(
                    "coverage {}: {} of {} must requirements checked, {} not observable over the interface",
                    c.family, c.checked, c.must, c.not_observable
                )?;
            }
            for w in &summary.written {
                say!("report: {}", w.display())?;
            }
            if let (Some(cause), true) = (interrupt.cause(), s.interrupted) {
                say!(
                    "interrupted by {cause}: {} case(s) not run; the reports cover the cases that ran",
                    s.not_run
                )?;
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

/// The unexpected failures again, each with its broken requirement, what the manual allows,
/// what came and the replay command.
fn recap(r: &drivespec_conform::report::Report) -> Result<()> {
    let failed: Vec<_> = r
        .cases
        .iter()
        .filter(|c| c.status == Status::Fail)
        .collect();
    if failed.is_empty() {
        return Ok(());
    }
    let colour = crate::colour(&std::io::stdout());
    say!("failures ({}):", failed.len())?;
    for c in failed {
        say!("{} {}", paint(colour, RED, "FAIL"), c.id)?;
        for l in c.failure.iter().flat_map(|f| f.headline()) {
            say!("  {l}")?;
        }
        if let Some(line) = &c.replay {
            say!("  replay: {line}")?;
        }
    }
    Ok(())
}

/// The `--reading OPTION=READING` pairs, each checked against the errata of the selected
/// families (all when `families` is empty).
fn strict_readings(
    spec: &drivespec_spec::Spec,
    families: &[FamilyId],
    given: &[String],
) -> Result<Vec<(String, String)>> {
    let selected: Vec<&drivespec_spec::Family> = spec
        .families()
        .into_iter()
        .filter(|f| families.is_empty() || families.contains(&f.info.id))
        .collect();
    let mut out = Vec::new();
    for text in given {
        let Some((option, reading)) = text.split_once('=') else {
            bail!("--reading {text:?}: expected OPTION=READING");
        };
        let (option, reading) = (option.trim(), reading.trim());
        let owner = selected
            .iter()
            .find(|f| f.errata.iter().any(|e| e.option.as_deref() == Some(option)));
        let family = match owner {
            Some(f) => *f,
            None => match selected.first() {
                Some(f) if selected.len() == 1 => *f,
                _ => {
                    let known: Vec<&str> = selected
                        .iter()
                        .flat_map(|f| f.errata.iter().filter_map(|e| e.option.as_deref()))
                        .collect();
                    bail!(
                        "--reading: no erratum option {option:?}; options: {}",
                        known.join(", ")
                    );
                }
            },
        };
        if let Err(e) = drivespec_spec::Readings::default().choose(family, option, reading) {
            bail!("--reading: {e}");
        }
        out.push((option.to_owned(), reading.to_owned()));
    }
    Ok(out)
}

/// The brake option `text` names (spec `[[protocol.brake]] kind`, PSx3xx manual 5.11–5.13).
pub(crate) fn brake_kind(spec: &drivespec_spec::Spec, text: &str) -> Result<BrakeKind> {
    let kinds: Vec<&str> = spec
        .family(FamilyId::Psx3xx)
        .psx3xx()
        .map(|p| p.brakes.iter().map(|b| b.kind.as_str()).collect())
        .unwrap_or_default();
    match BrakeKind::from_spec_name(text) {
        Some(k) if kinds.contains(&k.spec_name()) => Ok(k),
        _ => bail!(
            "--brake {text:?}: no such brake option; the PSx3xx brakes are {} (manual 5.11-5.13)",
            kinds.join(", ")
        ),
    }
}
