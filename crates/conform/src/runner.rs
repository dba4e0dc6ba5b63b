//! The runner: selects cases, runs them on the device under test, applies the expectations
//! file, shows progress and writes the reports. The CLI passes parsed [`Options`] to [`run`]
//! and exits with [`Summary::exit_code`].
//!
//! Runner contract (after toml-test and JSONTestSuite): exit 0 when every selected case
//! passed or failed as the expectations file says; 1 when a case failed unexpectedly; 2 for
//! bad usage or a device under test that cannot be reached at all ([`ConformError`]). A
//! device that misbehaves during the run fails cases, with evidence; the run goes on and the
//! reports are always written.

use crate::bar::Bar;
use crate::case::{CaseInfo, CaseRun, Outcome};
use crate::dut::{shell_quote, Dut};
use crate::report::{
    self, CaseRef, CaseReport, Counts, Coverage, CoverageRow, FamilyCoverage, Report, RunInfo,
    Status, Tool,
};
use crate::select::{Expectations, LevelFilter, SelectError, Selection};
use crate::suite::{self, Session, Settings, SetupError, Suite};
use drivespec_spec::{FamilyId, Level, Requirement, Spec};
use std::io::Write;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// Failing cases without a single byte from the device after which a run stops as a set-up
/// error: a wrong port, bit rate or address would otherwise cost the whole suite's time-outs.
const MUTE_CASES: usize = 10;

/// How progress is shown. Every mode but `Quiet` ends with nothing more: the recap of the
/// failures and the summary are the caller's ([`Summary::report`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Progress {
    /// A progress bar on a terminal, plain lines otherwise and when `CI=true`.
    #[default]
    Auto,
    /// A bar redrawn in place; failures as they happen.
    Bar,
    /// Failures as they happen and a progress line at every tenth of the run.
    Plain,
    /// One line per case; failures with their details.
    Verbose,
    /// Failures as they happen, nothing else.
    Quiet,
}

impl Progress {
    /// `Auto` resolved for stderr and the environment.
    pub fn resolve(self) -> Progress {
        use std::io::IsTerminal;
        match self {
            Progress::Auto => {
                let ci =
                    std::env::var("CI").is_ok_and(|v| v.eq_ignore_ascii_case("true") || v == "1");
                if !ci && std::io::stderr().is_terminal() {
                    Progress::Bar
                } else {
                    Progress::Plain
                }
            }
            p => p,
        }
    }
}

/// Everything `drivespec conform` takes.
#[derive(Debug, Clone)]
pub struct Options {
    /// Families to run; empty: every family that has a suite (`all`).
    pub families: Vec<FamilyId>,
    /// The device under test.
    pub dut: Dut,
    /// Address, seed, model, brake, slack.
    pub settings: Settings,
    /// `--case` patterns.
    pub case: Vec<String>,
    /// `--skip` patterns.
    pub skip: Vec<String>,
    /// `--level`.
    pub level: LevelFilter,
    /// `--expect FILE`.
    pub expect: Option<PathBuf>,
    /// `--list`: list the selected cases, run nothing.
    pub list: bool,
    /// `--fail-fast`: stop at the first unexpected failure.
    pub fail_fast: bool,
    /// `--retries N`: run a case that fails unexpectedly up to N more times; one that then
    /// passes is `flaky`.
    pub retries: u32,
    /// Folder of the reports (default `reports`).
    pub report_dir: PathBuf,
    /// JUnit file (default `<report_dir>/conform.junit.xml`).
    pub junit: Option<PathBuf>,
    /// JSON file (default `<report_dir>/conform.json`).
    pub json: Option<PathBuf>,
    /// HTML file (default `<report_dir>/conform.html`).
    pub html: Option<PathBuf>,
    /// Write no report files.
    pub no_reports: bool,
    /// How progress is shown.
    pub progress: Progress,
    /// Colour the progress output (ANSI; for terminals).
    pub colour: bool,
    /// The command that starts a run, for replay lines (`drivespec conform`).
    pub command: String,
    /// Set by the caller to stop the run after the current case; the rest is `not-run` and
    /// the report is marked interrupted.
    pub stop: Arc<AtomicBool>,
}

