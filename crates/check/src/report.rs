//! The result of a check: violations with requirement, place and evidence, tallies per
//! requirement, frame counts, cycle statistics and what was detected (schema in the crate
//! README, "JSON report").
//!
//! Memory is bounded: at most `max_violations` violations are listed, and at most
//! [`MAX_LISTED_PER_REQUIREMENT`] of one requirement (all are counted), the
//! requirement tallies are bounded by the catalogue, notes by [`MAX_NOTES`], and timelines
//! by [`crate::timeline::MAX_SAMPLES`]. Nothing here panics.

use crate::timeline::Timeline;
use drivespec_spec::hex::to_hex;
use drivespec_spec::{Requirement, Spec};
use serde::Serialize;
use std::collections::{BTreeMap, HashMap};
use std::fmt;
use std::sync::Arc;

/// Name and version of the JSON report schema (crate README, "JSON report").
pub const SCHEMA: &str = "drivespec-check/1";

/// Most notes kept in one report (the rest are counted in `notes_dropped`).
pub const MAX_NOTES: usize = 200;

/// The generic PROFINET rules (IEC 61158-6-10), in the spec's requirement format.
const PROFINET_RULES: &str = include_str!("../profinet.toml");

/// Where something happened (style rule 12: event index and time).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct Where {
    /// 0-based index of the event in the checked stream.
    pub event: u64,
    /// Record number in a capture (from 1, as Wireshark counts frames).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub frame: Option<u64>,
    /// Byte offset in the (decompressed) serial stream.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub offset: Option<u64>,
    /// 1-based line of a text recording or log.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub line: Option<u64>,
    /// Microseconds since 1970 (UTC) or since the log's own epoch.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time: Option<u64>,
}

impl fmt::Display for Where {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(n) = self.frame {
            write!(f, "frame {n}")?;
        } else if let Some(l) = self.line {
            write!(f, "line {l}")?;
        } else if let Some(o) = self.offset {
            write!(f, "byte {o}")?;
        } else {
            write!(f, "event {}", self.event)?;
        }
        if self.frame.is_some() || self.line.is_some() {
            if let Some(o) = self.offset {
                write!(f, ", byte {o}")?;
            }
        }
        if let Some(t) = self.time {
            write!(f, ", {}", format_time(t))?;
        }
        Ok(())
    }
}

/// A time for people: ISO 8601 UTC for times after 2000, else seconds since the log's epoch.
pub fn format_time(us: u64) -> String {
    const Y2000: u64 = 946_684_800_000_000;
    if us < Y2000 {
        return format!("t={}.{:06} s", us / 1_000_000, us % 1_000_000);
    }
    let secs = us / 1_000_000;
    let days = secs / 86_400;
    let tod = secs % 86_400;
    let (y, m, d) = civil_from_days(days);
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}.{:06}Z",
        tod / 3600,
        tod / 60 % 60,
        tod % 60,
        us % 1_000_000
    )
}

/// Year, month, day of a day count since 1970-01-01 (H. Hinnant's `civil_from_days`).
fn civil_from_days(days: u64) -> (u64, u64, u64) {
    let z = days + 719_468;
    let era = z / 146_097;
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + u64::from(m <= 2);
    (y, m, d)
}

/// What shows a violation: the bytes and the decoded fields involved.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Evidence {
    /// The bytes (hex, blank-separated), when one frame or image shows it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bytes: Option<String>,
    /// Decoded fields by name.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub fields: BTreeMap<String, serde_json::Value>,
}

impl Evidence {
    /// Evidence of the bytes `b`.
    pub fn bytes(b: &[u8]) -> Evidence {
        Evidence {
            bytes: Some(to_hex(b)),
            fields: BTreeMap::new(),
        }
    }

    /// No bytes, fields to follow.
    pub fn none() -> Evidence {
        Evidence::default()
    }

