//! What the steps of the cyclic families share: the start state of a sequence, the waits and
//! the typed reading of a `sequence` vector, where a misspelt key is an error naming the key
//! (`spec/SCHEMA.md` "Steps and scenarios").
//!
//! A family defines the vector's `input` (a [`SequenceInput`] naming its step type) and the
//! vector's `expect`; its typed vector is a [`SequenceVector`] of the two. [`check_sequences`]
//! reads every `sequence` vector of a family with it and reports each one that does not fit
//! as a spec [`Problem`] naming file, record and key.

use drivespec_spec::{Family, Problem, ProblemKind, Vector, VectorKind};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// A value in a sequence's start state: a number, or text for a string parameter.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum StateValue {
    /// An integer parameter value.
    Int(i64),
    /// A string parameter value.
    Text(String),
}

impl StateValue {
    /// The integer, None for text.
    pub fn int(&self) -> Option<i64> {
        match self {
            StateValue::Int(n) => Some(*n),
            StateValue::Text(_) => None,
        }
    }
}

/// The start state of a sequence: parameter number (or ISDU index) to value.
pub type State = BTreeMap<String, StateValue>;

/// What a step waits for after its action.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Wait {
    /// Until the drive reports a run.
    Running,
    /// Until the drive stands still.
    Standstill,
    /// Until the status word stops changing.
    Settle,
}

/// A family's typed `sequence` vector: its `input` (start state and steps) and its `expect`.
pub trait Sequence: Sized {
    /// The vector's `input`.
    type Input: DeserializeOwned;
    /// The vector's `expect`.
    type Expect: DeserializeOwned;
    /// One step of the input, read on its own so that an error names the step.
    type Step: DeserializeOwned;
    /// Builds the sequence from its typed parts.
    fn new(input: Self::Input, expect: Self::Expect) -> Self;
}

/// Bytes written as hex text in a step (`7E 21 02`; blanks optional): serde's `with` module
/// of the record and ISDU writes.
pub mod hex_text {
    use drivespec_spec::hex::{parse_hex, to_hex};
    use serde::{Deserialize, Deserializer, Serializer};

    /// The bytes as hex text.
    pub fn serialize<S: Serializer>(data: &[u8], s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&to_hex(data))
    }

    /// The bytes of hex text.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<u8>, D::Error> {
        let text = String::deserialize(d)?;
        parse_hex(&text).map_err(serde::de::Error::custom)
    }
}

/// The `input` of a family's `sequence` vector, naming the type of one of its steps.
pub trait SequenceInput: DeserializeOwned {
    /// One step of the input, read on its own so that an error names the step.
    type Step: DeserializeOwned;
}

/// A family's typed `sequence` vector: its `input` (start state and steps) and its `expect`.
#[derive(Debug, Clone, PartialEq)]
pub struct SequenceVector<I, E> {
    /// Start state and steps.
    pub input: I,
    /// What holds at the end.
    pub expect: E,
}

impl<I: SequenceInput, E: DeserializeOwned> Sequence for SequenceVector<I, E> {
    type Input = I;
    type Expect = E;
    type Step = I::Step;
    fn new(input: I, expect: E) -> SequenceVector<I, E> {
        SequenceVector { input, expect }
    }
}

/// Why a `sequence` vector does not fit its family's step type.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{part}: {message}")]
pub struct SequenceError {
    /// Where: `input`, `input.steps[N]` (1-based) or `expect`.
    pub part: String,
    /// The reader's message, naming the unknown or missing key.
    pub message: String,
}

fn typed<T: DeserializeOwned>(part: String, value: toml::Value) -> Result<T, SequenceError> {
    value
        .try_into()
        .map_err(|e: toml::de::Error| SequenceError {
            part,
            message: e.message().trim().to_owned(),
        })
}

/// Reads a `sequence` vector as the family's typed [`Sequence`].
pub fn read_sequence<S: Sequence>(v: &Vector) -> Result<S, SequenceError> {
    let empty = toml::Table::new();
    let (input, expect) = v
        .sequence()
        .map_or((&empty, &empty), |b| (&b.input, &b.expect));
    if let Some(steps) = input.get("steps").and_then(toml::Value::as_array) {
        for (i, step) in steps.iter().enumerate() {
            typed::<S::Step>(
                format!("input.steps[{}]", i.saturating_add(1)),
                step.clone(),
            )?;
        }
    }
    let input = typed(String::from("input"), toml::Value::Table(input.clone()))?;
    let expect = typed(String::from("expect"), toml::Value::Table(expect.clone()))?;
    Ok(S::new(input, expect))
}

/// Every `sequence` vector of `family` that does not read as `S`, as a spec problem naming
/// file, record and key.
pub fn check_sequences<S: Sequence>(family: &Family) -> Vec<Problem> {
    family
        .vectors
        .iter()
        .filter(|v| v.kind == VectorKind::Sequence)
        .filter_map(|v| {
            read_sequence::<S>(v).err().map(|e| {
                Problem::record(
                    v.file.clone(),
                    format!("vector {:?}", v.id),
                    ProblemKind::Schema {
                        message: e.to_string(),
                    },
                )
            })
        })
        .collect()
}
