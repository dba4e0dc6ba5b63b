//! Problems found while loading or validating a spec tree.

use std::fmt;

/// Every problem found in a spec tree; loading fails when there is at least one.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub struct SpecErrors(pub Vec<Problem>);

impl fmt::Display for SpecErrors {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, p) in self.0.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(f, "{p}")?;
        }
        Ok(())
    }
}

/// One problem: the file, the record in it (if any), and what is wrong.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub struct Problem {
    /// Path of the file relative to the spec root.
    pub file: String,
    /// The record, e.g. `parameter "44"` or `model "PSD426"`.
    pub record: Option<String>,
    /// What is wrong.
    pub kind: ProblemKind,
}

impl Problem {
    /// A problem with a whole file.
    pub fn file(file: impl Into<String>, kind: ProblemKind) -> Problem {
        Problem {
            file: file.into(),
            record: None,
            kind,
        }
    }

    /// A problem with one record of a file.
    pub fn record(
        file: impl Into<String>,
        record: impl Into<String>,
        kind: ProblemKind,
    ) -> Problem {
        Problem {
            file: file.into(),
            record: Some(record.into()),
            kind,
        }
    }
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.record {
            Some(r) => write!(f, "{}: {}: {}", self.file, r, self.kind),
            None => write!(f, "{}: {}", self.file, self.kind),
        }
    }
}

/// What is wrong with a spec file or record.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ProblemKind {
    /// The file could not be read.
    #[error("cannot read: {message}")]
    Io {
        /// The operating system's message.
        message: String,
    },
    /// The file is larger than the loader accepts.
    #[error("file is larger than the limit of {limit} bytes")]
    TooLarge {
        /// The limit.
        limit: u64,
    },
    /// The tree has more files than the loader accepts.
    #[error("more than {limit} files")]
    TooMany {
        /// The limit.
        limit: usize,
    },
    /// The file is not valid TOML.
    #[error("invalid TOML at line {line}, column {column}: {message}")]
    Syntax {
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// The parser's message.
        message: String,
    },
    /// A record does not match the schema (unknown or missing key, wrong type).
    #[error("{message}")]
    Schema {
        /// What the schema check said.
        message: String,
    },
    /// A family folder or a required file is missing.
    #[error("missing {what}")]
    Missing {
        /// What is missing.
        what: String,
    },
    /// An identifier is used twice.
    #[error("duplicate {what} {id:?} (first in {first})")]
    Duplicate {
        /// Kind of identifier.
        what: &'static str,
        /// The identifier.
        id: String,
        /// Where it was first defined.
        first: String,
    },
    /// A reference names something that does not exist.
    #[error("{what} {id:?} does not exist")]
    Dangling {
        /// Kind of thing referred to.
        what: &'static str,
        /// The name used.
        id: String,
    },
    /// An identifier has the wrong form.
    #[error("identifier {id:?} does not match {pattern}")]
    BadId {
        /// The identifier.
        id: String,
        /// The expected form.
        pattern: &'static str,
    },
    /// A default or enumerated value lies outside its range.
    #[error("{what} {value} outside range {range}{}", model.as_ref().map(|m| format!(" for model {m}")).unwrap_or_default())]
    OutOfRange {
        /// Which value.
        what: &'static str,
        /// The value.
        value: i64,
        /// The range it should be in.
        range: String,
        /// The model the range belongs to.
        model: Option<String>,
    },
    /// A range is malformed (min > max, or outside the data type).
    #[error("range {min}..{max} {reason}")]
    BadRange {
        /// Lower end.
        min: i64,
        /// Upper end.
        max: i64,
        /// Why it is wrong.
        reason: &'static str,
    },
    /// A model lacks a value the parameter says comes from the model.
    #[error("model {model:?} gives no {what} for parameter {param:?}")]
    ModelValueMissing {
        /// The model.
        model: String,
        /// The parameter.
        param: String,
        /// `range` or `default`.
        what: &'static str,
    },
    /// Two serial addresses overlap.
    #[error("address {address:#05x}..{end:#05x} overlaps parameter {other:?}")]
    AddressOverlap {
        /// First byte.
        address: u32,
        /// One past the last byte.
        end: u32,
        /// The other parameter.
        other: String,
    },
    /// A value is not allowed where it stands.
    #[error("{message}")]
    Invalid {
        /// What is wrong, naming the expected and found values.
        message: String,
    },
}