    /// Adds a decoded field.
    pub fn with(mut self, name: &str, value: impl Into<serde_json::Value>) -> Evidence {
        self.fields.insert(name.to_owned(), value.into());
        self
    }
}

/// One violation of a requirement.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Violation {
    /// Requirement ID (`HPD-FRAME-009`, `PSD-PKW-034`, `PN-RT-CC-001`).
    pub requirement: String,
    /// `must`, `should` or `informative`.
    pub level: String,
    /// The requirement in words.
    pub text: String,
    /// Where the requirement comes from (manual section or standard).
    pub source: String,
    /// What the violation concerns: `drive 3`, `PSD4xx #1 (slot 1)`, `stream 0x8001 …`.
    pub subject: String,
    /// Where it happened.
    #[serde(rename = "where")]
    pub at: Where,
    /// What is wrong, one line.
    pub message: String,
    /// What shows it.
    pub evidence: Evidence,
    /// Where a condition ended, when it ended before the capture did.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub end: Option<Where>,
    /// The condition's duration in µs, when both ends have a time.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub duration_us: Option<u64>,
}

/// How often a requirement was checked and violated.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Tally {
    /// `must`, `should` or `informative`.
    pub level: String,
    /// The requirement in words.
    pub text: String,
    /// Where it comes from.
    pub source: String,
    /// Violations counted (all of them, whatever `--max-violations` lists).
    pub violations: u64,
}

/// Statistics of a series of values (Welford's running mean and variance).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct Stats {
    /// Values seen.
    pub count: u64,
    /// Smallest.
    pub min: f64,
    /// Largest.
    pub max: f64,
    /// Mean.
    pub mean: f64,
    /// Standard deviation (population).
    pub stddev: f64,
    #[serde(skip)]
    m2: f64,
}

impl Stats {
    /// Adds a value.
    pub fn add(&mut self, x: f64) {
        self.count += 1;
        if self.count == 1 {
            self.min = x;
            self.max = x;
        } else {
            self.min = self.min.min(x);
            self.max = self.max.max(x);
        }
        let delta = x - self.mean;
        self.mean += delta / self.count as f64;
        self.m2 += delta * (x - self.mean);
    }

    /// Computes the standard deviation of the values added so far (kept out of `add`, which
    /// runs once per frame).
    pub fn done(mut self) -> Stats {
        if self.count > 0 {
            self.stddev = (self.m2 / self.count as f64).sqrt();
        }
        self
    }
}

/// Timing of one cyclic stream: a PROFINET IOCR, an IO-Link port, an HPD line.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StreamStats {
    /// What the stream is (`0x8001 00:0e:cf:01:02:03 → 00:1b:1b:0a:0b:0c`, `port 1`).
    pub stream: String,
    /// Frames or samples.
    pub frames: u64,
    /// Nominal interval in µs (from the Connect, or the most common counter step).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nominal_us: Option<f64>,
    /// Intervals between consecutive frames in µs.
    pub interval_us: Stats,
    /// |interval − nominal| in µs.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub jitter_us: Option<Stats>,
    /// Frames missing: cycles the counter skipped, at most as many as the capture time shows
    /// passed (sum over gaps).
    pub missing: u64,
    /// Gaps (places where at least one frame is missing).
    pub gaps: u64,
}

/// A drive found in the capture and how (PROFINET: from the Connect, options or search).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DriveInfo {
    /// Label used as the subject of its violations.
    pub label: String,
    /// Family id (`psd4xx`, `hpd`, `psx3xx`).
    pub family: String,
    /// How it was found: `connect`, `options`, `search`, `address`, `port`.
    pub found_by: String,
    /// Confidence 0..1 of a search; 1 for a Connect or options.
    pub confidence: f64,
    /// Details (frame IDs and offsets, slot/subslot, address).
    pub details: BTreeMap<String, serde_json::Value>,
}

/// Reading stopped before the end: the error and where (everything before was checked).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct InputFault {
    /// The reader's message; it names the offset.
    pub message: String,
    /// Byte offset where reading stopped, when known.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub offset: Option<u64>,
}

