//! Reports for people and tools: a text summary, JSON (schema `drivespec-check/1`, crate
//! README), JUnit XML (one test case per requirement checked) and a self-contained HTML page
//! with a timeline plot (inline SVG) per positioning drive. Output size is bounded by the
//! reports (violation listing cap, bounded timelines). Nothing here panics.

use crate::report::{format_time, Observation, Report, Verdict, SCHEMA};
use crate::timeline::Timeline;
use drivespec_report::escape as xml;
use drivespec_report::junit::{self as xml_junit, Case, Outcome, Problem, Suite};
use drivespec_report::svg::polyline;
use serde::Serialize;
use std::fmt::Write as _;

/// The JSON document of one run: every file's report.
#[derive(Debug, Serialize)]
pub struct Document<'a> {
    /// `drivespec-check/1`.
    pub schema: &'static str,
    /// Violations counted over all files.
    pub violation_count: u64,
    /// `must` violations counted over all files.
    pub must_count: u64,
    /// Warnings (violations of other levels) counted over all files.
    pub warning_count: u64,
    /// Files whose verdict is `fail`.
    pub failed: u64,
    /// Files whose reading stopped early.
    pub unreadable: u64,
    /// One report per file, in the order checked (`drivespec check` sorts by path).
    pub reports: &'a [Report],
}

/// The JSON document of `reports`.
pub fn json(reports: &[Report]) -> String {
    let doc = Document {
        schema: SCHEMA,
        violation_count: reports.iter().map(|r| r.violation_count).sum(),
        must_count: reports.iter().map(Report::must_count).sum(),
        warning_count: reports
            .iter()
            .map(|r| r.violation_count.saturating_sub(r.must_count()))
            .sum(),
        failed: reports
            .iter()
            .filter(|r| r.verdict == Verdict::Fail)
            .count() as u64,
        unreadable: reports.iter().filter(|r| r.error.is_some()).count() as u64,
        reports,
    };
    drivespec_report::json(&doc)
}

fn stats_line(s: &crate::report::Stats) -> String {
    if s.count == 0 {
        return "-".into();
    }
    format!(
        "mean {:.1} µs, min {:.1}, max {:.1}, σ {:.1}",
        s.mean, s.min, s.max, s.stddev
    )
}