impl Default for Options {
    fn default() -> Options {
        Options {
            families: vec![FamilyId::Hpd],
            dut: Dut::default(),
            settings: Settings::default(),
            case: Vec::new(),
            skip: Vec::new(),
            level: LevelFilter::default(),
            expect: None,
            list: false,
            fail_fast: false,
            retries: 0,
            report_dir: PathBuf::from("reports"),
            junit: None,
            json: None,
            html: None,
            no_reports: false,
            progress: Progress::Auto,
            colour: false,
            command: "drivespec conform".to_owned(),
            stop: Arc::default(),
        }
    }
}

/// Why a run could not happen (exit 2).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ConformError {
    /// Bad usage: options, patterns, the expectations file.
    #[error(transparent)]
    Select(#[from] SelectError),
    /// A suite or the transport could not be set up.
    #[error(transparent)]
    Setup(#[from] SetupError),
    /// The device answered nothing at all in the first cases: the transport, bit rate or
    /// address is wrong, not the device.
    #[error("the device under test answered nothing in the first {cases} cases ({dut}): check --dut, the bit rate and --address")]
    Mute {
        /// Cases run.
        cases: usize,
        /// The device under test.
        dut: String,
    },
    /// A report could not be written.
    #[error("cannot write {file}: {why}")]
    Write {
        /// The file.
        file: String,
        /// Why.
        why: String,
    },
}

/// What a run gives back.
#[derive(Debug, Clone)]
pub struct Summary {
    /// The report (also written to the files).
    pub report: Report,
    /// Files written.
    pub written: Vec<PathBuf>,
    /// With `--list`: the selected cases.
    pub listed: Vec<CaseInfo>,
}

impl Summary {
    /// 0 all pass or only expected failures, 1 failures.
    pub fn exit_code(&self) -> u8 {
        self.report.summary.exit_code
    }
}

/// Runs the conformance suites of `opts` and writes the reports.
pub fn run(spec: &Spec, opts: &Options, progress: &mut dyn Write) -> Result<Summary, ConformError> {
    let selection = Selection::new(&opts.case, &opts.skip, opts.level)?;
    let expectations = match &opts.expect {
        Some(p) => Expectations::load(p)?,
        None => Expectations::default(),
    };
    let mut settings = opts.settings.clone();
    match &opts.dut {
        Dut::Sim { model: Some(m) } if settings.model.is_none() => settings.model = Some(m.clone()),
        Dut::Serial { baud: Some(b), .. } if settings.bit_rate.is_none() => {
            settings.bit_rate = Some(*b)
        }
        _ => {}
    }
    let wanted: Vec<FamilyId> = if opts.families.is_empty() {
        FamilyId::ALL.to_vec()
    } else {
        opts.families.clone()
    };
    let mut suites: Vec<Box<dyn Suite + '_>> = Vec::new();
    for f in wanted {
        suites.push(suite::suite(spec, f, &settings)?);
    }
    let ids: Vec<&str> = suites
        .iter()
        .flat_map(|s| s.cases().iter().map(|c| c.id.as_str()))
        .collect();
    selection.check_patterns(&ids)?;
    let mut plan: Vec<(usize, usize)> = Vec::new();
    for (si, s) in suites.iter().enumerate() {
        for (ci, c) in s.cases().iter().enumerate() {
            if selection.admits(&c.id, c.level) {
                plan.push((si, ci));
            }
        }
    }
    if plan.is_empty() {
        return Err(SelectError::Empty.into());
    }
    if opts.list {
        let listed = plan
            .iter()
            .filter_map(|(si, ci)| suites.get(*si).and_then(|s| s.cases().get(*ci)).cloned())
            .collect();
        let report = build_report(
            opts,
            &settings,
            &suites,
            Vec::new(),
            "",
            &expectations,
            spec,
        );
        return Ok(Summary {
            report,
            written: Vec::new(),
            listed,
        });
    }
    if !opts.no_reports {
        drivespec_report::check_writable(&report_paths(opts)).map_err(write_error)?;
    }
    let mut sessions: Vec<Box<dyn Session + '_>> = Vec::new();
    for s in &suites {
        sessions.push(s.open(&opts.dut)?);
    }
    let transport = sessions.first().map(|s| s.describe()).unwrap_or_default();
    let mode = opts.progress.resolve();
    let run_started = Instant::now();
    let started_at = std::time::SystemTime::now();
    let mut failed = 0usize;
    let mut results: Vec<CaseReport> = Vec::new();
    let mut stop = false;
    let mut interrupted = false;
    let mut heard = false;
    let total = plan.len();
    let bar = (mode == Progress::Bar).then(|| Bar::count(total as u64, "cases"));
    for (n, (si, ci)) in plan.iter().enumerate() {
        let (Some(suite), Some(session)) = (suites.get(*si), sessions.get_mut(*si)) else {
            continue;
        };
        let Some(info) = suite.cases().get(*ci) else {
            continue;
        };
        let known = expectations.known(&info.id);
        if !interrupted && opts.stop.load(Ordering::Relaxed) {
            interrupted = true;
            stop = true;
        }
        if stop {
            results.push(case_report(
                info,
                None,
                Status::NotRun,
                known.map(|k| k.reason.clone()),
                None,
                0.0,
            ));
            continue;
        }
        let started = Instant::now();
        let mut run = session.run(*ci);
        let mut first_failure = None;
        let mut tries = 0;
        while known.is_none()
            && run.outcome.failed()
            && tries < opts.retries
            && !opts.stop.load(Ordering::Relaxed)
        {
            tries += 1;
            let again = session.run(*ci);
            if !again.outcome.failed() {
                if let Outcome::Fail(f) = std::mem::replace(&mut run, again).outcome {
                    first_failure = Some(f);
                }
            } else {
                run = again;
            }
        }
        let answered = run
            .evidence
            .iter()
            .any(|r| r.got.as_ref().is_some_and(|a| !a.is_silence()));
        heard |= answered || !run.outcome.failed();
        let mute = !heard && n + 1 >= MUTE_CASES && !opts.stop.load(Ordering::Relaxed);
        let wall_ms = started.elapsed().as_secs_f64() * 1000.0;
        let status = match (&run.outcome, known) {
            (Outcome::Pass, None) if first_failure.is_some() => Status::Flaky,
            (Outcome::Pass, None) if run.findings.is_empty() => Status::Pass,
            (Outcome::Pass, None) => Status::Acceptable,
            (Outcome::Pass, Some(_)) => Status::Fixed,
            (Outcome::Fail(_), None) => Status::Fail,
            (Outcome::Fail(_), Some(_)) => Status::ExpectedFailure,
            (Outcome::Skip { .. }, _) => Status::Skipped,
        };
        let replay = (run.outcome.failed() || first_failure.is_some())
            .then(|| replay_line(opts, &settings, &info.id));
        let headline = match &run.outcome {
            Outcome::Fail(f) if status == Status::Fail => f.headline(),
            _ => Vec::new(),
        };
        failed += usize::from(status == Status::Fail);
        let line = Line {
            at: (n + 1, total),
            id: &info.id,
            status,
            headline: &headline,
            replay: replay.as_deref(),
            failed,
            elapsed_s: run_started.elapsed().as_secs_f64(),
        };
        show(progress, mode, bar.as_ref(), opts.colour, &line);
        if mute {
            return Err(ConformError::Mute {
                cases: n + 1,
                dut: opts.dut.to_string(),
            });
        }
        if status == Status::Fail && opts.fail_fast {
            stop = true;
        }
        let mut report = case_report(
            info,
            Some(run),
            status,
            known.map(|k| k.reason.clone()),
            replay,
            wall_ms,
        );
        report.failure = report.failure.take().or(first_failure);
        results.push(report);
    }
    if let Some(b) = &bar {
        b.finish();
    }
    let mut report = build_report(
        opts,
        &settings,
        &suites,
        results,
        &transport,
        &expectations,
        spec,
    );
    report.summary.interrupted = interrupted;
    report.timing = Some(report::Timing {
        started: started_at,
        wall_ms: run_started.elapsed().as_secs_f64() * 1000.0,
    });
    let written = if opts.no_reports {
        Vec::new()
    } else {
        write_reports(opts, &report)?
    };
    Ok(Summary {
        report,
        written,
        listed: Vec::new(),
    })
}

/// What the progress output says after one case.
struct Line<'a> {
    /// This case's number and the number of cases.
    at: (usize, usize),
    id: &'a str,
    status: Status,
    /// The failure's headline (unexpected failures).
    headline: &'a [String],
    replay: Option<&'a str>,
    /// Unexpected failures so far.
    failed: usize,
    /// Seconds since the first case.
    elapsed_s: f64,
}

