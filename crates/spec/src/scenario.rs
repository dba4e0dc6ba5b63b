//! `[[scenario]]` records (`spec/<family>/scenarios/*.toml`): hand-written conformance cases
//! kept as data, each a timed sequence of the family's steps.
//!
//! The spec crate reads the parts every family shares (id, description, requirements); the
//! family's model crate types `setup` and `steps` with its own step language, so that a
//! misspelt key is an error naming the scenario and the step (`spec/SCHEMA.md` "Steps and
//! scenarios").

use crate::{Family, Problem, ProblemKind};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

/// One hand-written case.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Case id inside the family's suite (`status/jog-keys`).
    pub id: String,
    /// One line: what the case shows.
    pub description: String,
    /// Requirements the case exercises.
    pub requirements: Vec<String>,
    /// How the family runs and judges the case (start format, tolerance, plot), typed by the
    /// family.
    #[serde(default)]
    pub setup: toml::Table,
    /// The steps, in order, typed by the family.
    pub steps: Vec<toml::Table>,
    /// File the record was loaded from.
    #[serde(skip)]
    pub file: String,
}

/// A scenario's `setup` or one of its steps does not fit the family's step language.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{part}: {message}")]
pub struct ScenarioError {
    /// Where: `setup` or `steps[N]` (1-based).
    pub part: String,
    /// The reader's message, naming the unknown, missing or mistyped key.
    pub message: String,
}

/// A scenario with its setup and steps typed by the family.
#[derive(Debug, Clone, PartialEq)]
pub struct TypedScenario<'a, Setup, Step> {
    /// The record.
    pub record: &'a Scenario,
    /// How the family runs it.
    pub setup: Setup,
    /// The steps.
    pub steps: Vec<Step>,
}

fn typed<T: DeserializeOwned>(part: String, t: &toml::Table) -> Result<T, ScenarioError> {
    toml::Value::Table(t.clone())
        .try_into()
        .map_err(|e: toml::de::Error| ScenarioError {
            part,
            message: e.message().trim().to_owned(),
        })
}

impl Scenario {
    /// Types the setup and every step with the family's types.
    pub fn typed<Setup: DeserializeOwned, Step: DeserializeOwned>(
        &self,
    ) -> Result<TypedScenario<'_, Setup, Step>, ScenarioError> {
        let setup = typed(String::from("setup"), &self.setup)?;
        let steps = self
            .steps
            .iter()
            .enumerate()
            .map(|(i, s)| typed(format!("steps[{}]", i.saturating_add(1)), s))
            .collect::<Result<_, _>>()?;
        Ok(TypedScenario {
            record: self,
            setup,
            steps,
        })
    }
}

/// Every scenario of `family` whose setup or steps do not read as `Setup` and `Step`, as a
/// spec problem naming file, record and key.
pub fn check_scenarios<Setup: DeserializeOwned, Step: DeserializeOwned>(
    family: &Family,
) -> Vec<Problem> {
    family
        .scenarios
        .iter()
        .filter_map(|s| {
            s.typed::<Setup, Step>().err().map(|e| {
                Problem::record(
                    s.file.clone(),
                    format!("scenario {:?}", s.id),
                    ProblemKind::Schema {
                        message: e.to_string(),
                    },
                )
            })
        })
        .collect()
}