/// The text summary of `reports`.
pub fn text(reports: &[Report]) -> String {
    let mut o = String::new();
    for r in reports {
        let _ = writeln!(
            o,
            "{} [{}]",
            r.file.as_deref().unwrap_or("(stream)"),
            r.family
        );
        for d in &r.detection {
            let _ = writeln!(o, "  detected: {d}");
        }
        let kinds: Vec<String> = r.frames.iter().map(|(k, n)| format!("{k} {n}")).collect();
        let _ = writeln!(o, "  events: {}; {}", r.events, kinds.join(", "));
        for d in &r.drives {
            let _ = writeln!(
                o,
                "  drive: {} (found by {}, confidence {:.2})",
                d.label, d.found_by, d.confidence
            );
        }
        if !r.streams.is_empty() {
            let _ = writeln!(o, "  timing:");
            for s in r.streams.iter().take(50) {
                let nominal = s
                    .nominal_us
                    .map_or(String::new(), |n| format!(", nominal {n:.1} µs"));
                let jitter = s
                    .jitter_us
                    .as_ref()
                    .filter(|j| j.count > 0)
                    .map_or(String::new(), |j| format!(", jitter max {:.1} µs", j.max));
                let missing = if s.missing > 0 {
                    format!(", {} missing in {} gap(s)", s.missing, s.gaps)
                } else {
                    String::new()
                };
                let _ = writeln!(
                    o,
                    "    {}: {} frames, interval {}{nominal}{jitter}{missing}",
                    s.stream,
                    s.frames,
                    stats_line(&s.interval_us)
                );
            }
            if r.streams.len() > 50 {
                let _ = writeln!(o, "    … {} more streams", r.streams.len() - 50);
            }
        }
        let checked = r.requirements.len();
        let must = r.must_count();
        let _ = writeln!(
            o,
            "  requirements checked: {checked}; violations: {} ({must} must, {} warning(s)); allowed states: {}; inconclusive: {}",
            r.violation_count,
            r.violation_count.saturating_sub(must),
            r.allowed_count,
            r.inconclusive_count
        );
        for (id, t) in r.requirements.iter().filter(|(_, t)| t.violations > 0) {
            let _ = writeln!(
                o,
                "    {id:<22} {:>6} × [{}] {}",
                t.violations, t.level, t.text
            );
        }
        if !r.violations.is_empty() {
            let listed = r.violations.len() as u64;
            let capped = if listed < r.violation_count {
                format!(" (first {listed} of {})", r.violation_count)
            } else {
                String::new()
            };
            let _ = writeln!(o, "  violations{capped}:");
            for v in &r.violations {
                let until = match (&v.end, v.duration_us) {
                    (Some(e), Some(d)) => format!(" (until {e}: {})", duration(d)),
                    (Some(e), None) => format!(" (until {e})"),
                    (None, _) => String::new(),
                };
                let _ = writeln!(
                    o,
                    "    {} {} — {}: {}{until}",
                    v.at, v.requirement, v.subject, v.message
                );
                if let Some(b) = &v.evidence.bytes {
                    let _ = writeln!(o, "        bytes: {b}");
                }
                for (k, val) in &v.evidence.fields {
                    let _ = writeln!(
                        o,
                        "        {k}: {}",
                        val.as_str().map_or_else(|| val.to_string(), str::to_owned)
                    );
                }
            }
            for (id, t) in &r.requirements {
                let shown = r.violations.iter().filter(|v| v.requirement == *id).count() as u64;
                if t.violations > shown {
                    let _ = writeln!(o, "    … and {} more of {id}", t.violations - shown);
                }
            }
        }
        observations(&mut o, "allowed states", &r.allowed, r.allowed_count, true);
        observations(
            &mut o,
            "inconclusive",
            &r.inconclusive,
            r.inconclusive_count,
            false,
        );
        for n in &r.notes {
            let _ = writeln!(o, "  note: {n}");
        }
        if r.notes_dropped > 0 {
            let _ = writeln!(o, "  note: … {} more notes", r.notes_dropped);
        }
        if let Some(e) = &r.error {
            let _ = writeln!(o, "  error: reading stopped: {}", e.message);
        }
        if r.interrupted {
            let _ = writeln!(
                o,
                "  interrupted: reading stopped before the end; this covers what was read"
            );
        }
        let mut line = format!("  result: {}", r.verdict.as_str());
        let scopes = r.scope_line();
        if !scopes.is_empty() {
            let _ = write!(line, " — {scopes}");
        }
        let missing: Vec<&str> = r
            .policy
            .require
            .iter()
            .filter(|f| {
                !r.scopes
                    .iter()
                    .any(|s| s.ran && s.family.as_deref() == Some(f.as_str()))
            })
            .map(String::as_str)
            .collect();
        if !missing.is_empty() {
            let _ = write!(line, " (required: {})", missing.join(", "));
        }
        if r.policy.strict && r.must_count() < r.violation_count {
            line.push_str(" (--strict: warnings fail)");
        }
        let _ = writeln!(o, "{line}");
    }
    o
}

/// Lists allowed states (`spans`: with start, end and duration) or inconclusive checks
/// (where), what and why.
fn observations(o: &mut String, title: &str, list: &[Observation], count: u64, spans: bool) {
    if count == 0 {
        return;
    }
    let more = if (list.len() as u64) < count {
        format!(" (first {} of {count})", list.len())
    } else {
        String::new()
    };
    let _ = writeln!(o, "  {title}{more}:");
    for x in list {
        let span = match (&x.end, x.duration_us, spans) {
            (_, _, false) => x.start.to_string(),
            (Some(e), _, true) if *e == x.start => x.start.to_string(),
            (Some(e), Some(d), true) => format!("{} to {e} ({})", x.start, duration(d)),
            (Some(e), None, true) => format!("{} to {e}", x.start),
            (None, _, true) => format!("{} to the end of the capture", x.start),
        };
        let _ = writeln!(
            o,
            "    {span} {} — {}: {}",
            x.requirement, x.subject, x.message
        );
        let _ = writeln!(o, "        because: {}", x.reason);
    }
}

/// A duration for people: µs, ms or s.
pub fn duration(us: u64) -> String {
    if us < 1000 {
        format!("{us} µs")
    } else if us < 10_000_000 {
        format!("{:.1} ms", us as f64 / 1000.0)
    } else {
        format!("{:.3} s", us as f64 / 1_000_000.0)
    }
}

