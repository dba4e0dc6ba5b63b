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

/// The readings chosen for selectable errata: the adopted one unless overridden by name.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Readings {
    chosen: std::collections::BTreeMap<String, String>,
}

/// A reading choice that names no selectable erratum or no reading of it.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum ReadingError {
    /// No erratum has this option.
    #[error("no erratum option {option:?}; options: {known}")]
    UnknownOption {
        /// The option given.
        option: String,
        /// The options there are.
        known: String,
    },
    /// The erratum has no such reading.
    #[error("erratum option {option:?} has no reading {reading:?}; readings: {known}")]
    UnknownReading {
        /// The option.
        option: String,
        /// The reading given.
        reading: String,
        /// The readings there are.
        known: String,
    },
}

impl Readings {
    /// Chooses `reading` for the erratum with `option`, checked against the family's errata.
    pub fn choose(
        &mut self,
        family: &crate::Family,
        option: &str,
        reading: &str,
    ) -> Result<(), ReadingError> {
        let Some(e) = family
            .errata
            .iter()
            .find(|e| e.option.as_deref() == Some(option))
        else {
            let known: Vec<&str> = family
                .errata
                .iter()
                .filter_map(|e| e.option.as_deref())
                .collect();
            return Err(ReadingError::UnknownOption {
                option: option.to_owned(),
                known: known.join(", "),
            });
        };
        if e.readings.iter().all(|r| r.id != reading) {
            let known: Vec<&str> = e.readings.iter().map(|r| r.id.as_str()).collect();
            return Err(ReadingError::UnknownReading {
                option: option.to_owned(),
                reading: reading.to_owned(),
                known: known.join(", "),
            });
        }
        self.chosen.insert(option.to_owned(), reading.to_owned());
        Ok(())
    }

    /// The reading in force for `option`: the chosen one, else the adopted one.
    pub fn reading<'f>(&'f self, family: &'f crate::Family, option: &str) -> Option<&'f str> {
        if let Some(r) = self.chosen.get(option) {
            return Some(r.as_str());
        }
        family
            .errata
            .iter()
            .find(|e| e.option.as_deref() == Some(option))
            .map(|e| e.adopted.as_str())
    }

    /// The reading of `option` in force, `adopted` when the family has no such option.
    pub fn reading_or<'f>(
        &'f self,
        family: &'f crate::Family,
        option: &str,
        adopted: &'f str,
    ) -> &'f str {
        self.reading(family, option).unwrap_or(adopted)
    }
}
