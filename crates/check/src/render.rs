//! Reports for people and tools: a text summary, JSON (schema `drivespec-check/1`, crate
//! README), JUnit XML (one test case per requirement checked) and a self-contained HTML page
//! (a summary linking to each recording's violations, then per recording its violations, a
//! timeline plot (inline SVG) per positioning drive, the requirements and the timing). Output size is bounded by the
//! reports (violation listing cap, bounded timelines). Nothing here panics.

use crate::report::{format_time, Observation, Report, Verdict, SCHEMA};
use crate::timeline::Timeline;
use drivespec_report::escape as xml;
use drivespec_report::junit::{self as xml_junit, Case, Outcome, Problem, Suite};
use drivespec_report::svg::{legend, polyline, Frame, Key};
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

/// An SVG timeline (`<svg class="timeline">`, as wide as the page allows): a legend, the
/// position and target and the speed over time with ticks and titled axes, the 16 status
/// bits with their full names, and a red line at each violation.
fn svg(t: &Timeline) -> String {
    let (Some(first), Some(last)) = (t.samples.first(), t.samples.last()) else {
        return "<p class=\"muted\">no samples</p>\n".to_owned();
    };
    let names: Vec<String> = (0..16usize)
        .map(|b| {
            t.status_names
                .get(b)
                .map_or_else(|| format!("bit {b}"), |n| format!("{b} {n}"))
        })
        .collect();
    // Room for the longest bit name (about 6 px a character) and the axes' tick labels.
    let widest = names.iter().map(|n| n.chars().count()).max().unwrap_or(0);
    let left = (16.0 + 6.0 * widest as f64).clamp(100.0, 300.0);
    let (w, row) = (1000.0f64.max(left + 500.0), 12.0f64);
    let width = w - left - 15.0;
    let (pos_top, pos_h, speed_top, speed_h) = (30.0, 180.0, 240.0, 110.0);
    let bits_top = speed_top + speed_h + 48.0;
    let height = bits_top + 16.0 * row + 10.0;
    // Time since the first sample: ms for up to 10 s, s beyond.
    let span_us = last.time.saturating_sub(first.time);
    let (scale, unit) = if span_us <= 10_000_000 {
        (1000.0, "ms")
    } else {
        (1_000_000.0, "s")
    };
    let rel = |time: u64| time.saturating_sub(first.time) as f64 / scale;
    // At least one unit wide: a drive seen once is a point at the start.
    let t1 = rel(last.time).max(1.0);
    let mut o = String::new();
    let _ = writeln!(
        o,
        "<svg class=\"timeline\" xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{height}\" viewBox=\"0 0 {w} {height}\" font-family=\"sans-serif\" font-size=\"11\">"
    );
    o.push_str(&legend(
        left,
        14.0,
        &[
            (Key::Line(POSITION), "actual position"),
            (Key::Line(TARGET), "target"),
            (Key::Line(SPEED), "speed"),
            (Key::Fill(BIT), "status bit set"),
            (Key::Line(VIOLATION), "violation"),
        ],
    ));
    let range = |vals: &mut dyn Iterator<Item = i64>| {
        let (lo, hi) = vals.fold((i64::MAX, i64::MIN), |(a, b), v| (a.min(v), b.max(v)));
        if lo > hi {
            (0.0, 1.0)
        } else {
            // A flat line sits mid-panel with whole-number ticks.
            let pad = ((hi as f64 - lo as f64) * 0.05).max(2.0);
            (lo as f64 - pad, hi as f64 + pad)
        }
    };
    let position = Frame {
        left,
        top: pos_top,
        width,
        height: pos_h,
        x: (0.0, t1),
        y: range(
            &mut t
                .samples
                .iter()
                .flat_map(|s| std::iter::once(s.actual).chain(s.target)),
        ),
    };
    let speed = Frame {
        top: speed_top,
        height: speed_h,
        y: range(&mut t.samples.iter().map(|s| s.speed)),
        ..position
    };
    // One sample is drawn as a dot, more as a line.
    let line = |o: &mut String, pts: Vec<(f64, f64)>, style: &str| match pts.as_slice() {
        [] => {}
        [(x, y)] => {
            let _ = writeln!(
                o,
                "<circle cx=\"{x:.1}\" cy=\"{y:.1}\" r=\"2.5\" fill=\"none\" {style}/>"
            );
        }
        _ => {
            let _ = writeln!(o, "{}", polyline(&pts, style));
        }
    };
    o.push_str(&position.axes(None, "position (raw, as sent)"));
    line(
        &mut o,
        t.samples
            .iter()
            .filter_map(|s| {
                s.target
                    .map(|v| (position.x(rel(s.time)), position.y(v as f64)))
            })
            .collect(),
        TARGET,
    );
    line(
        &mut o,
        t.samples
            .iter()
            .map(|s| (position.x(rel(s.time)), position.y(s.actual as f64)))
            .collect(),
        POSITION,
    );
    let time_title = format!("time since {} ({unit})", format_time(first.time));
    o.push_str(&speed.axes(Some(&time_title), "speed (rpm)"));
    line(
        &mut o,
        t.samples
            .iter()
            .map(|s| (speed.x(rel(s.time)), speed.y(s.speed as f64)))
            .collect(),
        SPEED,
    );
    let _ = writeln!(o, "<g class=\"bits\">");
    for (b, name) in (0..16u16).zip(&names) {
        let y = bits_top + f64::from(b) * row;
        let _ = writeln!(
            o,
            "<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"end\">{}</text><line x1=\"{left:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"#eee\"/>",
            left - 6.0,
            y + 9.0,
            xml(name),
            y + row - 1.0,
            left + width,
            y + row - 1.0
        );
        let mut start: Option<u64> = None;
        for (i, s) in t.samples.iter().enumerate() {
            let on = s.status & (1 << b) != 0;
            let end = if i + 1 == t.samples.len() && on {
                Some(s.time)
            } else if !on {
                start.map(|_| s.time)
            } else {
                None
            };
            if on && start.is_none() {
                start = Some(s.time);
            }
            if let (Some(st), Some(en)) = (start, end) {
                let (x0, x1) = (position.x(rel(st)), position.x(rel(en)));
                let _ = writeln!(
                    o,
                    "<rect x=\"{x0:.1}\" y=\"{y:.1}\" width=\"{:.1}\" height=\"{:.1}\" fill=\"{BIT}\"><title>{}: {} to {}</title></rect>",
                    (x1 - x0).max(0.5),
                    row - 2.0,
                    xml(name),
                    xml(&format_time(st)),
                    xml(&format_time(en))
                );
                start = None;
            }
        }
    }
    o.push_str("</g>\n");
    for m in &t.marks {
        let mx = position.x(rel(m.time.max(first.time)));
        let _ = writeln!(
            o,
            "<line class=\"violation\" x1=\"{mx:.1}\" y1=\"{pos_top:.0}\" x2=\"{mx:.1}\" y2=\"{:.0}\" {VIOLATION}><title>{} at {}</title></line>",
            bits_top + 16.0 * row,
            xml(&m.requirement),
            xml(&format_time(m.time))
        );
    }
    o.push_str("</svg>\n");
    o
}

