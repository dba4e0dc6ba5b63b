//! A self-contained HTML report (no scripts, no external resources): the summary with a link
//! to every failure, then per family every case with its evidence (failures first and open,
//! then known failures, flaky and acceptable cases, passes, cases not run), then the
//! requirement coverage matrix (requirement → cases → verdict).

use super::{CaseReport, Coverage, PlotUnits, Report, Status};
use drivespec_report::escape;
use drivespec_report::html::anchor;
use drivespec_report::plot;
use drivespec_spec::FamilyId;
use std::fmt::Write as _;

const STYLE: &str = "body{font:14px/1.4 system-ui,sans-serif;margin:2em;color:#222}\
h1{font-size:1.5em}h2{font-size:1.2em;margin-top:2em}\
table{border-collapse:collapse;margin:.5em 0}td,th{border:1px solid #ccc;padding:.2em .5em;vertical-align:top;text-align:left}\
.pass{color:#176f2c}.acceptable{color:#2d6a8f}.fail{color:#b00020;font-weight:bold}.expected-failure{color:#a15c00}.fixed{color:#0057b3}\
.skipped,.not-run,.untested{color:#777}code,pre{font:12px ui-monospace,monospace}pre{white-space:pre-wrap;margin:0}\
details{margin:.3em 0;border-left:3px solid #ddd;padding-left:.6em}summary{cursor:pointer}\
.bad{background:#fde8ea}.muted{color:#777}svg.plot{display:block;max-width:100%;height:auto}";

/// The report as one HTML page.
pub fn html(r: &Report) -> String {
    html_with(r, "drivespec conform", "")
}

