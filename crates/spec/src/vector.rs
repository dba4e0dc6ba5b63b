//! `[[vector]]` records: the manuals' worked examples as language-neutral data.

mod bodies;

pub use bodies::*;

use serde::{Deserialize, Serialize};

/// What a vector exercises; the keys of `input` and `expect` depend on it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum VectorKind {
    /// An HPD serial request and the drive's answer.
    HpdFrame,
    /// An HPD PLC program run on given parameters.
    HpdPlc,
    /// An HPD PLC listing and its bytes.
    HpdPlcBytes,
    /// A formula from the manual with inputs and outputs.
    Formula,
    /// A PSD PKW command and response.
    Pkw,
    /// A process image and its fields.
    ProcessImage,
    /// An acyclic record read or write.
    Record,
    /// An IO-Link ISDU request and response.
    Isdu,
    /// A PSx time stamp and its effect.
    Timestamp,
    /// Position arithmetic (scaling, mapping end, limits).
    Position,
    /// IO-Link Direct Parameter page 1.
    DirectParameter,
    /// A sequence of process-data steps.
    Sequence,
}

impl VectorKind {
    /// The name used in spec files.
    pub fn as_str(self) -> &'static str {
        match self {
            VectorKind::HpdFrame => "hpd-frame",
            VectorKind::HpdPlc => "hpd-plc",
            VectorKind::HpdPlcBytes => "hpd-plc-bytes",
            VectorKind::Formula => "formula",
            VectorKind::Pkw => "pkw",
            VectorKind::ProcessImage => "process-image",
            VectorKind::Record => "record",
            VectorKind::Isdu => "isdu",
            VectorKind::Timestamp => "timestamp",
            VectorKind::Position => "position",
            VectorKind::DirectParameter => "direct-parameter",
            VectorKind::Sequence => "sequence",
        }
    }
}

/// Whether the example is a conforming exchange (Wycheproof's three verdicts).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum VectorResult {
    /// A conforming input and output.
    #[default]
    Valid,
    /// An input a conforming implementation rejects.
    Invalid,
    /// Either handling conforms.
    Acceptable,
}

/// One golden vector.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(try_from = "RawVector")]
pub struct Vector {
    /// Unique id in the family.
    pub id: String,
    /// What it exercises.
    pub kind: VectorKind,
    /// Manual section.
    pub source: String,
    /// One line.
    pub description: String,
    /// Valid, invalid or acceptable.
    pub result: VectorResult,
    /// Requirements it demonstrates.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub requirements: Vec<String>,
    /// Device model it applies to.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub model: Option<String>,
    /// Inputs and expected outputs, typed by `kind`.
    #[serde(flatten)]
    pub body: VectorBody,
    /// File the record was loaded from.
    #[serde(skip)]
    pub file: String,
}

/// A vector as written, before its body is typed by its kind.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawVector {
    id: String,
    kind: VectorKind,
    source: String,
    description: String,
    #[serde(default)]
    result: VectorResult,
    #[serde(default)]
    requirements: Vec<String>,
    #[serde(default)]
    model: Option<String>,
    #[serde(default)]
    input: toml::Table,
    #[serde(default)]
    expect: toml::Table,
}

impl TryFrom<RawVector> for Vector {
    type Error = BodyError;

    fn try_from(raw: RawVector) -> Result<Vector, BodyError> {
        Ok(Vector {
            body: VectorBody::parse(raw.kind, raw.input, raw.expect)?,
            id: raw.id,
            kind: raw.kind,
            source: raw.source,
            description: raw.description,
            result: raw.result,
            requirements: raw.requirements,
            model: raw.model,
            file: String::new(),
        })
    }
}

/// A vector's `input` or `expect` table does not fit its kind.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{table}: {message}")]
pub struct BodyError {
    /// `input` or `expect`.
    pub table: &'static str,
    /// What the schema check said (names the unknown, missing or mistyped key).
    pub message: String,
}

