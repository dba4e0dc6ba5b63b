//! Newline-delimited JSON for log pipelines (schema `drivespec-check-finding/1`, crate README
//! "NDJSON findings"): one object per violation listed, one per file whose reading failed, and
//! a summary object last. Every line carries the schema; field names are only ever added.

use crate::report::{Evidence, Report, Verdict, Where};
use serde::Serialize;

/// Name and version of the line schema (crate README, "NDJSON findings").
pub const SCHEMA: &str = "drivespec-check-finding/1";

/// One violation, flat: the file, where, the requirement and what shows it.
#[derive(Serialize)]
struct Finding<'a> {
    schema: &'static str,
    kind: &'static str,
    file: Option<&'a str>,
    family: &'a str,
    #[serde(flatten)]
    at: &'a Where,
    requirement: &'a str,
    level: &'a str,
    subject: &'a str,
    message: &'a str,
    evidence: &'a Evidence,
    #[serde(skip_serializing_if = "Option::is_none")]
    end: Option<&'a Where>,
    #[serde(skip_serializing_if = "Option::is_none")]
    duration_us: Option<u64>,
}

/// A file whose reading failed or stopped early.
#[derive(Serialize)]
struct Failure<'a> {
    schema: &'static str,
    kind: &'static str,
    file: &'a str,
    message: &'a str,
    #[serde(skip_serializing_if = "Option::is_none")]
    offset: Option<u64>,
}

/// The last line: counts over every file of the run.
#[derive(Debug, Default, Serialize)]
pub struct Summary {
    /// `drivespec-check-finding/1`.
    schema: &'static str,
    /// `summary`.
    kind: &'static str,
    /// Files checked or attempted.
    pub files: u64,
    /// Finding lines written (the violations listed under the caps).
    pub findings: u64,
    /// Violations counted (listed or not).
    pub violation_count: u64,
    /// `must` violations counted.
    pub must_count: u64,
    /// Warnings (violations of other levels) counted.
    pub warning_count: u64,
    /// Files whose verdict is `fail`.
    pub failed: u64,
    /// Files that could not be read, wholly or in part.
    pub unreadable: u64,
}

impl Summary {
    /// An empty summary.
    pub fn new() -> Summary {
        Summary {
            schema: SCHEMA,
            kind: "summary",
            ..Summary::default()
        }
    }

    /// The lines of one file's report (each ending in a newline), counted in the summary.
    pub fn report_lines(&mut self, r: &Report) -> String {
        let file = r.file.as_deref();
        let mut out = String::new();
        for v in &r.violations {
            line(
                &mut out,
                &Finding {
                    schema: SCHEMA,
                    kind: "finding",
                    file,
                    family: &r.family,
                    at: &v.at,
                    requirement: &v.requirement,
                    level: &v.level,
                    subject: &v.subject,
                    message: &v.message,
                    evidence: &v.evidence,
                    end: v.end.as_ref(),
                    duration_us: v.duration_us,
                },
            );
        }
        if let Some(e) = &r.error {
            line(
                &mut out,
                &Failure {
                    schema: SCHEMA,
                    kind: "unreadable",
                    file: file.unwrap_or("-"),
                    message: &e.message,
                    offset: e.offset,
                },
            );
        }
        self.files += 1;
        self.findings += r.violations.len() as u64;
        self.violation_count += r.violation_count;
        self.must_count += r.must_count();
        self.warning_count += r.violation_count.saturating_sub(r.must_count());
        self.failed += u64::from(r.verdict == Verdict::Fail);
        self.unreadable += u64::from(r.error.is_some());
        out
    }

    /// The line of a file that could not be opened or read at all, counted in the summary.
    pub fn unreadable_line(&mut self, file: &str, message: &str) -> String {
        let mut out = String::new();
        line(
            &mut out,
            &Failure {
                schema: SCHEMA,
                kind: "unreadable",
                file,
                message,
                offset: None,
            },
        );
        self.files += 1;
        self.unreadable += 1;
        out
    }

    /// The summary line (ending in a newline).
    pub fn line(&self) -> String {
        let mut out = String::new();
        line(&mut out, self);
        out
    }
}

/// Appends `value` as one compact JSON line.
fn line<T: Serialize>(out: &mut String, value: &T) {
    match serde_json::to_string(value) {
        Ok(s) => out.push_str(&s),
        Err(e) => out.push_str(
            &serde_json::json!({"schema": SCHEMA, "kind": "error", "message": e.to_string()})
                .to_string(),
        ),
    }
    out.push('\n');
}
