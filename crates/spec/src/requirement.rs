//! `[[requirement]]` records: every normative statement of a manual, with a stable ID.

use serde::{Deserialize, Serialize};

/// How binding a requirement is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Level {
    /// A conforming implementation must do this.
    Must,
    /// A conforming implementation should do this.
    Should,
    /// Describes behaviour without binding it.
    Informative,
}

impl Level {
    /// The name used in spec files.
    pub fn as_str(self) -> &'static str {
        match self {
            Level::Must => "must",
            Level::Should => "should",
            Level::Informative => "informative",
        }
    }
}

/// One normative statement.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Requirement {
    /// Stable ID, e.g. `PSD-PKW-003`.
    pub id: String,
    /// Must, should or informative.
    pub level: Level,
    /// The statement in our words.
    pub text: String,
    /// Manual section.
    pub source: String,
    /// Parameters it concerns.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub params: Vec<String>,
    /// Remark.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
    /// Whether a check over the interface can observe it; `false` for safety instructions
    /// and motor physics that no message or cyclic image shows.
    #[serde(default = "observable_default", skip_serializing_if = "is_observable")]
    pub observable: bool,
    /// Why the requirement cannot be observed over the interface; given exactly when
    /// `observable` is `false`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// File the record was loaded from.
    #[serde(skip)]
    pub file: String,
}

/// A requirement is observable unless its record says otherwise.
fn observable_default() -> bool {
    true
}

/// Whether `observable` has its default value and is left out when written.
fn is_observable(observable: &bool) -> bool {
    *observable
}