/// `text` in the ANSI colour `code` when `on`.
pub fn paint(on: bool, code: &str, text: &str) -> String {
    if on {
        format!("\x1b[{code}m{text}\x1b[0m")
    } else {
        text.to_owned()
    }
}

/// Red, for failures.
pub const RED: &str = "1;31";

/// One case's progress (on `bar` in [`Progress::Bar`] mode). A failure shows, in every mode,
/// its headline (the broken requirement, what the manual allows and what came) and the replay
/// command.
fn show(out: &mut dyn Write, mode: Progress, bar: Option<&Bar>, colour: bool, l: &Line<'_>) {
    let (n, total) = l.at;
    let fail = l.status == Status::Fail;
    let details = |out: &mut dyn Write| {
        let _ = writeln!(out, "{} {} ({n}/{total})", paint(colour, RED, "FAIL"), l.id);
        for h in l.headline {
            let _ = writeln!(out, "  {h}");
        }
        if let Some(r) = l.replay {
            let _ = writeln!(out, "  replay: {r}");
        }
    };
    match mode {
        Progress::Auto => {}
        Progress::Quiet => {
            if fail {
                details(out);
            }
        }
        Progress::Verbose => {
            if fail {
                details(out);
            } else {
                let _ = writeln!(out, "{:<16} {} ({n}/{total})", l.status.as_str(), l.id);
            }
        }
        Progress::Plain => {
            if fail {
                details(out);
            }
            let tenth = |k: usize| k * 10 / total.max(1);
            if total >= 20 && tenth(n) > tenth(n.saturating_sub(1)) {
                let _ = writeln!(
                    out,
                    "progress: {n}/{total} cases ({}%), {} failed, {:.0} s",
                    n * 100 / total.max(1),
                    l.failed,
                    l.elapsed_s
                );
            }
        }
        Progress::Bar => {
            let Some(bar) = bar else { return };
            if fail {
                bar.suspend(|| {
                    details(out);
                    let _ = out.flush();
                });
            }
            let failed = match l.failed {
                0 => String::new(),
                k => format!("{k} failed, "),
            };
            bar.set(n as u64, format!("{failed}{}", l.id));
        }
    }
}