/// The `input` and `expect` tables of one vector.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Body<I, E> {
    /// Inputs.
    pub input: I,
    /// Expected outputs.
    pub expect: E,
}

impl<I: serde::de::DeserializeOwned, E: serde::de::DeserializeOwned> Body<I, E> {
    /// Types both tables.
    fn parse(input: toml::Table, expect: toml::Table) -> Result<Body<I, E>, BodyError> {
        Ok(Body {
            input: typed("input", input)?,
            expect: typed("expect", expect)?,
        })
    }
}

/// One table typed as `T`; the error names the table.
fn typed<T: serde::de::DeserializeOwned>(
    table: &'static str,
    t: toml::Table,
) -> Result<T, BodyError> {
    toml::Value::Table(t)
        .try_into()
        .map_err(|e: toml::de::Error| BodyError {
            table,
            message: e.message().to_owned(),
        })
}

/// The `input` and `expect` tables of a vector, typed by its kind.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum VectorBody {
    /// An HPD serial request and the drive's answer.
    HpdFrame(Box<Body<HpdFrameInput, HpdFrameExpect>>),
    /// An HPD PLC program run on given parameters.
    HpdPlc(Box<Body<HpdPlcInput, HpdPlcExpect>>),
    /// An HPD PLC listing and its bytes.
    HpdPlcBytes(Box<Body<HpdPlcBytesInput, HpdPlcBytesExpect>>),
    /// A formula from the manual with inputs and outputs.
    Formula(Box<Body<FormulaInput, FormulaExpect>>),
    /// A PSD PKW command and response.
    Pkw(Box<Body<PkwInput, PkwExpect>>),
    /// A process image and its fields.
    ProcessImage(Box<Body<ProcessImageInput, ProcessImageExpect>>),
    /// An acyclic record read or write.
    Record(Box<Body<RecordInput, RecordExpect>>),
    /// An IO-Link ISDU request and response.
    Isdu(Box<Body<IsduInput, IsduExpect>>),
    /// A PSx time stamp and its effect.
    Timestamp(Box<Body<TimestampInput, TimestampExpect>>),
    /// Position arithmetic (scaling, mapping end, limits).
    Position(Box<Body<PositionInput, PositionExpect>>),
    /// IO-Link Direct Parameter page 1.
    DirectParameter(Box<Body<DirectParameterInput, DirectParameterExpect>>),
    /// A sequence of process-data steps.
    Sequence(Box<Body<toml::Table, toml::Table>>),
}

impl VectorBody {
    /// Reads the `input` and `expect` tables of a vector of `kind`.
    fn parse(
        kind: VectorKind,
        input: toml::Table,
        expect: toml::Table,
    ) -> Result<VectorBody, BodyError> {
        Ok(match kind {
            VectorKind::HpdFrame => VectorBody::HpdFrame(Box::new(Body::parse(input, expect)?)),
            VectorKind::HpdPlc => VectorBody::HpdPlc(Box::new(Body::parse(input, expect)?)),
            VectorKind::HpdPlcBytes => {
                VectorBody::HpdPlcBytes(Box::new(Body::parse(input, expect)?))
            }
            VectorKind::Formula => VectorBody::Formula(Box::new(Body::parse(input, expect)?)),
            VectorKind::Pkw => VectorBody::Pkw(Box::new(Body::parse(input, expect)?)),
            VectorKind::ProcessImage => {
                VectorBody::ProcessImage(Box::new(Body::parse(input, expect)?))
            }
            VectorKind::Record => VectorBody::Record(Box::new(Body::parse(input, expect)?)),
            VectorKind::Isdu => VectorBody::Isdu(Box::new(Body::parse(input, expect)?)),
            VectorKind::Timestamp => VectorBody::Timestamp(Box::new(Body::parse(input, expect)?)),
            VectorKind::Position => VectorBody::Position(Box::new(Body::parse(input, expect)?)),
            VectorKind::DirectParameter => {
                VectorBody::DirectParameter(Box::new(Body::parse(input, expect)?))
            }
            VectorKind::Sequence => VectorBody::Sequence(Box::new(Body { input, expect })),
        })
    }