/// The report of one check (schema `drivespec-check/1`, crate README).
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    /// `drivespec-check/1`.
    pub schema: &'static str,
    /// The file checked, when a file was.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
    /// Checker family: `hpd`, `psd4xx` (PROFINET), `psx3xx`.
    pub family: String,
    /// What was detected (format, device) and why.
    pub detection: Vec<String>,
    /// Events checked (frames, line events, log lines).
    pub events: u64,
    /// Frames or events by kind.
    pub frames: BTreeMap<String, u64>,
    /// Violations counted.
    pub violation_count: u64,
    /// The listing cap in force (`--max-violations`), if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_violations: Option<u64>,
    /// Violations listed, in order of occurrence (at most `max_violations`).
    pub violations: Vec<Violation>,
    /// Every requirement checked, with its violation count.
    pub requirements: BTreeMap<String, Tally>,
    /// Cycle and timing statistics per stream.
    pub streams: Vec<StreamStats>,
    /// Drives found and checked.
    pub drives: Vec<DriveInfo>,
    /// Remarks: what could not be checked and why.
    pub notes: Vec<String>,
    /// Notes not kept beyond [`MAX_NOTES`].
    pub notes_dropped: u64,
    /// Reading stopped early: why and where.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<InputFault>,
    /// Violations counted per level (`must`, `should`, `informative`).
    pub levels: BTreeMap<String, u64>,
    /// States the standards allow that a stricter reading would flag, with start and end.
    pub allowed: Vec<Observation>,
    /// States allowed, counted (all of them, however many are listed).
    pub allowed_count: u64,
    /// Checks that could not decide, with why.
    pub inconclusive: Vec<Observation>,
    /// Inconclusive checks, counted.
    pub inconclusive_count: u64,
    /// What was and was not checked: one entry per group of checks.
    pub scopes: Vec<Scope>,
    /// How the verdict is reached (`--strict`, `--require`).
    pub policy: Policy,
    /// The verdict under `policy`: `pass`, `warn`, `fail` or `unreadable`.
    pub verdict: Verdict,
    /// Reading was stopped by the caller (a signal) before the end of the file: the report
    /// covers what was read. Present only then.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub interrupted: bool,
    /// When the check started and how long it took (JUnit); not in the JSON, which stays the
    /// same for the same recording.
    #[serde(skip)]
    pub timing: Option<(std::time::SystemTime, f64)>,
    /// Position, speed and bits over time per positioning drive (HTML report only).
    #[serde(skip)]
    pub timelines: Vec<Timeline>,
}

/// Most allowed-state and inconclusive observations listed per report (all are counted).
pub const MAX_OBSERVATIONS: usize = 200;

/// A state that is not a violation: allowed by the standard or the manual, or a check that
/// could not decide. Conditions have a start, an end (when they ended in the capture) and a
/// duration.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Observation {
    /// The requirement the state concerns.
    pub requirement: String,
    /// What it concerns (a stream, a drive).
    pub subject: String,
    /// Where it began.
    pub start: Where,
    /// Where it ended, when it ended before the capture did.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub end: Option<Where>,
    /// Its duration in µs, when both ends have a time.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub duration_us: Option<u64>,
    /// What was seen, one line.
    pub message: String,
    /// Why it is allowed, or why the check cannot decide (with the manual section).
    pub reason: String,
}

/// One group of checks (generic PROFINET, PSD4xx, HPD, PSx3xx) and whether it ran.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Scope {
    /// `PROFINET`, `PSD4xx`, `HPD`, `PSx3xx`.
    pub name: String,
    /// The family id it stands for (`psd4xx`, `hpd`, `psx3xx`), if one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub family: Option<String>,
    /// Whether its checks ran.
    pub ran: bool,
    /// Why they did not run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub why_not: Option<String>,
    /// `must` violations of its requirements.
    pub must: u64,
    /// Other violations (`should`, `informative`): warnings.
    pub warnings: u64,
}

