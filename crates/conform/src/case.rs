//! What every family's cases and results look like to the runner and the reports: a case's
//! identity and coverage, its outcome, and the evidence of each step.
//!
//! These types are the JSON report's vocabulary (schema in `crates/conform/README.md`, "JSON
//! report"): fields are only ever added.

use drivespec_spec::{Family, FamilyId, Level};
use serde::Serialize;

/// A conformance case as the runner, `--list` and the reports see it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CaseInfo {
    /// Stable ID, `family/group/...` (`hpd/param/Pr33/above-max`).
    pub id: String,
    /// The device family.
    pub family: FamilyId,
    /// Requirement IDs the case covers (its own and those its steps exercise), sorted.
    pub requirements: Vec<String>,
    /// `must` or `should`: the strongest level among its own requirements.
    pub level: Level,
    /// One line.
    pub description: String,
    /// The steps, one line each, in order.
    pub steps: Vec<String>,
}

/// A requirement quoted in a failure or the coverage matrix.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct RequirementRef {
    /// Stable ID.
    pub id: String,
    /// must, should or informative.
    pub level: Level,
    /// The requirement in the spec's words.
    pub text: String,
    /// The manual section it comes from.
    pub source: String,
}

impl RequirementRef {
    /// The requirement `id` of `family` with its level and text; None when the spec lacks it.
    pub fn of(family: &Family, id: &str) -> Option<RequirementRef> {
        family.requirement(id).map(|r| RequirementRef {
            id: r.id.clone(),
            level: r.level,
            text: r.text.clone(),
            source: r.source.clone(),
        })
    }

    /// `ID (section): text`, the way a failure names the requirement it broke.
    pub fn line(&self) -> String {
        format!("{} ({}): {}", self.id, self.source, self.text)
    }
}

/// Why a case failed.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Failure {
    /// Index of the step that failed (into `evidence`), when a step did.
    pub step: Option<usize>,
    /// One line: what went wrong.
    pub message: String,
    /// What the reference model did (or the rule demanded).
    pub expected: String,
    /// What the device under test did.
    pub got: String,
    /// The requirements the failing step and the case cover, with their text; the first is
    /// the one the device broke.
    pub requirements: Vec<RequirementRef>,
}

impl Failure {
    /// The requirement the device broke (the first one named).
    pub fn broken(&self) -> Option<&RequirementRef> {
        self.requirements.first()
    }

    /// The lines people read first: the broken requirement, what went wrong, what the manual
    /// allows and what came.
    pub fn headline(&self) -> Vec<String> {
        let mut lines = Vec::new();
        if let Some(r) = self.broken() {
            lines.push(format!("breaks {}", r.line()));
        }
        lines.push(self.message.clone());
        lines.push(format!("allowed: {}", self.expected));
        lines.push(format!("got:     {}", self.got));
        lines
    }
}

/// What running a case found, before expectations are applied.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(tag = "result", rename_all = "kebab-case")]
pub enum Outcome {
    /// Every judged step matched the reference.
    Pass,
    /// A step differed, or the transport failed.
    Fail(Failure),
    /// Not run, and why (a capability the transport lacks).
    Skip {
        /// Why.
        reason: String,
    },
}

impl Outcome {
    /// Whether the case failed.
    pub fn failed(&self) -> bool {
        matches!(self, Outcome::Fail(_))
    }
}

/// Who a step is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Role {
    /// Brings the device into the state the case needs; judged.
    Setup,
    /// The behaviour under test; judged.
    Check,
    /// Restores the state; recorded, never judged.
    Cleanup,
}

/// What one side put on the line in answer to a step (empty `hex`: silence).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Answer {
    /// Bytes on the line, hex; empty for silence.
    pub hex: String,
    /// The bytes in words (decoded frames), or `silence`.
    pub text: String,
    /// Time from the end of the request to the first byte (µs), when something came.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub delay_us: Option<u64>,
}

impl Answer {
    /// No bytes.
    pub fn silence() -> Answer {
        Answer {
            hex: String::new(),
            text: "silence".to_owned(),
            delay_us: None,
        }
    }

    /// Whether nothing came.
    pub fn is_silence(&self) -> bool {
        self.hex.is_empty()
    }
}

/// The evidence of one step: what was sent, what the reference and the device answered.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Record {
    /// Step index in the case.
    pub step: usize,
    /// Setup, check or cleanup.
    pub role: Role,
    /// What the step does, one line.
    pub action: String,
    /// Time of the step on the transport's clock (µs since the session opened).
    pub at_us: u64,
    /// Bytes sent, hex.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sent: Option<String>,
    /// The bytes sent in words.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sent_text: Option<String>,
    /// What the reference model answered.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub expected: Option<Answer>,
    /// What the device under test answered.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub got: Option<Answer>,
    /// Whether the step matched (None: not judged).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ok: Option<bool>,
    /// Remarks (comparison rule, tolerance, why not judged).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// A point where the manual allows several outcomes, and the one the device showed.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Finding {
    /// The device follows one reading of an erratum (`spec errata`).
    Reading {
        /// The erratum (`HPD-ERRATUM-058`).
        erratum: String,
        /// The reading's id in the spec.
        reading: String,
        /// What the reading says.
        text: String,
    },
    /// The manual leaves the point open (an example value, a silent point, a bound).
    Open {
        /// The requirement the point belongs to.
        requirement: String,
        /// What the device did, one line.
        text: String,
    },
}

impl Finding {
    /// One line: `follows reading R of E: text` or `ID: text`.
    pub fn line(&self) -> String {
        match self {
            Finding::Reading {
                erratum,
                reading,
                text,
            } => format!("follows reading `{reading}` of {erratum}: {text}"),
            Finding::Open { requirement, text } => format!("{requirement}: {text}"),
        }
    }
}

/// What a session reports for one case.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CaseRun {
    /// Pass, fail or skip.
    pub outcome: Outcome,
    /// Points where the device showed one of several outcomes the manual allows; a passing
    /// case with findings is `acceptable`.
    pub findings: Vec<Finding>,
    /// The requirements whose checks evaluated in this case (the judged steps' own
    /// requirements), for coverage by checking rather than by citation.
    pub checked: Vec<String>,
    /// One record per step run.
    pub evidence: Vec<Record>,
    /// Time that passed on the transport's clock (µs; virtual for `sim`).
    pub elapsed_us: u64,
}
