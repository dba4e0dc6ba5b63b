//! JUnit XML in the form GitHub and GitLab test reporters read: `<testsuites>` with one
//! `<testsuite>` per family and one `<testcase name classname time>` per case; failures
//! carry `message` and a text with expected vs got, the requirements, the exchange and the
//! replay command; skipped and known failures are `<skipped>`.

use super::{CaseReport, Report, Status};
use drivespec_report::junit::{Case, Document, Form, Outcome, Suite};
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
            Suite {
                name: family.to_string(),
                properties: props,
                cases: r
                    .cases
                    .iter()
                    .filter(|c| c.family == *family)
                    .map(case)
                    .collect(),
            }
        })
        .collect();
    Document {
        name: tool.to_owned(),
        form: Form::Timed,
        suites,
    }
    .to_xml()
}

fn case(c: &CaseReport) -> Case {
    let mut parts = c.id.split('/');
    let classname = match (parts.next(), parts.next()) {
        (Some(f), Some(g)) => format!("{f}.{g}"),
        (Some(f), None) => f.to_owned(),
        _ => String::new(),
    };
    let outcome = match c.status {
        Status::Pass => Outcome::Passed,
        Status::Acceptable => Outcome::PassedWithOutput(
            c.findings
                .iter()
                .map(|f| format!("acceptable: {}\n", f.line()))
                .collect(),
        ),
        Status::Fixed => Outcome::PassedWithOutput(format!(
            "passes although the expectations file lists it as a known failure ({}); remove the entry",
            c.expectation.as_deref().unwrap_or("")
        )),
        Status::ExpectedFailure => Outcome::Skipped(format!(
            "known failure: {}",
            c.expectation.as_deref().unwrap_or("")
        )),
        Status::NotRun => Outcome::Skipped("not run: --fail-fast stopped the run".to_owned()),
        Status::Skipped => Outcome::Skipped(c.skip_reason.clone().unwrap_or_default()),
        Status::Fail => {
            let (message, text) = match &c.failure {
                Some(f) => (
                    match f.broken() {
                        Some(r) => format!("breaks {}: {}", r.id, f.message),
                        None => f.message.clone(),
                    },
                    failure_text(c),
                ),
                None => ("failed".to_owned(), String::new()),
            };
            Outcome::Failed {
                message,
                kind: "mismatch".to_owned(),
                text: Some(text),
            }
        }
    };
    Case {
        name: c.id.clone(),
        classname,
        time_ms: c.wall_ms,
        outcome,
    }
}

/// The failure text: expected vs got, requirements, the exchange, the replay command.
pub(crate) fn failure_text(c: &CaseReport) -> String {
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
    if let Some(r) = &c.replay {
        let _ = writeln!(t, "replay: {r}");
    }
    t
}
