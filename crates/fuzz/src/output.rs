//! Fuzz reports in the conformance runner's formats (README "Fuzz reports"): every finding
//! is a failing case of the conform report model, with its minimised exchange as evidence
//! and the replay command; the JSON adds a `fuzz` section with the statistics, the HTML a
//! statistics section, the JUnit file properties.

use crate::engine::Found;
use crate::replay::Replay;
use crate::stats::Stats;
use drivespec_conform::case::{CaseRun, Failure, RequirementRef};
use drivespec_conform::report::{
    self, CaseRef, CaseReport, Counts, Coverage, CoverageRow, FamilyCoverage, Report, RunInfo,
    Status, Tool,
};
use drivespec_spec::{FamilyId, Level};
use serde::Serialize;
use std::fmt::Write as _;

/// A finding as the reports show it.
#[derive(Debug, Clone)]
pub struct Finding {
    /// Case ID in the reports (`hpd/fuzz/finding-1`).
    pub id: String,
    /// The replay (minimised sequence, exchanges, finding).
    pub replay: Replay,
    /// The run that confirmed it: evidence and failure.
    pub run: CaseRun,
    /// The failure at the failing step.
    pub failure: Failure,
    /// Failing sequences that showed the same bug.
    pub occurrences: u64,
    /// Where the replay file was written.
    pub file: Option<std::path::PathBuf>,
}

impl Finding {
    pub(crate) fn new(id: String, found: &Found, replay: Replay) -> Finding {
        Finding {
            id,
            replay,
            run: found.trial.run.clone(),
            failure: found.fault.failure.clone(),
            occurrences: found.occurrences,
            file: None,
        }
    }
}

/// The JSON report: the conform report plus the `fuzz` section.
#[derive(Serialize)]
struct FuzzJson<'r> {
    #[serde(flatten)]
    report: &'r Report,
    fuzz: &'r Stats,
}

/// The JSON report text.
pub fn json(report: &Report, stats: &Stats) -> String {
    drivespec_report::json(&FuzzJson {
        report,
        fuzz: stats,
    })
}

/// What the report header says about the run.
pub(crate) struct RunDesc<'x> {
    pub(crate) family: FamilyId,
    pub(crate) dut: String,
    pub(crate) transport: String,
    pub(crate) seed: u64,
    pub(crate) address: u8,
    pub(crate) model: Option<String>,
    pub(crate) replay_cmd: &'x dyn Fn(&Finding) -> Option<String>,
}

/// The conform report model of a campaign.
pub(crate) fn build(
    desc: &RunDesc<'_>,
    findings: &[Finding],
    stats: &Stats,
    reqs: &dyn Fn(&str) -> Option<RequirementRef>,
    all_reqs: &[(String, Level)],
) -> Report {
    let mut cases: Vec<CaseReport> = Vec::new();
    for f in findings {
        let mut ids: Vec<String> = f
            .replay
            .steps
            .iter()
            .flat_map(|s| s.requirements.iter().cloned())
            .chain(f.failure.requirements.iter().map(|r| r.id.clone()))
            .filter(|id| reqs(id).is_some())
            .collect();
        ids.sort();
        ids.dedup();
        let level = if f
            .failure
            .requirements
            .iter()
            .any(|r| r.level == Level::Must)
            || f.failure.requirements.is_empty()
        {
            Level::Must
        } else {
            Level::Should
        };
        let info = f.replay.finding.as_ref();
        let description = match info {
            Some(i) => format!(
                "{} ({}): {} step(s), minimised from {}; seen {} time(s)",
                i.signature,
                i.class.as_str(),
                f.replay.steps.len(),
                i.original_steps,
                f.occurrences
            ),
            None => "a fuzz sequence".to_owned(),
        };
        cases.push(CaseReport {
            id: f.id.clone(),
            family: desc.family,
            level,
            description,
            requirements: ids,
            status: Status::Fail,
            failure: Some(f.failure.clone()),
            skip_reason: None,
            checked: f
                .failure
                .requirements
                .first()
                .map(|r| vec![r.id.clone()])
                .unwrap_or_default(),
            findings: Vec::new(),
            expectation: None,
            evidence: f.run.evidence.clone(),
            replay: (desc.replay_cmd)(f),
            wall_ms: 0.0,
            elapsed_us: f.run.elapsed_us,
        });
    }
    let touched: Vec<String> = stats.requirements_touched.keys().cloned().collect();
    if findings.is_empty() {
        cases.push(CaseReport {
            id: format!("{}/fuzz/campaign", desc.family),
            family: desc.family,
            level: Level::Must,
            description: format!(
                "{} sequence(s), {} input(s): no finding",
                stats.sequences, stats.inputs
            ),
            requirements: touched.clone(),
            status: Status::Pass,
            failure: None,
            skip_reason: None,
            checked: touched.clone(),
            findings: Vec::new(),
            expectation: None,
            evidence: Vec::new(),
            replay: None,
            wall_ms: stats.wall_ms,
            elapsed_us: 0,
        });
    }
    let mut coverage = Vec::new();
    for (id, level) in all_reqs {
        let Some(r) = reqs(id) else { continue };
        let citing: Vec<CaseRef> = cases
            .iter()
            .filter(|c| c.requirements.contains(id))
            .map(|c| CaseRef {
                id: c.id.clone(),
                status: c.status,
            })
            .collect();
        let verdict = if citing.iter().any(|c| c.status == Status::Fail) {
            Coverage::Fail
        } else if touched.contains(id) {
            Coverage::Pass
        } else {
            Coverage::Untested
        };
        coverage.push(CoverageRow {
            requirement: id.clone(),
            level: *level,
            text: r.text,
            verdict,
            cases: citing,
        });
    }
    let failed = findings.len();
    let must: Vec<&CoverageRow> = coverage.iter().filter(|r| r.level == Level::Must).collect();
    let coverage_summary = vec![FamilyCoverage {
        family: desc.family,
        must: must.len(),
        checked: must
            .iter()
            .filter(|r| matches!(r.verdict, Coverage::Pass | Coverage::Fail))
            .count(),
        not_observable: 0,
    }];
    Report {
        schema: report::SCHEMA,
        tool: Tool {
            name: "drivespec".to_owned(),
            version: env!("CARGO_PKG_VERSION").to_owned(),
        },
        run: RunInfo {
            families: vec![desc.family],
            dut: desc.dut.clone(),
            transport: desc.transport.clone(),
            seed: desc.seed,
            address: desc.address,
            model: desc.model.clone(),
            brake: None,
            case: Vec::new(),
            skip: Vec::new(),
            level: "should".to_owned(),
            expectations: None,
        },
        summary: Counts {
            total: cases.len(),
            passed: cases.len() - failed,
            failed,
            exit_code: u8::from(failed > 0),
            ..Counts::default()
        },
        cases,
        coverage,
        coverage_summary,
        stale_expectations: Vec::new(),
        plot_units: Vec::new(),
        timing: None,
    }
}