    /// Both tables as TOML (keys in name order), for display.
    pub fn tables(&self) -> (toml::Table, toml::Table) {
        let mut body = toml::Table::try_from(self).unwrap_or_default();
        let mut take = |key: &str| match body.remove(key) {
            Some(toml::Value::Table(t)) => t,
            _ => toml::Table::new(),
        };
        (take("input"), take("expect"))
    }
}

impl Vector {
    /// The body of a `HpdFrame` vector; `None` for other kinds.
    pub fn hpd_frame(&self) -> Option<&Body<HpdFrameInput, HpdFrameExpect>> {
        match &self.body {
            VectorBody::HpdFrame(b) => Some(b),
            _ => None,
        }
    }

    /// The body of a `HpdPlc` vector; `None` for other kinds.
    pub fn hpd_plc(&self) -> Option<&Body<HpdPlcInput, HpdPlcExpect>> {
        match &self.body {
            VectorBody::HpdPlc(b) => Some(b),
            _ => None,
        }
    }

    /// The body of a `HpdPlcBytes` vector; `None` for other kinds.
    pub fn hpd_plc_bytes(&self) -> Option<&Body<HpdPlcBytesInput, HpdPlcBytesExpect>> {
        match &self.body {
            VectorBody::HpdPlcBytes(b) => Some(b),
            _ => None,
        }
    }

    /// The body of a `Formula` vector; `None` for other kinds.
    pub fn formula(&self) -> Option<&Body<FormulaInput, FormulaExpect>> {
        match &self.body {
            VectorBody::Formula(b) => Some(b),
            _ => None,
        }
    }

    /// The body of a `Pkw` vector; `None` for other kinds.
    pub fn pkw(&self) -> Option<&Body<PkwInput, PkwExpect>> {
        match &self.body {
            VectorBody::Pkw(b) => Some(b),
            _ => None,
        }
    }

    /// The body of a `ProcessImage` vector; `None` for other kinds.
    pub fn process_image(&self) -> Option<&Body<ProcessImageInput, ProcessImageExpect>> {
        match &self.body {
            VectorBody::ProcessImage(b) => Some(b),
            _ => None,
        }
    }

    /// The body of a `Record` vector; `None` for other kinds.
    pub fn record(&self) -> Option<&Body<RecordInput, RecordExpect>> {
        match &self.body {
            VectorBody::Record(b) => Some(b),
            _ => None,
        }
    }

    /// The body of a `Isdu` vector; `None` for other kinds.
    pub fn isdu(&self) -> Option<&Body<IsduInput, IsduExpect>> {
        match &self.body {
            VectorBody::Isdu(b) => Some(b),
            _ => None,
        }
    }

    /// The body of a `Timestamp` vector; `None` for other kinds.
    pub fn timestamp(&self) -> Option<&Body<TimestampInput, TimestampExpect>> {
        match &self.body {
            VectorBody::Timestamp(b) => Some(b),
            _ => None,
        }
    }

    /// The body of a `Position` vector; `None` for other kinds.
    pub fn position(&self) -> Option<&Body<PositionInput, PositionExpect>> {
        match &self.body {
            VectorBody::Position(b) => Some(b),
            _ => None,
        }
    }

    /// The body of a `DirectParameter` vector; `None` for other kinds.
    pub fn direct_parameter(&self) -> Option<&Body<DirectParameterInput, DirectParameterExpect>> {
        match &self.body {
            VectorBody::DirectParameter(b) => Some(b),
            _ => None,
        }
    }

    /// The body of a `Sequence` vector; `None` for other kinds.
    pub fn sequence(&self) -> Option<&Body<toml::Table, toml::Table>> {
        match &self.body {
            VectorBody::Sequence(b) => Some(b),
            _ => None,
        }
    }
}
