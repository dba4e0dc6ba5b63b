//! `[[bitfield]]` records: status and control words, HPD bit parameters, and their rules.

use crate::{Level, Requirement};
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
    /// The requirement this rule states; the first rule naming it creates its record.
    pub requirement: String,
    /// Level of the requirement.
    pub level: Level,
    /// The rule in words.
    pub text: String,
    /// The requirement's text when it is not
    /// `<bitfield id> bit <n> is <action>: <text> (<condition>)`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub statement: Option<String>,
    /// The requirement's manual section when it is not `<bitfield section> bit <n>`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub source: Option<String>,
    /// Parameters the requirement concerns.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub params: Vec<String>,
    /// Remark on the requirement.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
    /// Why no check over the interface can see the requirement; given, the requirement is
    /// not observable (as `observable = false` with `reason` on a `[[requirement]]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
}

impl BitRule {
    /// `<bitfield id> bit <n> is <action>: <text>`, with ` (<condition>)` when there is one.
    fn composed(&self, b: &Bitfield, bit: &BitfieldBit) -> String {
        let text = format!(
            "{} bit {} is {}: {}",
            b.id,
            bit.bit,
            self.action.as_str(),
            self.text
        );
        match &self.condition {
            Some(c) => format!("{text} ({c})"),
            None => text,
        }
    }
}

impl RuleAction {
    /// The word used in spec files and requirement texts.
    pub fn as_str(self) -> &'static str {
        match self {
            RuleAction::Set => "set",
            RuleAction::Reset => "reset",
        }
    }
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

    /// A circle of bits each winning over the next by `priority_over` (first bit repeated at
    /// the end), if the rules make one: then no bit wins.
    pub fn priority_cycle(&self) -> Option<Vec<u32>> {
        let over = |n: u32| {
            self.bit(n)
                .into_iter()
                .flat_map(|b| b.rules.iter().flat_map(|r| r.priority_over.iter().copied()))
        };
        // Depth-first search; `path` is the chain from the start, `done` the bits whose every
        // chain is known to end.
        let mut done: Vec<u32> = Vec::new();
        for start in self.bits.iter().map(|b| b.bit) {
            if done.contains(&start) {
                continue;
            }
            let mut path: Vec<(u32, Vec<u32>)> = vec![(start, over(start).collect())];
            while let Some((bit, next)) = path.last_mut() {
                let bit = *bit;
                match next.pop() {
                    Some(n) => {
                        if let Some(from) = path.iter().position(|(b, _)| *b == n) {
                            let mut circle: Vec<u32> =
                                path.iter().skip(from).map(|(b, _)| *b).collect();
                            circle.push(n);
                            return Some(circle);
                        }
                        if !done.contains(&n) && self.bit(n).is_some() {
                            path.push((n, over(n).collect()));
                        }
                    }
                    None => {
                        done.push(bit);
                        path.pop();
                    }
                }
            }
        }
        None
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

impl Bitfield {
    /// The manual section of the bits: the first part of `source` that is a bare section
    /// number (`3.4` in `3.1 ISDU 64; 3.4`).
    fn section(&self) -> &str {
        self.source
            .split(';')
            .map(str::trim)
            .find(|p| !p.is_empty() && p.chars().all(|c| c.is_ascii_digit() || c == '.'))
            .unwrap_or(self.source.as_str())
    }
}

/// The requirement records the rules of `bitfields` state, in rule order; the first rule
/// naming a requirement creates it.
pub(crate) fn rule_requirements(bitfields: &[Bitfield]) -> Vec<Requirement> {
    let mut out: Vec<Requirement> = Vec::new();
    for b in bitfields {
        for bit in &b.bits {
            for rule in &bit.rules {
                if out.iter().any(|r| r.id == rule.requirement) {
                    continue;
                }
                out.push(Requirement {
                    id: rule.requirement.clone(),
                    level: rule.level,
                    text: rule
                        .statement
                        .clone()
                        .unwrap_or_else(|| rule.composed(b, bit)),
                    source: rule
                        .source
                        .clone()
                        .unwrap_or_else(|| format!("{} bit {}", b.section(), bit.bit)),
                    params: rule.params.clone(),
                    note: rule.note.clone(),
                    observable: rule.reason.is_none(),
                    reason: rule.reason.clone(),
                    file: b.file.clone(),
                });
            }
        }
    }
    out
}
