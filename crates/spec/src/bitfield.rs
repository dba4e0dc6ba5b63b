//! `[[bitfield]]` records: status and control words, HPD bit parameters, and their rules.

use serde::{Deserialize, Serialize};

/// Whether a rule sets or resets its bit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RuleAction {
    /// The bit becomes 1.
    Set,
    /// The bit becomes 0.
    Reset,
}

/// A set or reset condition of one bit.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BitRule {
    /// Set or reset.
    pub action: RuleAction,
    /// Event token (kebab-case), e.g. `target-reached`.
    pub trigger: String,
    /// What must also hold, in words.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub condition: Option<String>,
    /// Bits this one wins against when both would be set.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub priority_over: Vec<u32>,
    /// The requirement this rule states.
    pub requirement: String,
    /// The rule in words.
    pub text: String,
}

/// One bit of a bitfield.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BitfieldBit {
    /// Bit number (0 = least significant).
    pub bit: u32,
    /// Name.
    pub name: String,
    /// Reserved by the manual.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub reserved: bool,
    /// The master must keep this bit 0.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub must_be_zero: bool,
    /// Access when it differs from the parameter's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub access: Option<crate::Access>,
    /// Delivery value.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub default: Option<u8>,
    /// One line.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub description: Option<String>,
    /// Set and reset rules.
    #[serde(default, rename = "rule", skip_serializing_if = "Vec::is_empty")]
    pub rules: Vec<BitRule>,
}

/// A documented whole-word value (PSD control word 0x14 …).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BitfieldValue {
    /// The word.
    pub value: i64,
    /// Short kebab-case name.
    pub name: String,
    /// What it does.
    pub meaning: String,
    /// Manual section.
    pub source: String,
}

/// A word of bits with their names and rules.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Bitfield {
    /// Unique id in the family.
    pub id: String,
    /// The parameter holding the bits.
    pub param: String,
    /// Name.
    pub name: String,
    /// Number of bits.
    pub width: u32,
    /// HPD: operating modes this layout applies in.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub modes: Vec<u32>,
    /// Manual section.
    pub source: String,
    /// The bits.
    #[serde(default, rename = "bit")]
    pub bits: Vec<BitfieldBit>,
    /// Documented whole-word values.
    #[serde(default, rename = "value", skip_serializing_if = "Vec::is_empty")]
    pub values: Vec<BitfieldValue>,
    /// File the record was loaded from.
    #[serde(skip)]
    pub file: String,
}

impl Bitfield {
    /// One bit by number.
    pub fn bit(&self, n: u32) -> Option<&BitfieldBit> {
        self.bits.iter().find(|b| b.bit == n)
    }

    /// Mask of the bits the master must keep 0.
    pub fn must_be_zero_mask(&self) -> u64 {
        self.bits
            .iter()
            .filter(|b| b.must_be_zero && b.bit < 64)
            .fold(0, |m, b| m | 1 << b.bit)
    }

    /// Names of the bits set in `word`, in bit order.
    pub fn names_set(&self, word: u64) -> Vec<&str> {
        self.bits
            .iter()
            .filter(|b| b.bit < 64 && word >> b.bit & 1 == 1)
            .map(|b| b.name.as_str())
            .collect()
    }
}