/// The statistics as an HTML section.
pub(crate) fn html_section(stats: &Stats) -> String {
    let e = drivespec_report::escape;
    let mut h = String::new();
    h.push_str("<h2>Fuzzing</h2>\n<table>");
    for (k, v) in [
        ("sequences", stats.sequences.to_string()),
        ("inputs", stats.inputs.to_string()),
        ("failing sequences", stats.failing_sequences.to_string()),
        ("findings", stats.findings.len().to_string()),
        ("device restarts", stats.restarts.to_string()),
        ("minimisation runs", stats.minimisation_runs.to_string()),
        ("stopped by", stats.stopped_by.clone()),
        ("wall time", format!("{:.0} ms", stats.wall_ms)),
    ] {
        let _ = write!(h, "<tr><th>{}</th><td>{}</td></tr>", e(k), e(&v));
    }
    h.push_str("</table>\n");
    if !stats.findings.is_empty() {
        h.push_str("<table><tr><th>finding</th><th>class</th><th>signature</th><th>steps</th><th>seen</th><th>replay file</th></tr>\n");
        for f in &stats.findings {
            let _ = writeln!(
                h,
                "<tr><td><a href=\"#{}\">{}</a></td><td class=\"fail\">{}</td><td><code>{}</code></td><td>{} (from {})</td><td>{}</td><td><code>{}</code></td></tr>",
                drivespec_report::html::anchor(&f.id),
                e(&f.id),
                f.class.as_str(),
                e(&f.signature),
                f.steps,
                f.original_steps,
                f.occurrences,
                e(f.file.as_deref().unwrap_or(""))
            );
        }
        h.push_str("</table>\n");
    }
    let table = |h: &mut String, title: &str, rows: &mut dyn Iterator<Item = (String, u64)>| {
        let _ = write!(h, "<h3>{}</h3><table>", e(title));
        for (k, v) in rows {
            let _ = write!(h, "<tr><td><code>{}</code></td><td>{v}</td></tr>", e(&k));
        }
        h.push_str("</table>\n");
    };
    table(
        &mut h,
        "Inputs by class",
        &mut stats.inputs_by_class.iter().map(|(k, v)| (k.clone(), *v)),
    );
    table(
        &mut h,
        "Answers by verdict",
        &mut stats
            .answers_by_verdict
            .iter()
            .map(|(k, v)| (k.clone(), *v)),
    );
    let _ = writeln!(
        h,
        "<p class=\"muted\">{} requirement(s) touched; not touched: {}</p>",
        stats.requirements_touched.len(),
        e(&stats.requirements_not_touched.join(", "))
    );
    h
}

/// The statistics as JUnit properties.
pub(crate) fn junit_properties(stats: &Stats) -> Vec<(String, String)> {
    vec![
        ("fuzz.sequences".to_owned(), stats.sequences.to_string()),
        ("fuzz.inputs".to_owned(), stats.inputs.to_string()),
        ("fuzz.findings".to_owned(), stats.findings.len().to_string()),
        ("fuzz.stopped_by".to_owned(), stats.stopped_by.clone()),
    ]
}
