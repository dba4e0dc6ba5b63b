//! `[[parameter]]` records: one per parameter, ISDU entry or HPD Pr/Pb.

use crate::Ranges;
use serde::{Deserialize, Serialize};

/// Wire data type of a parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum DataType {
    /// Unsigned 8 bit.
    U8,
    /// Signed 8 bit.
    I8,
    /// Unsigned 16 bit.
    U16,
    /// Signed 16 bit.
    I16,
    /// Unsigned 32 bit.
    U32,
    /// Signed 32 bit.
    I32,
    /// Character string (see `length`).
    String,
    /// 8 bits, each with its own meaning.
    Bits8,
    /// 16 bits, each with its own meaning.
    Bits16,
    /// 32 bits, each with its own meaning.
    Bits32,
}

impl DataType {
    /// Smallest and largest raw value, for numeric types.
    pub fn bounds(self) -> Option<(i64, i64)> {
        Some(match self {
            DataType::U8 | DataType::Bits8 => (0, 0xFF),
            DataType::I8 => (-0x80, 0x7F),
            DataType::U16 | DataType::Bits16 => (0, 0xFFFF),
            DataType::I16 => (-0x8000, 0x7FFF),
            DataType::U32 | DataType::Bits32 => (0, 0xFFFF_FFFF),
            DataType::I32 => (-0x8000_0000, 0x7FFF_FFFF),
            DataType::String => return None,
        })
    }

    /// Width in bytes of numeric types.
    pub fn width(self) -> Option<u32> {
        match self {
            DataType::U8 | DataType::I8 | DataType::Bits8 => Some(1),
            DataType::U16 | DataType::I16 | DataType::Bits16 => Some(2),
            DataType::U32 | DataType::I32 | DataType::Bits32 => Some(4),
            DataType::String => None,
        }
    }

    /// Whether the raw value is two's complement.
    pub fn signed(self) -> bool {
        matches!(self, DataType::I8 | DataType::I16 | DataType::I32)
    }

    /// The name used in spec files.
    pub fn as_str(self) -> &'static str {
        match self {
            DataType::U8 => "u8",
            DataType::I8 => "i8",
            DataType::U16 => "u16",
            DataType::I16 => "i16",
            DataType::U32 => "u32",
            DataType::I32 => "i32",
            DataType::String => "string",
            DataType::Bits8 => "bits8",
            DataType::Bits16 => "bits16",
            DataType::Bits32 => "bits32",
        }
    }
}

/// Who may read or write a parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Access {
    /// Read only.
    R,
    /// Write only.
    W,
    /// Read and write.
    Rw,
    /// Written only through cyclic process data (PSD par 32, 33).
    Pd,
}

impl Access {
    /// Whether a parameter access may write it.
    pub fn writable(self) -> bool {
        matches!(self, Access::W | Access::Rw)
    }

    /// Whether a parameter access may read it.
    pub fn readable(self) -> bool {
        matches!(self, Access::R | Access::Rw | Access::Pd)
    }

    /// The name used in spec files.
    pub fn as_str(self) -> &'static str {
        match self {
            Access::R => "r",
            Access::W => "w",
            Access::Rw => "rw",
            Access::Pd => "pd",
        }
    }
}

/// A documented value of an enumerated parameter (PSD par 96, PSx ISDU 193, HPD Pr26).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnumValue {
    /// Raw value.
    pub value: i64,
    /// Short kebab-case name.
    pub name: String,
    /// What the value does or means.
    pub meaning: String,
}

/// The meaning of a parameter in particular operating modes (HPD Pr50–Pr69).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModeMeaning {
    /// Operating modes (Pr31) this meaning applies in.
    pub modes: Vec<u32>,
    /// Name in those modes.
    pub name: String,
    /// Unit in those modes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unit: Option<String>,
    /// Scale in those modes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<f64>,
    /// Range in those modes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub range: Option<Ranges>,
    /// Default in those modes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub default: Option<i64>,
    /// Access in those modes, where it differs from the parameter's (Pr55 is read-only in
    /// modes 2, 8 and 10, manual 3.6.2, 3.6.3, 3.6.5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub access: Option<Access>,
    /// One line.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub description: Option<String>,
}

/// One parameter (see `spec/SCHEMA.md`).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Parameter {
    /// Unique key in the family.
    pub id: String,
    /// Parameter number or ISDU index.
    pub number: u32,
    /// ISDU sub-index.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub subindex: Option<u32>,
    /// Designation.
    pub name: String,
    /// Parameter group.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub group: Option<String>,
    /// Wire data type.
    #[serde(rename = "type")]
    pub data_type: DataType,
    /// Maximum string length in bytes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub length: Option<u32>,
    /// Number of array elements.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub array: Option<u32>,
    /// Unit of the shown value.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unit: Option<String>,
    /// Shown value = raw × scale.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<f64>,
    /// Allowed raw values (absent: the data type's range).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub range: Option<Ranges>,
    /// The range comes from the device model.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub range_model: bool,
    /// The model attribute that is each model's range maximum (with `range_model`; the
    /// models give the minimum as `min`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model_max: Option<String>,
    /// A range that depends on other parameters, in words.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub range_note: Option<String>,
    /// Raw delivery value.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub default: Option<i64>,
    /// The default comes from the device model.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub default_model: bool,
    /// Where each model's default comes from (with `default_model`): a model attribute, or
    /// `max` for the top of the model's range.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model_default: Option<String>,
    /// Delivery value of a string parameter.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub default_text: Option<String>,
    /// Read/write access.
    pub access: Access,
    /// Kept in non-volatile memory.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub saved: Option<bool>,
    /// Write conditions (`standstill`, `plc-stopped`, `restart`, `reset`, `drive-disabled`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub conditions: Vec<String>,
    /// HPD serial address.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub address: Option<u32>,
    /// HPD serial length in bytes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub size: Option<u32>,
    /// The value changes by itself.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub live: bool,
    /// The value is the device's own (identity, measurement): the manual gives an example or
    /// nothing, so a conforming device may report any value of the type, length and range.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub per_device: bool,
    /// Manual section.
    pub source: String,
    /// One line.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub description: Option<String>,
    /// Enumerated values.
    #[serde(default, rename = "value", skip_serializing_if = "Vec::is_empty")]
    pub values: Vec<EnumValue>,
    /// Operating-mode-specific meanings.
    #[serde(default, rename = "mode", skip_serializing_if = "Vec::is_empty")]
    pub modes: Vec<ModeMeaning>,
    /// File the record was loaded from.
    #[serde(skip_deserializing, skip_serializing)]
    pub file: String,
}

impl Parameter {
    /// Whether the serial/bus write conditions include `cond`.
    pub fn has_condition(&self, cond: &str) -> bool {
        self.conditions.iter().any(|c| c == cond)
    }

    /// Shown value for a raw value (`253` → `25.3` for Pr33).
    pub fn display_value(&self, raw: i64) -> f64 {
        raw as f64 * self.scale.unwrap_or(1.0)
    }

    /// The documented meaning of a raw value, if the parameter enumerates its values.
    pub fn value_named(&self, raw: i64) -> Option<&EnumValue> {
        self.values.iter().find(|v| v.value == raw)
    }
}

/// Range and default of a parameter for one model.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Resolved {
    /// Allowed raw values (None for strings).
    pub range: Option<Ranges>,
    /// Raw delivery value.
    pub default: Option<i64>,
}