/// How the verdict is reached.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct Policy {
    /// Warnings fail too (`--strict`).
    pub strict: bool,
    /// Families whose checks must have run (`--require`), as family ids.
    pub require: Vec<String>,
}

/// The verdict of one report.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Verdict {
    /// No violation; every required check ran.
    #[default]
    Pass,
    /// Only warnings (`should` findings), and not `--strict`.
    Warn,
    /// A `must` violation, a warning under `--strict`, or a required check that did not run.
    Fail,
    /// Reading stopped early.
    Unreadable,
}

impl Verdict {
    /// The word printed on the result line.
    pub fn as_str(self) -> &'static str {
        match self {
            Verdict::Pass => "PASS",
            Verdict::Warn => "PASS with warnings",
            Verdict::Fail => "FAIL",
            Verdict::Unreadable => "UNREADABLE (checked up to the error)",
        }
    }
}

/// The scope a requirement belongs to, by its ID prefix.
fn scope_of(id: &str) -> &'static str {
    if id.starts_with("PN-") {
        "PROFINET"
    } else if id.starts_with("PSD-") {
        "PSD4xx"
    } else if id.starts_with("HPD-") {
        "HPD"
    } else {
        "PSx3xx"
    }
}

impl Report {
    /// An empty report of a family.
    pub fn new(family: &str) -> Report {
        Report {
            schema: SCHEMA,
            file: None,
            family: family.to_owned(),
            detection: Vec::new(),
            events: 0,
            frames: BTreeMap::new(),
            violation_count: 0,
            max_violations: None,
            violations: Vec::new(),
            requirements: BTreeMap::new(),
            streams: Vec::new(),
            drives: Vec::new(),
            notes: Vec::new(),
            notes_dropped: 0,
            error: None,
            levels: BTreeMap::new(),
            allowed: Vec::new(),
            allowed_count: 0,
            inconclusive: Vec::new(),
            inconclusive_count: 0,
            scopes: Vec::new(),
            policy: Policy::default(),
            verdict: Verdict::Pass,
            interrupted: false,
            timing: None,
            timelines: Vec::new(),
        }
    }

    /// Declares a group of checks: `ran` or not and why (its counts come from the tallies
    /// in [`Report::judge`]).
    pub fn scope(&mut self, name: &str, family: Option<&str>, why_not: Option<String>) {
        self.scopes.retain(|s| s.name != name);
        self.scopes.push(Scope {
            name: name.to_owned(),
            family: family.map(str::to_owned),
            ran: why_not.is_none(),
            why_not,
            must: 0,
            warnings: 0,
        });
    }

    /// Counts the violations per scope and level and reaches the verdict under `policy`:
    /// `must` violations fail, other levels warn (fail under `--strict`), a required family
    /// whose checks did not run fails, a read error is `unreadable`.
    pub fn judge(&mut self, policy: Policy) {
        self.levels.clear();
        for s in &mut self.scopes {
            s.must = 0;
            s.warnings = 0;
        }
        for (id, t) in &self.requirements {
            if t.violations == 0 {
                continue;
            }
            *self.levels.entry(t.level.clone()).or_insert(0) += t.violations;
            let name = scope_of(id);
            if let Some(s) = self.scopes.iter_mut().find(|s| s.name == name) {
                if t.level == "must" {
                    s.must += t.violations;
                } else {
                    s.warnings += t.violations;
                }
            }
        }
        let must = self.levels.get("must").copied().unwrap_or(0);
        let warnings = self.violation_count.saturating_sub(must);
        let missing = policy.require.iter().any(|f| {
            !self
                .scopes
                .iter()
                .any(|s| s.ran && s.family.as_deref() == Some(f.as_str()))
        });
        self.verdict = if self.error.is_some() {
            Verdict::Unreadable
        } else if must > 0 || missing || (policy.strict && warnings > 0) {
            Verdict::Fail
        } else if warnings > 0 {
            Verdict::Warn
        } else {
            Verdict::Pass
        };
        self.policy = policy;
    }