fn case_report(
    info: &CaseInfo,
    run: Option<CaseRun>,
    status: Status,
    expectation: Option<String>,
    replay: Option<String>,
    wall_ms: f64,
) -> CaseReport {
    let (failure, skip_reason, evidence, elapsed_us, findings, checked) = match run {
        Some(r) => {
            let (failure, skip) = match r.outcome {
                Outcome::Pass => (None, None),
                Outcome::Fail(f) => (Some(f), None),
                Outcome::Skip { reason } => (None, Some(reason)),
            };
            (
                failure,
                skip,
                r.evidence,
                r.elapsed_us,
                r.findings,
                r.checked,
            )
        }
        None => (None, None, Vec::new(), 0, Vec::new(), Vec::new()),
    };
    let expectation = match status {
        Status::ExpectedFailure | Status::Fixed | Status::NotRun => expectation,
        _ => None,
    };
    CaseReport {
        id: info.id.clone(),
        family: info.family,
        level: info.level,
        description: info.description.clone(),
        requirements: info.requirements.clone(),
        status,
        failure,
        skip_reason,
        checked,
        findings,
        expectation,
        evidence,
        replay,
        wall_ms,
        elapsed_us,
    }
}

/// The command line that runs one case alone against the same device.
fn replay_line(opts: &Options, settings: &Settings, id: &str) -> String {
    let family = id.split('/').next().unwrap_or("all");
    let mut words = vec![opts.command.clone(), family.to_owned()];
    words.push(format!("--dut {}", shell_quote(&opts.dut.to_string())));
    words.push(format!("--case {}", shell_quote(id)));
    if settings.seed != 0 {
        words.push(format!("--seed {}", settings.seed));
    }
    if settings.address != 0 {
        words.push(format!("--address {}", settings.address));
    }
    if let (Some(m), false) = (
        &settings.model,
        matches!(opts.dut, Dut::Sim { model: Some(_) }),
    ) {
        words.push(format!("--model {}", shell_quote(m)));
    }
    if let Some(b) = settings.brake {
        words.push(format!("--brake {}", b.spec_name()));
    }
    words.join(" ")
}

