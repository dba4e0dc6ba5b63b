//! The run report: one data model (serialised as the JSON report, schema in
//! `crates/conform/README.md`, "JSON report"), rendered as JUnit XML and as a self-contained
//! HTML page with the `drivespec-report` formats.

mod html;
mod junit;

pub use html::{html, html_with};
pub use junit::{junit, junit_with};

use crate::case::{Failure, Finding, Record};
use drivespec_spec::{Family, FamilyId, Level};
use serde::Serialize;

/// Name and version of the JSON schema (`crates/conform/README.md`, "JSON report").
pub const SCHEMA: &str = "drivespec-conform/1";

/// A case's final status, with expectations applied.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Status {
    /// Passed.
    Pass,
    /// Passed, showing one of several outcomes the manual allows (its findings say which).
    Acceptable,
    /// Failed, then passed when run again (`--retries`): passes the run, counted apart, its
    /// first failure kept.
    Flaky,
    /// Failed and not expected to: fails the run.
    Fail,
    /// Failed as the expectations file says.
    ExpectedFailure,
    /// Listed as a known failure but passed: remove it from the file.
    Fixed,
    /// Not run, with a reason (a capability the transport lacks).
    Skipped,
    /// Not run because `--fail-fast` or an interrupt stopped the run.
    NotRun,
}

impl Status {
    /// The name used in reports.
    pub fn as_str(self) -> &'static str {
        match self {
            Status::Pass => "pass",
            Status::Acceptable => "acceptable",
            Status::Flaky => "flaky",
            Status::Fail => "fail",
            Status::ExpectedFailure => "expected-failure",
            Status::Fixed => "fixed",
            Status::Skipped => "skipped",
            Status::NotRun => "not-run",
        }
    }
}

/// The whole report.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    /// `drivespec-conform/1`.
    pub schema: &'static str,
    /// The tool that wrote it.
    pub tool: Tool,
    /// How the run was set up.
    pub run: RunInfo,
    /// Counts and the exit status.
    pub summary: Counts,
    /// Every selected case, in run order.
    pub cases: Vec<CaseReport>,
    /// Requirement → cases → verdict.
    pub coverage: Vec<CoverageRow>,
    /// Per family: how many `must` requirements a check evaluated.
    pub coverage_summary: Vec<FamilyCoverage>,
    /// Expectations entries that matched no selected case.
    pub stale_expectations: Vec<crate::select::KnownFailure>,
    /// The units of each plotting family's position and speed (HTML plots); not in the JSON.
    #[serde(skip)]
    pub plot_units: Vec<PlotUnits>,
    /// When the run started and how long it took (JUnit); not in the JSON, which stays the
    /// same for the same run.
    #[serde(skip)]
    pub timing: Option<Timing>,
}

/// The units a family's plots give the position and speed in: the spec `unit` of the
/// parameters the input image carries them as.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PlotUnits {
    /// The family.
    pub family: FamilyId,
    /// Unit of the position (`increments`).
    pub position: String,
    /// Unit of the speed (`rpm`).
    pub speed: String,
}

impl PlotUnits {
    /// The units of `family`'s parameters `position` and `speed` (IDs); `raw` for one the
    /// spec gives no unit.
    pub fn of(id: FamilyId, family: &Family, position: Option<&str>, speed: Option<&str>) -> Self {
        let unit = |param: Option<&str>| {
            param
                .and_then(|p| family.parameters.iter().find(|x| x.id == p))
                .and_then(|p| p.unit.clone())
                .unwrap_or_else(|| "raw".to_owned())
        };
        PlotUnits {
            family: id,
            position: unit(position),
            speed: unit(speed),
        }
    }
}

/// When a run started and how long it took.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Timing {
    /// The start, on the system clock.
    pub started: std::time::SystemTime,
    /// Wall time of the whole run (ms).
    pub wall_ms: f64,
}

/// Tool name and version.
#[derive(Debug, Clone, Serialize)]
pub struct Tool {
    /// `drivespec`.
    pub name: String,
    /// Crate version.
    pub version: String,
}