    /// Whether the verdict lets the run pass (`pass` or `warn`).
    pub fn passed(&self) -> bool {
        matches!(self.verdict, Verdict::Pass | Verdict::Warn)
    }

    /// `must` violations counted.
    pub fn must_count(&self) -> u64 {
        self.levels.get("must").copied().unwrap_or(0)
    }

    /// The result line's list of what was and was not checked: `PROFINET: pass; PSD4xx: no
    /// drive found`.
    pub fn scope_line(&self) -> String {
        let parts: Vec<String> = self
            .scopes
            .iter()
            .map(|s| {
                let state = if !s.ran {
                    s.why_not.clone().unwrap_or_else(|| "not checked".into())
                } else if s.must > 0 {
                    format!("fail ({} must violation(s))", s.must)
                } else if s.warnings > 0 {
                    format!("pass with {} warning(s)", s.warnings)
                } else {
                    "pass".into()
                };
                format!("{}: {state}", s.name)
            })
            .collect();
        parts.join("; ")
    }

    /// Whether nothing is wrong: no violation and no read error.
    pub fn clean(&self) -> bool {
        self.violation_count == 0 && self.error.is_none()
    }

    /// Violations counted per requirement ID (only those violated).
    pub fn counts(&self) -> BTreeMap<&str, u64> {
        self.requirements
            .iter()
            .filter(|(_, t)| t.violations > 0)
            .map(|(id, t)| (id.as_str(), t.violations))
            .collect()
    }

    /// Says how many lines of a text log were unreadable; when they are more than half of the
    /// lines (or all of them) reading counts as failed: a verdict on the rest would be a verdict
    /// on a fraction of the recording. `read` is the number of lines read.
    pub fn unreadable_lines(&mut self, read: u64) {
        let skipped = self.frames.get("unreadable line").copied().unwrap_or(0);
        if skipped == 0 || self.error.is_some() {
            return;
        }
        let total = skipped.saturating_add(read);
        let share = skipped as f64 * 100.0 / total as f64;
        let said =
            format!("{skipped} of {total} line(s) ({share:.2} %) were unreadable and skipped");
        if skipped > read {
            let message = if read == 0 {
                format!("no readable line: all {skipped} line(s) were skipped (see the notes)")
            } else {
                format!("{said}, more than half: not judged (see the notes)")
            };
            self.error = Some(InputFault {
                message,
                offset: None,
            });
        } else {
            // First among the notes, which stay at most MAX_NOTES.
            if self.notes.len() >= MAX_NOTES {
                self.notes.pop();
                self.notes_dropped += 1;
            }
            self.notes.insert(0, said);
        }
    }

    /// Adds a note, keeping at most [`MAX_NOTES`].
    pub fn note(&mut self, text: impl Into<String>) {
        if self.notes.len() < MAX_NOTES {
            self.notes.push(text.into());
        } else {
            self.notes_dropped += 1;
        }
    }

    /// Counts one frame or event of `kind`.
    pub fn count(&mut self, kind: &str) {
        match self.frames.get_mut(kind) {
            Some(n) => *n += 1,
            None => {
                self.frames.insert(kind.to_owned(), 1);
            }
        }
    }

    /// The JSON form (schema `drivespec-check/1`).
    pub fn json(&self) -> String {
        drivespec_report::json(self)
    }
}

/// One requirement of the catalogue.
#[derive(Debug, Clone, PartialEq, Eq)]
struct Entry {
    level: String,
    text: String,
    source: String,
}

/// The catalogue could not be built (a bug in the generic rules file).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("generic PROFINET rules (crates/check/profinet.toml): {0}")]
pub struct CatalogError(String);