/// Line styles and colours of the timeline.
const POSITION: &str = "stroke=\"#1f77b4\" stroke-width=\"1.5\"";
const TARGET: &str = "stroke=\"#999\" stroke-width=\"1\" stroke-dasharray=\"4 2\"";
const SPEED: &str = "stroke=\"#2ca02c\" stroke-width=\"1.5\"";
const BIT: &str = "#ff7f0e";
const VIOLATION: &str = "stroke=\"#d00000\" stroke-width=\"1\"";

/// A self-contained HTML page of `reports`.
pub fn html(reports: &[Report]) -> String {
    let mut o = String::from("<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>drivespec check</title>\n<style>body{font-family:sans-serif;margin:1em}table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:2px 6px;text-align:left;vertical-align:top}.fail{color:#b00}.pass{color:#070}code{font-size:90%}svg.timeline{display:block;max-width:100%;height:auto}</style></head><body>\n<h1>drivespec check</h1>\n");
    o.push_str("<table id=\"summary\"><tr><th>recording</th><th>family</th><th>verdict</th><th>must violations</th><th>warnings</th></tr>\n");
    for (i, r) in reports.iter().enumerate() {
        let class = if r.passed() { "pass" } else { "fail" };
        let must = r.must_count();
        let link = if r.violations.is_empty() {
            format!("file-{i}")
        } else {
            format!("violations-{i}")
        };
        let _ = writeln!(
            o,
            "<tr><td><a href=\"#{link}\">{}</a></td><td>{}</td><td class=\"{class}\">{}</td><td>{must}</td><td>{}</td></tr>",
            xml(r.file.as_deref().unwrap_or("stream")),
            xml(&r.family),
            xml(r.verdict.as_str()),
            r.violation_count.saturating_sub(must)
        );
    }
    o.push_str("</table>\n");
    for (i, r) in reports.iter().enumerate() {
        let class = if r.passed() { "pass" } else { "fail" };
        let _ = writeln!(
            o,
            "<h2 id=\"file-{i}\">{} ({}) — <span class=\"{class}\">{}</span></h2><p>{}</p>",
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
        if !r.violations.is_empty() {
            let _ = writeln!(o, "<h3 id=\"violations-{i}\">Violations ({} listed of {})</h3><table><tr><th>where</th><th>requirement</th><th>subject</th><th>message</th><th>evidence</th></tr>", r.violations.len(), r.violation_count);
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