/// JUnit XML: one test suite per file, named by the file's name, one test case per
/// requirement checked (a `<failure>` when a `must` requirement, or any under `--strict`, is
/// violated; warnings pass with the listed violations as output), one per group of checks
/// (skipped, or failed when required, if it did not run), and an `<error>` test case when the
/// file could not be read to its end.
pub fn junit(reports: &[Report]) -> String {
    let suites = reports
        .iter()
        .map(|r| {
            let mut cases: Vec<Case> = r
                .requirements
                .iter()
                .map(|(id, t)| {
                    let mut text = String::new();
                    for v in r.violations.iter().filter(|v| &v.requirement == id) {
                        let _ = writeln!(text, "{}: {}: {}", v.at, v.subject, v.message);
                    }
                    let fails = t.level == "must" || r.policy.strict;
                    let (outcome, output) = if t.violations == 0 {
                        (Outcome::Passed, None)
                    } else if !fails {
                        let warnings = format!(
                            "{} warning(s) [{}]: {}\n{text}",
                            t.violations, t.level, t.text
                        );
                        (Outcome::Passed, Some(warnings))
                    } else {
                        let failed = Outcome::Failed(Problem {
                            message: format!("{} violation(s): {}", t.violations, t.text),
                            kind: t.level.clone(),
                            text: Some(text),
                        });
                        (failed, None)
                    };
                    Case {
                        name: id.clone(),
                        classname: format!("drivespec.check.{}", r.family),
                        time_ms: 0.0,
                        outcome,
                        output,
                    }
                })
                .collect();
            if let Some(e) = &r.error {
                cases.push(Case {
                    name: "readable".to_owned(),
                    classname: "drivespec.check.input".to_owned(),
                    time_ms: 0.0,
                    outcome: Outcome::Errored(Problem {
                        message: e.message.clone(),
                        kind: "input".to_owned(),
                        text: None,
                    }),
                    output: None,
                });
            }
            for sc in &r.scopes {
                let required = sc
                    .family
                    .as_ref()
                    .is_some_and(|f| r.policy.require.contains(f));
                let outcome = match (&sc.why_not, required) {
                    (None, _) => Outcome::Passed,
                    (Some(why), false) => Outcome::Skipped(why.clone()),
                    (Some(why), true) => Outcome::Failed(Problem {
                        message: format!("required checks did not run: {why}"),
                        kind: "required".to_owned(),
                        text: None,
                    }),
                };
                cases.push(Case {
                    name: format!("{} checks ran", sc.name),
                    classname: "drivespec.check.scope".to_owned(),
                    time_ms: 0.0,
                    outcome,
                    output: None,
                });
            }
            let must = r.must_count();
            let mut properties = vec![
                ("verdict".to_owned(), r.verdict.as_str().to_owned()),
                ("must_violations".to_owned(), must.to_string()),
                (
                    "warnings".to_owned(),
                    r.violation_count.saturating_sub(must).to_string(),
                ),
                ("allowed_states".to_owned(), r.allowed_count.to_string()),
                ("inconclusive".to_owned(), r.inconclusive_count.to_string()),
            ];
            let name = r.file.as_deref().map_or("stream", |f| {
                std::path::Path::new(f)
                    .file_name()
                    .and_then(|n| n.to_str())
                    .unwrap_or(f)
            });
            if let Some(f) = &r.file {
                properties.push(("file".to_owned(), f.clone()));
            }
            if r.interrupted {
                properties.push(("interrupted".to_owned(), "true".to_owned()));
            }
            Suite {
                name: name.to_owned(),
                time_ms: r.timing.map(|(_, ms)| ms),
                properties,
                cases,
            }
        })
        .collect();
    let started = reports
        .iter()
        .filter_map(|r| r.timing)
        .map(|(t, _)| t)
        .min();
    xml_junit::Document {
        name: "drivespec check".to_owned(),
        timestamp: started.map(xml_junit::timestamp),
        hostname: started.map(|_| xml_junit::hostname()),
        suites,
    }
    .to_xml()
}

