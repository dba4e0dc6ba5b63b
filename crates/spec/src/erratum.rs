//! `[[erratum]]` records: contradictions in a manual, the readings, and the one adopted.

use serde::{Deserialize, Serialize};

/// One way to read a contradictory passage.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Reading {
    /// Short id, e.g. `zero`.
    pub id: String,
    /// The reading.
    pub text: String,
    /// Where the manual says so.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub source: Option<String>,
}

/// A contradiction or error in a manual.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Erratum {
    /// Stable ID, e.g. `HPD-ERRATUM-001`.
    pub id: String,
    /// Manual sections involved.
    pub source: String,
    /// One line.
    pub title: String,
    /// Id of the reading adopted.
    pub adopted: String,
    /// Why.
    pub reason: String,
    /// Name of the option that switches the reading, where devices could go either way.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub option: Option<String>,
    /// Requirements that depend on the reading.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub requirements: Vec<String>,
    /// The readings.
    #[serde(rename = "reading")]
    pub readings: Vec<Reading>,
    /// File the record was loaded from.
    #[serde(skip)]
    pub file: String,
}

impl Erratum {
    /// The adopted reading.
    pub fn adopted_reading(&self) -> Option<&Reading> {
        self.readings.iter().find(|r| r.id == self.adopted)
    }
}