/// The report as one HTML page titled `tool` (`drivespec fuzz`), with `extra` (HTML, escaped
/// by the caller) after the summary tables.
pub fn html_with(r: &Report, tool: &str, extra: &str) -> String {
    let mut h = String::new();
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{}: {}</title><style>{STYLE}</style></head><body>\n<section id=\"summary\">\n",
        escape(tool),
        escape(&r.run.dut)
    );
    let s = &r.summary;
    let verdict = if s.exit_code == 0 { "pass" } else { "fail" };
    let families: Vec<String> = r.run.families.iter().map(|f| f.to_string()).collect();
    let _ = writeln!(
        h,
        "<h1>{} {}: <span class=\"{verdict}\">{}</span></h1>",
        escape(tool),
        escape(&families.join(", ")),
        verdict.to_uppercase()
    );
    let _ = writeln!(
        h,
        "<table><tr><th>device under test</th><td><code>{}</code> ({})</td></tr><tr><th>seed</th><td>{}</td></tr><tr><th>address</th><td>{}</td></tr><tr><th>selection</th><td>level {}{}{}</td></tr><tr><th>expectations</th><td>{}</td></tr><tr><th>tool</th><td>{} {}</td></tr></table>",
        escape(&r.run.dut),
        escape(&r.run.transport),
        r.run.seed,
        r.run.address,
        escape(&r.run.level),
        if r.run.case.is_empty() { String::new() } else { format!("; --case {}", escape(&r.run.case.join(" "))) },
        if r.run.skip.is_empty() { String::new() } else { format!("; --skip {}", escape(&r.run.skip.join(" "))) },
        escape(r.run.expectations.as_deref().unwrap_or("none")),
        escape(&r.tool.name),
        escape(&r.tool.version),
    );
    let _ = writeln!(
        h,
        "<table><tr><th>cases</th><th class=\"pass\">pass</th><th class=\"acceptable\">of which acceptable</th><th class=\"fail\">fail</th><th class=\"expected-failure\">expected failures</th><th class=\"fixed\">fixed</th><th class=\"skipped\">skipped</th><th class=\"not-run\">not run</th></tr><tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr></table>",
        s.total, s.passed, s.acceptable, s.failed, s.expected_failures, s.fixed, s.skipped, s.not_run
    );
    if s.interrupted {
        h.push_str("<p class=\"fail\">interrupted: the run was stopped before its end; the cases it did not reach are not run</p>\n");
    }
    for k in &r.stale_expectations {
        let _ = writeln!(
            h,
            "<p class=\"muted\">expectations entry <code>{}</code> matches no selected case ({})</p>",
            escape(&k.case),
            escape(&k.reason)
        );
    }

    for c in &r.coverage_summary {
        let _ = writeln!(
            h,
            "<p>coverage {}: {} of {} <code>must</code> requirements checked, {} not observable over the interface</p>",
            escape(&c.family.to_string()),
            c.checked,
            c.must,
            c.not_observable
        );
    }
    h.push_str(extra);
    failure_list(&mut h, r);
    h.push_str("</section>\n");
    let mut families: Vec<FamilyId> = Vec::new();
    for c in &r.cases {
        if !families.contains(&c.family) {
            families.push(c.family);
        }
    }
    for family in families {
        let units = r.plot_units.iter().find(|u| u.family == family);
        let _ = writeln!(
            h,
            "<h2 id=\"cases-{}\">Cases: {}</h2>",
            anchor(&family.to_string()),
            escape(&family.to_string())
        );
        let mut cases: Vec<&CaseReport> = r.cases.iter().filter(|c| c.family == family).collect();
        cases.sort_by_key(|c| rank(c.status));
        for c in cases {
            case(&mut h, c, units);
        }
    }
    h.push_str("<h2>Requirement coverage</h2>\n<table><tr><th>requirement</th><th>level</th><th>verdict</th><th>cases</th><th>text</th></tr>\n");
    for row in &r.coverage {
        let v = match row.verdict {
            Coverage::Pass => "pass",
            Coverage::Fail => "fail",
            Coverage::NotRun => "not-run",
            Coverage::Untested => "untested",
            Coverage::NotObservable => "not-observable",
        };
        let cases: Vec<String> = row
            .cases
            .iter()
            .map(|c| {
                format!(
                    "<a href=\"#{}\" class=\"{}\">{}</a>",
                    anchor(&c.id),
                    c.status.as_str(),
                    escape(&c.id)
                )
            })
            .collect();
        let cases = if cases.len() > 12 {
            let shown = cases.iter().take(12).cloned().collect::<Vec<_>>().join(" ");
            format!(
                "<details><summary>{} cases</summary>{}</details>",
                cases.len(),
                [
                    shown,
                    cases.iter().skip(12).cloned().collect::<Vec<_>>().join(" ")
                ]
                .join(" ")
            )
        } else {
            cases.join(" ")
        };
        let _ = writeln!(
            h,
            "<tr><td><code>{}</code></td><td>{}</td><td class=\"{v}\">{v}</td><td>{cases}</td><td>{}</td></tr>",
            escape(&row.requirement),
            row.level.as_str(),
            escape(&row.text)
        );
    }
    h.push_str("</table>\n");
    h.push_str("</body></html>\n");
    h
}

/// Where a case stands in its family's list: failures first, passes late, cases not run last.
fn rank(s: Status) -> u8 {
    match s {
        Status::Fail => 0,
        Status::ExpectedFailure => 1,
        Status::Fixed => 2,
        Status::Flaky => 3,
        Status::Acceptable => 4,
        Status::Pass => 5,
        Status::Skipped => 6,
        Status::NotRun => 7,
    }
}

/// The failures of the run (then the known failures and the fixed cases), each a link to
/// its case with the reason in one line.
fn failure_list(h: &mut String, r: &Report) {
    for (status, title) in [
        (Status::Fail, "Failures"),
        (Status::ExpectedFailure, "Known failures"),
        (
            Status::Fixed,
            "Fixed (listed as known failures, now passing)",
        ),
    ] {
        let cases: Vec<&CaseReport> = r.cases.iter().filter(|c| c.status == status).collect();
        if cases.is_empty() {
            continue;
        }
        let _ = writeln!(
            h,
            "<h2>{title} ({})</h2>\n<ol class=\"{}-list\">",
            cases.len(),
            status.as_str()
        );
        for c in cases {
            let why = c.failure.as_ref().map_or("", |f| f.message.as_str());
            let _ = writeln!(
                h,
                "<li><a href=\"#{}\" class=\"{}\">{}</a> {}</li>",
                anchor(&c.id),
                status.as_str(),
                escape(&c.id),
                escape(why)
            );
        }
        h.push_str("</ol>\n");
    }
}