#[allow(clippy::too_many_arguments)]
fn build_report(
    opts: &Options,
    settings: &Settings,
    suites: &[Box<dyn Suite + '_>],
    cases: Vec<CaseReport>,
    transport: &str,
    expectations: &Expectations,
    spec: &Spec,
) -> Report {
    let mut counts = Counts {
        total: cases.len(),
        ..Counts::default()
    };
    for c in &cases {
        match c.status {
            Status::Pass => counts.passed += 1,
            Status::Acceptable => {
                counts.passed += 1;
                counts.acceptable += 1;
            }
            Status::Flaky => {
                counts.passed += 1;
                counts.flaky += 1;
            }
            Status::Fail => counts.failed += 1,
            Status::ExpectedFailure => counts.expected_failures += 1,
            Status::Fixed => counts.fixed += 1,
            Status::Skipped => counts.skipped += 1,
            Status::NotRun => counts.not_run += 1,
        }
    }
    counts.exit_code = u8::from(counts.failed > 0);
    let families: Vec<FamilyId> = suites.iter().map(|s| s.family()).collect();
    let mut coverage = Vec::new();
    let mut coverage_summary = Vec::new();
    for s in suites {
        let family = spec.family(s.family());
        let mut must = FamilyCoverage {
            family: s.family(),
            must: 0,
            checked: 0,
            not_observable: 0,
        };
        for req in &family.requirements {
            let row = coverage_row(req, s.cases(), &cases);
            if req.level == Level::Must {
                must.must += 1;
                match row.verdict {
                    Coverage::Pass | Coverage::Fail => must.checked += 1,
                    Coverage::NotObservable => must.not_observable += 1,
                    Coverage::NotRun | Coverage::Untested => {}
                }
            }
            if req.level == Level::Informative && row.cases.is_empty() {
                continue;
            }
            coverage.push(row);
        }
        coverage_summary.push(must);
    }
    let ids: Vec<&str> = suites
        .iter()
        .flat_map(|s| s.cases().iter())
        .filter(|c| {
            Selection::new(&opts.case, &opts.skip, opts.level)
                .is_ok_and(|sel| sel.admits(&c.id, c.level))
        })
        .map(|c| c.id.as_str())
        .collect();
    let stale = expectations.stale(&ids).into_iter().cloned().collect();
    Report {
        schema: report::SCHEMA,
        tool: Tool {
            name: "drivespec".to_owned(),
            version: env!("CARGO_PKG_VERSION").to_owned(),
        },
        run: RunInfo {
            families,
            dut: opts.dut.to_string(),
            transport: transport.to_owned(),
            seed: settings.seed,
            address: settings.address,
            model: settings.model.clone(),
            brake: settings.brake.map(|b| b.spec_name().to_owned()),
            case: opts.case.clone(),
            skip: opts.skip.clone(),
            level: opts.level.as_str().to_owned(),
            expectations: expectations.file.clone(),
        },
        summary: counts,
        cases,
        coverage,
        coverage_summary,
        stale_expectations: stale,
        plot_units: suites.iter().filter_map(|s| s.plot_units()).collect(),
        timing: None,
    }
}

/// The coverage row of `req`: the run cases whose checks evaluated it (Fail when a failure
/// names it), or else the cases that cite it.
fn coverage_row(req: &Requirement, suite: &[CaseInfo], results: &[CaseReport]) -> CoverageRow {
    let checking: Vec<&CaseReport> = results
        .iter()
        .filter(|r| r.checked.contains(&req.id))
        .collect();
    let (verdict, refs) = if checking.is_empty() {
        let refs: Vec<CaseRef> = suite
            .iter()
            .filter(|c| c.requirements.contains(&req.id))
            .map(|c| CaseRef {
                id: c.id.clone(),
                status: results
                    .iter()
                    .find(|r| r.id == c.id)
                    .map_or(Status::NotRun, |r| r.status),
            })
            .collect();
        let ran = refs
            .iter()
            .any(|r| !matches!(r.status, Status::Skipped | Status::NotRun));
        let verdict = if !req.observable {
            Coverage::NotObservable
        } else if refs.is_empty() || ran {
            Coverage::Untested
        } else {
            Coverage::NotRun
        };
        (verdict, refs)
    } else {
        let names = |r: &CaseReport| {
            r.failure
                .as_ref()
                .is_some_and(|f| f.requirements.iter().any(|x| x.id == req.id))
        };
        let verdict = if checking.iter().any(|r| names(r)) {
            Coverage::Fail
        } else {
            Coverage::Pass
        };
        let refs = checking
            .iter()
            .map(|r| CaseRef {
                id: r.id.clone(),
                status: r.status,
            })
            .collect();
        (verdict, refs)
    };
    CoverageRow {
        requirement: req.id.clone(),
        level: req.level,
        text: req.text.clone(),
        verdict,
        cases: refs,
    }
}

/// The report files of a run: JUnit, JSON, HTML.
fn report_paths(opts: &Options) -> [PathBuf; 3] {
    let dir = &opts.report_dir;
    [
        opts.junit
            .clone()
            .unwrap_or_else(|| dir.join("conform.junit.xml")),
        opts.json
            .clone()
            .unwrap_or_else(|| dir.join("conform.json")),
        opts.html
            .clone()
            .unwrap_or_else(|| dir.join("conform.html")),
    ]
}

fn write_reports(opts: &Options, report: &Report) -> Result<Vec<PathBuf>, ConformError> {
    let [junit, json, html] = report_paths(opts);
    let files = [
        (junit, report::junit(report)),
        (json, report.json()),
        (html, report::html(report)),
    ];
    drivespec_report::write_set(&files).map_err(write_error)?;
    Ok(files.into_iter().map(|(p, _)| p).collect())
}

fn write_error(e: drivespec_report::WriteError) -> ConformError {
    ConformError::Write {
        file: e.path.display().to_string(),
        why: e.why.to_string(),
    }
}