/// How the run was set up.
#[derive(Debug, Clone, Serialize)]
pub struct RunInfo {
    /// Families run.
    pub families: Vec<FamilyId>,
    /// The device under test as given (`sim`, `tcp:…`).
    pub dut: String,
    /// What the transport says it is connected to.
    pub transport: String,
    /// Seed of the case values.
    pub seed: u64,
    /// Device address.
    pub address: u8,
    /// Device model, when given.
    pub model: Option<String>,
    /// The PSx3xx brake option declared (`--brake`; manual 5.11–5.13), when given.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub brake: Option<String>,
    /// `--case` patterns.
    pub case: Vec<String>,
    /// `--skip` patterns.
    pub skip: Vec<String>,
    /// `must` or `should`.
    pub level: String,
    /// The expectations file, when given.
    pub expectations: Option<String>,
}

/// Counts of a run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct Counts {
    /// Cases selected.
    pub total: usize,
    /// Passed.
    pub passed: usize,
    /// Passed with an outcome the manual allows among several (also counted in `passed`).
    pub acceptable: usize,
    /// Failed, then passed on a retry (also counted in `passed`); present when not 0.
    #[serde(skip_serializing_if = "is_zero")]
    pub flaky: usize,
    /// Failed unexpectedly.
    pub failed: usize,
    /// Failed as expected.
    pub expected_failures: usize,
    /// Expected to fail but passed.
    pub fixed: usize,
    /// Skipped with a reason.
    pub skipped: usize,
    /// Not run (fail-fast or interrupted).
    pub not_run: usize,
    /// The run was stopped before its end (a signal or the time limit); present only then.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub interrupted: bool,
    /// 0 pass, 1 failures (2 is never written: the run did not happen).
    pub exit_code: u8,
}

/// One case in the report.
#[derive(Debug, Clone, Serialize)]
pub struct CaseReport {
    /// Stable ID.
    pub id: String,
    /// Family.
    pub family: FamilyId,
    /// must or should.
    pub level: Level,
    /// One line.
    pub description: String,
    /// Requirement IDs covered.
    pub requirements: Vec<String>,
    /// Final status.
    pub status: Status,
    /// Why it failed (fail and expected-failure; the first try of a flaky case).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub failure: Option<Failure>,
    /// Why it was skipped.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub skip_reason: Option<String>,
    /// The requirements whose checks evaluated in this case.
    pub checked: Vec<String>,
    /// Which of several allowed outcomes the device showed (acceptable).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub findings: Vec<Finding>,
    /// The expectations entry's reason (expected-failure and fixed).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub expectation: Option<String>,
    /// One record per step run.
    pub evidence: Vec<Record>,
    /// The command that runs this case alone (failures).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub replay: Option<String>,
    /// Wall time (ms).
    pub wall_ms: f64,
    /// Time on the transport's clock (µs; virtual for `sim`).
    pub elapsed_us: u64,
}

/// Verdict of a requirement over the checks that evaluated it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Coverage {
    /// Checked, and no failure names it.
    Pass,
    /// A failure (expected or not) names it.
    Fail,
    /// Cases cite it but none ran (skipped, not selected, not run).
    NotRun,
    /// No check evaluated it (cases may cite it).
    Untested,
    /// No check can evaluate it over the interface (spec `observable = false`, with the reason).
    NotObservable,
}

/// How many of a family's `must` requirements a check evaluated in the run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct FamilyCoverage {
    /// The family.
    pub family: FamilyId,
    /// Its `must` requirements.
    pub must: usize,
    /// Those a check evaluated.
    pub checked: usize,
    /// Those no check can evaluate over the interface (spec `observable = false`).
    pub not_observable: usize,
}

/// One row of the coverage matrix.
#[derive(Debug, Clone, Serialize)]
pub struct CoverageRow {
    /// Requirement ID.
    pub requirement: String,
    /// must, should or informative.
    pub level: Level,
    /// Its text.
    pub text: String,
    /// Verdict over the cases.
    pub verdict: Coverage,
    /// The cases that cover it, with their status.
    pub cases: Vec<CaseRef>,
}

/// A case in the coverage matrix.
#[derive(Debug, Clone, Serialize)]
pub struct CaseRef {
    /// Case ID.
    pub id: String,
    /// Its status.
    pub status: Status,
}

impl Report {
    /// The JSON report.
    pub fn json(&self) -> String {
        drivespec_report::json(self)
    }
}

fn is_zero(n: &usize) -> bool {
    *n == 0
}
