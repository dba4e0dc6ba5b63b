//! JUnit XML (`drivespec_report::junit`): one `<testsuite>` per family and one `<testcase
//! name classname time>` per case; a failure carries `message` and a text with the broken
//! requirement, allowed vs got and the replay command, and the exchange in `<system-out>`;
//! skipped, not-run and known failures are `<skipped>`.

use super::{CaseReport, Report, Status};
use drivespec_report::junit::{self as xml, Case, Document, Outcome, Problem, Suite};
use std::fmt::Write as _;

/// The report as JUnit XML.
pub fn junit(r: &Report) -> String {
    junit_with(r, "drivespec conform", &[])
}

/// The report as JUnit XML under the name `tool` (`drivespec fuzz`), with `properties` added
/// to each test suite's properties.
pub fn junit_with(r: &Report, tool: &str, properties: &[(String, String)]) -> String {
    let suites = r
        .run
        .families
        .iter()
        .map(|family| {
            let mut props: Vec<(String, String)> = vec![
                ("dut".to_owned(), r.run.dut.clone()),
                ("transport".to_owned(), r.run.transport.clone()),
                ("seed".to_owned(), r.run.seed.to_string()),
                ("address".to_owned(), r.run.address.to_string()),
            ];
            props.extend(properties.iter().cloned());
            if r.summary.interrupted {
                props.push(("interrupted".to_owned(), "true".to_owned()));
            }
            Suite {
                name: family.to_string(),
                time_ms: match (r.run.families.len(), r.timing) {
                    (1, Some(t)) => Some(t.wall_ms),
                    _ => None,
                },
                properties: props,
                cases: r
                    .cases
                    .iter()
                    .filter(|c| c.family == *family)
                    .map(|c| case(c, r.summary.interrupted))
                    .collect(),
            }
        })
        .collect();
    Document {
        name: tool.to_owned(),
        timestamp: r.timing.map(|t| xml::timestamp(t.started)),
        hostname: r.timing.map(|_| xml::hostname()),
        suites,
    }
    .to_xml()
}

fn case(c: &CaseReport, interrupted: bool) -> Case {
    let mut parts = c.id.split('/');
    let classname = match (parts.next(), parts.next()) {
        (Some(f), Some(g)) => format!("{f}.{g}"),
        (Some(f), None) => f.to_owned(),
        _ => String::new(),
    };
    let mut output = None;
    let outcome = match c.status {
        Status::Pass => Outcome::Passed,
        Status::Acceptable => {
            output = Some(
                c.findings
                    .iter()
                    .map(|f| format!("acceptable: {}\n", f.line()))
                    .collect(),
            );
            Outcome::Passed
        }
        Status::Fixed => {
            output = Some(format!(
                "passes although the expectations file lists it as a known failure ({}); remove the entry",
                c.expectation.as_deref().unwrap_or("")
            ));
            Outcome::Passed
        }
        Status::ExpectedFailure => Outcome::Skipped(format!(
            "known failure: {}",
            c.expectation.as_deref().unwrap_or("")
        )),
        Status::NotRun if interrupted => {
            Outcome::Skipped("not run: the run was interrupted".to_owned())
        }
        Status::NotRun => Outcome::Skipped("not run: --fail-fast stopped the run".to_owned()),
        Status::Skipped => Outcome::Skipped(c.skip_reason.clone().unwrap_or_default()),
        Status::Flaky => Outcome::Flaky(Problem {
            message: c.failure.as_ref().map_or_else(
                || "failed, then passed when run again".to_owned(),
                |f| format!("failed, then passed when run again: {}", f.message),
            ),
            kind: "mismatch".to_owned(),
            text: Some(failure_text(c)),
        }),
        Status::Fail => {
            let message = match &c.failure {
                Some(f) => match f.broken() {
                    Some(r) => format!("breaks {}: {}", r.id, f.message),
                    None => f.message.clone(),
                },
                None => "failed".to_owned(),
            };
            let log = exchange_text(c);
            output = (!log.is_empty()).then_some(log);
            Outcome::Failed(Problem {
                message,
                kind: "mismatch".to_owned(),
                text: Some(failure_text(c)),
            })
        }
    };
    Case {
        name: c.id.clone(),
        classname,
        time_ms: c.wall_ms,
        outcome,
        output,
    }
}

/// The failure text: the broken requirement, allowed vs got, the other requirements cited,
/// the replay command.
fn failure_text(c: &CaseReport) -> String {
    let mut t = String::new();
    if let Some(f) = &c.failure {
        for l in f.headline() {
            let _ = writeln!(t, "{l}");
        }
        if f.requirements.len() > 1 {
            t.push_str("also cited:\n");
            for r in f.requirements.iter().skip(1) {
                let _ = writeln!(t, "  {} ({}): {}", r.id, r.level.as_str(), r.text);
            }
        }
    }
    if let Some(r) = &c.replay {
        let _ = writeln!(t, "replay: {r}");
    }
    t
}

/// The exchange of a case, step by step: what was sent, expected and got.
fn exchange_text(c: &CaseReport) -> String {
    let mut t = String::new();
    if !c.evidence.is_empty() {
        t.push_str("exchange:\n");
        for e in &c.evidence {
            let mark = match e.ok {
                Some(true) => "ok ",
                Some(false) => "BAD",
                None => "   ",
            };
            let _ = writeln!(t, "  {mark} #{} {:?} {}", e.step, e.role, e.action);
            if let Some(s) = &e.sent {
                let _ = writeln!(t, "        sent     {s}");
            }
            if let Some(a) = &e.expected {
                let _ = writeln!(
                    t,
                    "        expected {}",
                    if a.is_silence() { "silence" } else { &a.hex }
                );
            }
            if let Some(a) = &e.got {
                let _ = writeln!(
                    t,
                    "        got      {}",
                    if a.is_silence() { "silence" } else { &a.hex }
                );
            }
            if let Some(n) = &e.note {
                let _ = writeln!(t, "        note     {n}");
            }
        }
    }
    t
}