/// Every requirement a checker may cite: the spec's three families and the generic PROFINET
/// rules of IEC 61158-6-10 (`profinet.toml`).
#[derive(Debug, Clone)]
pub struct Catalog {
    map: HashMap<String, Entry>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct RulesFile {
    requirement: Vec<Requirement>,
}

impl Catalog {
    /// The catalogue of `spec` plus the generic PROFINET rules.
    pub fn new(spec: &Spec) -> Result<Catalog, CatalogError> {
        let mut map = HashMap::new();
        let generic: RulesFile =
            toml::from_str(PROFINET_RULES).map_err(|e| CatalogError(e.to_string()))?;
        let all = spec
            .families()
            .into_iter()
            .flat_map(|f| f.requirements.iter())
            .chain(generic.requirement.iter());
        for r in all {
            map.insert(
                r.id.clone(),
                Entry {
                    level: r.level.as_str().to_owned(),
                    text: r.text.clone(),
                    source: r.source.clone(),
                },
            );
        }
        Ok(Catalog { map })
    }

    /// Whether the catalogue has `id`.
    pub fn has(&self, id: &str) -> bool {
        self.map.contains_key(id)
    }

    /// The IDs of the generic PROFINET rules.
    pub fn generic_ids() -> Vec<String> {
        toml::from_str::<RulesFile>(PROFINET_RULES)
            .map(|f| f.requirement.into_iter().map(|r| r.id).collect())
            .unwrap_or_default()
    }

    fn entry(&self, id: &str) -> Entry {
        self.map.get(id).cloned().unwrap_or_else(|| Entry {
            level: "must".into(),
            text: format!("(requirement {id} is not in the spec)"),
            source: String::new(),
        })
    }
}

/// Collects a report: requirements checked, violations with their catalogue text, the cap.
#[derive(Debug, Clone)]
pub struct Recorder {
    catalog: Arc<Catalog>,
    report: Report,
    max: Option<u64>,
    /// Violations listed per requirement.
    listed: HashMap<String, u64>,
}

/// Lists an observation when fewer than [`MAX_OBSERVATIONS`] are; gives its index.
fn observe(
    list: &mut Vec<Observation>,
    id: &str,
    subject: &str,
    start: Where,
    message: String,
    reason: String,
) -> Option<usize> {
    if list.len() >= MAX_OBSERVATIONS {
        return None;
    }
    list.push(Observation {
        requirement: id.to_owned(),
        subject: subject.to_owned(),
        start,
        end: None,
        duration_us: None,
        message,
        reason,
    });
    Some(list.len() - 1)
}

/// Violations listed by default (all are counted): a capture full of one fault must not fill
/// memory or the terminal.
pub const DEFAULT_MAX_VIOLATIONS: u64 = 1000;

/// Most violations of one requirement listed, so one repeated fault does not hide the others.
pub const MAX_LISTED_PER_REQUIREMENT: u64 = 100;

impl Recorder {
    /// A recorder for a `family` report listing at most `max` violations.
    pub fn new(catalog: Arc<Catalog>, family: &str, max: Option<u64>) -> Recorder {
        let mut report = Report::new(family);
        report.max_violations = max;
        Recorder {
            catalog,
            report,
            max,
            listed: HashMap::new(),
        }
    }

    /// Marks requirements as checked (they appear in the tallies and the JUnit report).
    pub fn checks(&mut self, ids: &[&str]) {
        for id in ids {
            self.tally(id);
        }
    }

    /// Calls `f` with the tally of requirement `id`, made from the catalogue on first use (the
    /// key is allocated only then: `checks` runs for every frame).
    fn with_tally<R>(&mut self, id: &str, f: impl FnOnce(&mut Tally) -> R) -> R {
        if let Some(t) = self.report.requirements.get_mut(id) {
            return f(t);
        }
        let e = self.catalog.entry(id);
        let mut t = Tally {
            level: e.level,
            text: e.text,
            source: e.source,
            violations: 0,
        };
        let r = f(&mut t);
        self.report.requirements.insert(id.to_owned(), t);
        r
    }

