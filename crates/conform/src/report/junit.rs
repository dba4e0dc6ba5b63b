//! JUnit XML in the form GitHub and GitLab test reporters read: `<testsuites>` with one
//! `<testsuite>` per family and one `<testcase name classname time>` per case; failures
//! carry `message` and a text with expected vs got, the requirements, the exchange and the
//! replay command; skipped and known failures are `<skipped>`.

use super::{escape, CaseReport, Report, Status};
use std::fmt::Write as _;

/// The report as JUnit XML.
pub fn junit(r: &Report) -> String {
    junit_with(r, "drivespec conform", &[])
}

/// The report as JUnit XML under the name `tool` (`drivespec fuzz`), with `properties` added
/// to each test suite's properties.
pub fn junit_with(r: &Report, tool: &str, properties: &[(String, String)]) -> String {
    let mut x = String::new();
    x.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let time = |cases: &[&CaseReport]| cases.iter().map(|c| c.wall_ms).sum::<f64>() / 1000.0;
    let all: Vec<&CaseReport> = r.cases.iter().collect();
    let fails = |cases: &[&CaseReport]| cases.iter().filter(|c| c.status == Status::Fail).count();
    let skips = |cases: &[&CaseReport]| {
        cases
            .iter()
            .filter(|c| {
                matches!(
                    c.status,
                    Status::Skipped | Status::NotRun | Status::ExpectedFailure
                )
            })
            .count()
    };
    let _ = writeln!(
        x,
        "<testsuites name=\"{}\" tests=\"{}\" failures=\"{}\" errors=\"0\" skipped=\"{}\" time=\"{:.3}\">",
        escape(tool),
        all.len(),
        fails(&all),
        skips(&all),
        time(&all)
    );
    for family in &r.run.families {
        let cases: Vec<&CaseReport> = r.cases.iter().filter(|c| c.family == *family).collect();
        let _ = writeln!(
            x,
            "  <testsuite name=\"{family}\" tests=\"{}\" failures=\"{}\" errors=\"0\" skipped=\"{}\" time=\"{:.3}\">",
            cases.len(),
            fails(&cases),
            skips(&cases),
            time(&cases)
        );
        x.push_str("    <properties>\n");
        for (k, v) in [
            ("dut", r.run.dut.clone()),
            ("transport", r.run.transport.clone()),
            ("seed", r.run.seed.to_string()),
            ("address", r.run.address.to_string()),
        ] {
            let _ = writeln!(x, "      <property name=\"{k}\" value=\"{}\"/>", escape(&v));
        }
        for (k, v) in properties {
            let _ = writeln!(
                x,
                "      <property name=\"{}\" value=\"{}\"/>",
                escape(k),
                escape(v)
            );
        }
        x.push_str("    </properties>\n");
        for c in cases {
            case(&mut x, c);
        }
        x.push_str("  </testsuite>\n");
    }
    x.push_str("</testsuites>\n");
    x
}

fn case(x: &mut String, c: &CaseReport) {
    let mut parts = c.id.split('/');
    let classname = match (parts.next(), parts.next()) {
        (Some(f), Some(g)) => format!("{f}.{g}"),
        (Some(f), None) => f.to_owned(),
        _ => String::new(),
    };
    let _ = write!(
        x,
        "    <testcase name=\"{}\" classname=\"{}\" time=\"{:.3}\"",
        escape(&c.id),
        escape(&classname),
        c.wall_ms / 1000.0
    );
    match c.status {
        Status::Pass => x.push_str("/>\n"),
        Status::Fixed => {
            let _ = writeln!(
                x,
                ">\n      <system-out>{}</system-out>\n    </testcase>",
                escape(&format!(
                    "passes although the expectations file lists it as a known failure ({}); remove the entry",
                    c.expectation.as_deref().unwrap_or("")
                ))
            );
        }
        Status::Skipped | Status::NotRun | Status::ExpectedFailure => {
            let msg = match c.status {
                Status::ExpectedFailure => {
                    format!("known failure: {}", c.expectation.as_deref().unwrap_or(""))
                }
                Status::NotRun => "not run: --fail-fast stopped the run".to_owned(),
                _ => c.skip_reason.clone().unwrap_or_default(),
            };
            let _ = writeln!(
                x,
                ">\n      <skipped message=\"{}\"/>\n    </testcase>",
                escape(&msg)
            );
        }
        Status::Fail => {
            let (message, body) = match &c.failure {
                Some(f) => (f.message.clone(), failure_text(c)),
                None => ("failed".to_owned(), String::new()),
            };
            let _ = writeln!(
                x,
                ">\n      <failure message=\"{}\" type=\"mismatch\">{}</failure>\n    </testcase>",
                escape(&message),
                escape(&body)
            );
        }
    }
}

/// The failure text: expected vs got, requirements, the exchange, the replay command.
pub(crate) fn failure_text(c: &CaseReport) -> String {
    let mut t = String::new();
    if let Some(f) = &c.failure {
        let _ = writeln!(t, "{}", f.message);
        let _ = writeln!(t, "expected: {}", f.expected);
        let _ = writeln!(t, "got:      {}", f.got);
        if !f.requirements.is_empty() {
            t.push_str("requirements:\n");
            for r in &f.requirements {
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