/// An SVG timeline: position and target, speed, the 16 status bits, violation marks.
fn svg(t: &Timeline) -> String {
    let (w, h_pos, h_speed, row) = (1000.0f64, 200.0f64, 120.0f64, 10.0f64);
    let h_bits = row * 16.0;
    let height = h_pos + h_speed + h_bits + 60.0;
    let mut o = String::new();
    let _ = writeln!(
        o,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{height}\" viewBox=\"0 0 {w} {height}\" font-family=\"sans-serif\" font-size=\"10\">"
    );
    let (Some(first), Some(last)) = (t.samples.first(), t.samples.last()) else {
        o.push_str("<text x=\"10\" y=\"20\">no samples</text></svg>");
        return o;
    };
    let t0 = first.time as f64;
    let span = ((last.time as f64) - t0).max(1.0);
    let left = 60.0;
    let plot_w = w - left - 10.0;
    let x = |time: u64| left + ((time as f64 - t0) / span) * plot_w;
    let range = |vals: &mut dyn Iterator<Item = i64>| {
        let mut lo = i64::MAX;
        let mut hi = i64::MIN;
        for v in vals {
            lo = lo.min(v);
            hi = hi.max(v);
        }
        if lo > hi {
            (0.0, 1.0)
        } else if lo == hi {
            (lo as f64 - 1.0, hi as f64 + 1.0)
        } else {
            (lo as f64, hi as f64)
        }
    };
    let (plo, phi) = range(
        &mut t
            .samples
            .iter()
            .flat_map(|s| std::iter::once(s.actual).chain(s.target)),
    );
    let (slo, shi) = range(&mut t.samples.iter().map(|s| s.speed));
    let y_pos = |v: i64| 10.0 + h_pos - ((v as f64 - plo) / (phi - plo)) * h_pos;
    let y_speed = |v: i64| 20.0 + h_pos + h_speed - ((v as f64 - slo) / (shi - slo)) * h_speed;
    let line = |o: &mut String, pts: Vec<(f64, f64)>, color: &str| {
        if pts.is_empty() {
            return;
        }
        let _ = writeln!(
            o,
            "{}",
            polyline(&pts, &format!("stroke=\"{color}\" stroke-width=\"1\""))
        );
    };
    let _ = writeln!(o, "<text x=\"2\" y=\"20\">position</text><text x=\"2\" y=\"32\">{phi:.0}</text><text x=\"2\" y=\"{:.0}\">{plo:.0}</text>", 10.0 + h_pos);
    line(
        &mut o,
        t.samples
            .iter()
            .map(|s| (x(s.time), y_pos(s.actual)))
            .collect(),
        "#1f77b4",
    );
    line(
        &mut o,
        t.samples
            .iter()
            .filter_map(|s| s.target.map(|v| (x(s.time), y_pos(v))))
            .collect(),
        "#999999",
    );
    let _ = writeln!(o, "<text x=\"2\" y=\"{:.0}\">speed</text><text x=\"2\" y=\"{:.0}\">{shi:.0}</text><text x=\"2\" y=\"{:.0}\">{slo:.0}</text>", 30.0 + h_pos, 42.0 + h_pos, 20.0 + h_pos + h_speed);
    line(
        &mut o,
        t.samples
            .iter()
            .map(|s| (x(s.time), y_speed(s.speed)))
            .collect(),
        "#2ca02c",
    );
    let top = 40.0 + h_pos + h_speed;
    for b in 0..16u16 {
        let y = top + f64::from(b) * row;
        let name = t
            .status_names
            .get(usize::from(b))
            .map_or("", String::as_str);
        let short: String = name.chars().take(10).collect();
        let _ = writeln!(
            o,
            "<text x=\"2\" y=\"{:.0}\"><title>{}</title>{b:>2} {}</text>",
            y + 8.0,
            xml(name),
            xml(&short)
        );
        let mut start: Option<u64> = None;
        for (i, s) in t.samples.iter().enumerate() {
            let on = s.status & (1 << b) != 0;
            match (on, start) {
                (true, None) => start = Some(s.time),
                (false, Some(st)) => {
                    let _ = writeln!(o, "<rect x=\"{:.1}\" y=\"{y:.1}\" width=\"{:.1}\" height=\"{:.1}\" fill=\"#ff7f0e\"/>", x(st), (x(s.time) - x(st)).max(0.5), row - 2.0);
                    start = None;
                }
                _ => {}
            }
            if i + 1 == t.samples.len() {
                if let Some(st) = start {
                    let _ = writeln!(o, "<rect x=\"{:.1}\" y=\"{y:.1}\" width=\"{:.1}\" height=\"{:.1}\" fill=\"#ff7f0e\"/>", x(st), (x(s.time) - x(st)).max(0.5), row - 2.0);
                }
            }
        }
    }
    for m in &t.marks {
        let mx = x(m.time.max(first.time));
        let _ = writeln!(
            o,
            "<line x1=\"{mx:.1}\" y1=\"5\" x2=\"{mx:.1}\" y2=\"{:.0}\" stroke=\"red\" stroke-width=\"1\"><title>{} at {}</title></line>",
            top + h_bits,
            xml(&m.requirement),
            xml(&format_time(m.time))
        );
    }
    let _ = writeln!(
        o,
        "<text x=\"{left}\" y=\"{:.0}\">{} … {}</text>",
        height - 5.0,
        xml(&format_time(first.time)),
        xml(&format_time(last.time))
    );
    o.push_str("</svg>\n");
    o
}