    fn tally(&mut self, id: &str) {
        self.with_tally(id, |_| ());
    }

    /// Whether a violation of `id` recorded now would be listed (not only counted): callers
    /// with a costly message build it only then.
    pub fn lists(&self, id: &str) -> bool {
        self.listed.get(id).copied().unwrap_or(0) < MAX_LISTED_PER_REQUIREMENT
            && self
                .max
                .is_none_or(|m| (self.report.violations.len() as u64) < m)
    }

    /// Records a violation of requirement `id`; gives its index in the listing, if listed.
    pub fn violation(
        &mut self,
        id: &str,
        subject: &str,
        at: Where,
        message: impl Into<String>,
        evidence: Evidence,
    ) -> Option<usize> {
        self.violation_with(id, subject, at, || (message.into(), evidence))
    }

    /// [`Recorder::violation`] with the message and evidence made only when the violation is
    /// listed.
    pub fn violation_with(
        &mut self,
        id: &str,
        subject: &str,
        at: Where,
        detail: impl FnOnce() -> (String, Evidence),
    ) -> Option<usize> {
        self.report.violation_count += 1;
        self.with_tally(id, |t| t.violations += 1);
        if !self.lists(id) {
            return None;
        }
        let (level, text, source) =
            self.with_tally(id, |t| (t.level.clone(), t.text.clone(), t.source.clone()));
        *self.listed.entry(id.to_owned()).or_insert(0) += 1;
        let (message, evidence) = detail();
        self.report.violations.push(Violation {
            requirement: id.to_owned(),
            level,
            text,
            source,
            subject: subject.to_owned(),
            at,
            message,
            evidence,
            end: None,
            duration_us: None,
        });
        Some(self.report.violations.len() - 1)
    }

    /// Ends the condition of the violation listed at `index` at `end`.
    pub fn violation_ended(&mut self, index: usize, end: Where) {
        if let Some(v) = self.report.violations.get_mut(index) {
            v.duration_us = match (v.at.time, end.time) {
                (Some(a), Some(b)) => Some(b.saturating_sub(a)),
                _ => None,
            };
            v.end = Some(end);
        }
    }

    /// Records a state the standard or manual allows (not a violation) that begins at
    /// `start`; gives its index for [`Recorder::ended`], if it is listed.
    pub fn allowed(
        &mut self,
        id: &str,
        subject: &str,
        start: Where,
        message: impl Into<String>,
        reason: impl Into<String>,
    ) -> Option<usize> {
        self.tally(id);
        let r = &mut self.report;
        r.allowed_count += 1;
        observe(
            &mut r.allowed,
            id,
            subject,
            start,
            message.into(),
            reason.into(),
        )
    }

    /// Records a check that could not decide, and why.
    pub fn inconclusive(
        &mut self,
        id: &str,
        subject: &str,
        at: Where,
        message: impl Into<String>,
        reason: impl Into<String>,
    ) {
        self.tally(id);
        let r = &mut self.report;
        r.inconclusive_count += 1;
        observe(
            &mut r.inconclusive,
            id,
            subject,
            at,
            message.into(),
            reason.into(),
        );
    }

    /// Ends the allowed state listed at `index` at `end`.
    pub fn ended(&mut self, index: usize, end: Where) {
        if let Some(o) = self.report.allowed.get_mut(index) {
            o.duration_us = match (o.start.time, end.time) {
                (Some(a), Some(b)) => Some(b.saturating_sub(a)),
                _ => None,
            };
            o.end = Some(end);
        }
    }

    /// The report being built.
    pub fn report(&mut self) -> &mut Report {
        &mut self.report
    }

    /// The report being built, read-only.
    pub fn view(&self) -> &Report {
        &self.report
    }

    /// The catalogue.
    pub fn catalog(&self) -> &Arc<Catalog> {
        &self.catalog
    }

    /// Ends recording.
    pub fn finish(self) -> Report {
        self.report
    }
}