fn case(h: &mut String, c: &CaseReport, units: Option<&PlotUnits>) {
    let open = if c.status == Status::Fail {
        " open"
    } else {
        ""
    };
    let _ = writeln!(
        h,
        "<details id=\"{}\"{open}><summary><span class=\"{}\">{}</span> <code>{}</code> ({}) {}</summary>",
        anchor(&c.id),
        c.status.as_str(),
        c.status.as_str(),
        escape(&c.id),
        c.level.as_str(),
        escape(&c.description)
    );
    if let Some(f) = &c.failure {
        if let Some(r) = f.broken() {
            let _ = writeln!(
                h,
                "<p class=\"fail\">breaks <code>{}</code> ({}): {}</p>",
                escape(&r.id),
                escape(&r.source),
                escape(&r.text)
            );
        }
        let _ = writeln!(
            h,
            "<p class=\"fail\">{}</p><table><tr><th>allowed</th><td><code>{}</code></td></tr><tr><th>got</th><td><code>{}</code></td></tr></table>",
            escape(&f.message),
            escape(&f.expected),
            escape(&f.got)
        );
        for r in &f.requirements {
            let _ = writeln!(
                h,
                "<p><code>{}</code> ({}): {}</p>",
                escape(&r.id),
                r.level.as_str(),
                escape(&r.text)
            );
        }
    }
    for f in &c.findings {
        let _ = writeln!(
            h,
            "<p class=\"acceptable\">acceptable: {}</p>",
            escape(&f.line())
        );
    }
    if let Some(e) = &c.expectation {
        let _ = writeln!(
            h,
            "<p class=\"expected-failure\">known failure: {}</p>",
            escape(e)
        );
    }
    if let Some(s) = &c.skip_reason {
        let _ = writeln!(h, "<p class=\"skipped\">skipped: {}</p>", escape(s));
    }
    if let Some(r) = &c.replay {
        let _ = writeln!(h, "<p>replay: <code>{}</code></p>", escape(r));
    }
    let _ = writeln!(
        h,
        "<p class=\"muted\">requirements: {}</p>",
        escape(&c.requirements.join(", "))
    );
    // Positioning cases: position/speed/status over time, reference vs device (inline SVG).
    for e in c.evidence.iter().filter(|e| e.action == plot::ACTION) {
        let units = plot::Units {
            position: units.map_or("raw", |u| u.position.as_str()),
            speed: units.map_or("raw", |u| u.speed.as_str()),
        };
        if let Some(svg) = e.note.as_deref().and_then(|n| plot::svg(n, units)) {
            let _ = writeln!(h, "<figure>{svg}</figure>");
        }
    }
    if !c.evidence.is_empty() && c.status != Status::Pass {
        h.push_str("<table><tr><th>#</th><th>role</th><th>step</th><th>sent</th><th>reference</th><th>device</th><th>note</th></tr>\n");
        for e in &c.evidence {
            let class = if e.ok == Some(false) {
                " class=\"bad\""
            } else {
                ""
            };
            let ans = |a: &Option<crate::case::Answer>| match a {
                Some(a) if a.is_silence() => "silence".to_owned(),
                Some(a) => format!(
                    "<code>{}</code><br><span class=\"muted\">{}{}</span>",
                    escape(&a.hex),
                    escape(&a.text),
                    a.delay_us
                        .map(|d| format!(", after {d} µs"))
                        .unwrap_or_default()
                ),
                None => String::new(),
            };
            let _ = writeln!(
                h,
                "<tr{class}><td>{}</td><td>{:?}</td><td>{}</td><td><code>{}</code><br><span class=\"muted\">{}</span></td><td>{}</td><td>{}</td><td>{}</td></tr>",
                e.step,
                e.role,
                escape(&e.action),
                escape(e.sent.as_deref().unwrap_or("")),
                escape(e.sent_text.as_deref().unwrap_or("")),
                ans(&e.expected),
                ans(&e.got),
                escape(e.note.as_deref().unwrap_or(""))
            );
        }
        h.push_str("</table>\n");
    }
    h.push_str("</details>\n");
}