/// A self-contained HTML page of `reports`.
pub fn html(reports: &[Report]) -> String {
    let mut o = String::from("<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>drivespec check</title>\n<style>body{font-family:sans-serif;margin:1em}table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:2px 6px;text-align:left;vertical-align:top}.fail{color:#b00}.pass{color:#070}code{font-size:90%}</style></head><body>\n<h1>drivespec check</h1>\n");
    for r in reports {
        let class = if r.passed() { "pass" } else { "fail" };
        let _ = writeln!(
            o,
            "<h2>{} ({}) — <span class=\"{class}\">{}</span></h2><p>{}</p>",
            xml(r.file.as_deref().unwrap_or("stream")),
            xml(&r.family),
            xml(r.verdict.as_str()),
            xml(&r.scope_line())
        );
        o.push_str("<ul>");
        for d in &r.detection {
            let _ = write!(o, "<li>{}</li>", xml(d));
        }
        let kinds: Vec<String> = r.frames.iter().map(|(k, n)| format!("{k} {n}")).collect();
        let _ = write!(
            o,
            "<li>events {}: {}</li>",
            r.events,
            xml(&kinds.join(", "))
        );
        for d in &r.drives {
            let _ = write!(
                o,
                "<li>{} — found by {}, confidence {:.2}</li>",
                xml(&d.label),
                xml(&d.found_by),
                d.confidence
            );
        }
        if let Some(e) = &r.error {
            let _ = write!(
                o,
                "<li class=\"fail\">reading stopped: {}</li>",
                xml(&e.message)
            );
        }
        for n in &r.notes {
            let _ = write!(o, "<li>{}</li>", xml(n));
        }
        o.push_str("</ul>\n");
        for t in &r.timelines {
            let _ = writeln!(o, "<h3>{}</h3>", xml(&t.label));
            o.push_str(&svg(t));
        }
        o.push_str("<h3>Requirements</h3><table><tr><th>ID</th><th>level</th><th>violations</th><th>text</th><th>source</th></tr>\n");
        for (id, t) in &r.requirements {
            let class = if t.violations > 0 { "fail" } else { "pass" };
            let _ = writeln!(
                o,
                "<tr class=\"{class}\"><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                xml(id),
                xml(&t.level),
                t.violations,
                xml(&t.text),
                xml(&t.source)
            );
        }
        o.push_str("</table>\n");
        if !r.violations.is_empty() {
            let _ = writeln!(o, "<h3>Violations ({} listed of {})</h3><table><tr><th>where</th><th>requirement</th><th>subject</th><th>message</th><th>evidence</th></tr>", r.violations.len(), r.violation_count);
            for v in &r.violations {
                let mut ev = v.evidence.bytes.clone().unwrap_or_default();
                for (k, val) in &v.evidence.fields {
                    let _ = write!(
                        ev,
                        "\n{k}: {}",
                        val.as_str().map_or_else(|| val.to_string(), str::to_owned)
                    );
                }
                let _ = writeln!(
                    o,
                    "<tr><td>{}</td><td title=\"{}\">{}</td><td>{}</td><td>{}</td><td><pre>{}</pre></td></tr>",
                    xml(&v.at.to_string()),
                    xml(&v.text),
                    xml(&v.requirement),
                    xml(&v.subject),
                    xml(&v.message),
                    xml(&ev)
                );
            }
            o.push_str("</table>\n");
        }
        if !r.streams.is_empty() {
            o.push_str("<h3>Timing</h3><table><tr><th>stream</th><th>frames</th><th>nominal µs</th><th>interval µs</th><th>jitter max µs</th><th>missing</th></tr>\n");
            for s in r.streams.iter().take(200) {
                let _ = writeln!(
                    o,
                    "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                    xml(&s.stream),
                    s.frames,
                    s.nominal_us.map_or("-".into(), |n| format!("{n:.1}")),
                    xml(&stats_line(&s.interval_us)),
                    s.jitter_us
                        .as_ref()
                        .filter(|j| j.count > 0)
                        .map_or("-".into(), |j| format!("{:.1}", j.max)),
                    s.missing
                );
            }
            o.push_str("</table>\n");
        }
    }
    o.push_str("</body></html>\n");
    o
}
