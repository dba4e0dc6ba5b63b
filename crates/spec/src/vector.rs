//! `[[vector]]` records: the manuals' worked examples as language-neutral data.

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
    /// Keys `input` must have for a vector of this kind to mean anything.
    pub fn required_input(self) -> &'static [&'static str] {
        match self {
            VectorKind::HpdFrame => &["request"],
            VectorKind::HpdPlc => &["program"],
            VectorKind::HpdPlcBytes => &["listing"],
            VectorKind::Formula => &["formula"],
            VectorKind::Pkw => &["ak", "pnu"],
            VectorKind::ProcessImage => &["direction"],
            VectorKind::Record | VectorKind::Isdu => &["op", "index"],
            VectorKind::Timestamp => &["stamp"],
            VectorKind::Position | VectorKind::Sequence => &[],
            VectorKind::DirectParameter => &["bytes"],
        }
    }

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
#[serde(deny_unknown_fields)]
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
    #[serde(default)]
    pub result: VectorResult,
    /// Requirements it demonstrates.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub requirements: Vec<String>,
    /// Device model it applies to.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model: Option<String>,
    /// Inputs.
    #[serde(default)]
    pub input: toml::Table,
    /// Expected outputs.
    #[serde(default)]
    pub expect: toml::Table,
    /// File the record was loaded from.
    #[serde(skip)]
    pub file: String,
}

impl Vector {
    /// An input value.
    pub fn input(&self, key: &str) -> Option<&toml::Value> {
        self.input.get(key)
    }

    /// An expected value.
    pub fn expected(&self, key: &str) -> Option<&toml::Value> {
        self.expect.get(key)
    }
}
