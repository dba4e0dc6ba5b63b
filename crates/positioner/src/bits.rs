//! A status or control word decoded against a spec [`Bitfield`] (PSD4xx manual 3.6 and 3.7,
//! PSx3xx manual 3.5): the bits set with their names, the reserved bits the master must keep 0
//! that are set anyway, set bits the spec does not describe, and the documented whole-word
//! value (PSD4xx control word 0x14 "release-and-transfer" …) if the word is one.
//!
//! Allocation is bounded by the width of the word (at most 64 entries per list).

use drivespec_spec::Bitfield;
use serde::Serialize;
use std::fmt;

/// One bit set in a word (PSD4xx 3.6/3.7).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct SetBit {
    /// Bit number, 0 = least significant.
    pub bit: u32,
    /// The spec's name of the bit.
    pub name: String,
    /// The manual marks the bit reserved.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub reserved: bool,
}

/// A documented whole-word value (PSD4xx 3.7/4.1 control word values).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct NamedWord {
    /// Kebab-case name from the spec.
    pub name: String,
    /// What the value does.
    pub meaning: String,
}

/// A word decoded against a bitfield (PSD4xx 3.6/3.7, PSx3xx 3.5).
///
/// JSON: `{"bitfield", "word", "set": [{"bit", "name", "reserved"?}], "must_be_zero": [bit],
/// "undefined": [bit], "value"?: {"name", "meaning"}}`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct BitsDecoded {
    /// The bitfield's spec id (`status`, `control`).
    pub bitfield: String,
    /// Width of the word in bits.
    #[serde(skip)]
    pub width: u32,
    /// The raw word.
    pub word: u64,
    /// The bits set that the spec describes, in bit order.
    pub set: Vec<SetBit>,
    /// Must-be-zero bits that are set (violations by the master), in bit order.
    pub must_be_zero: Vec<u32>,
    /// Set bits the spec does not describe (none listed, or beyond the width), in bit order.
    pub undefined: Vec<u32>,
    /// The documented whole-word value the word equals, if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub value: Option<NamedWord>,
}

impl BitsDecoded {
    /// Whether no must-be-zero bit and no undescribed bit is set (PSD4xx 3.6/3.7).
    pub fn is_clean(&self) -> bool {
        self.must_be_zero.is_empty() && self.undefined.is_empty()
    }

    /// Whether bit `n` is set (PSD4xx 3.6/3.7).
    pub fn is_set(&self, n: u32) -> bool {
        n < 64 && self.word >> n & 1 == 1
    }
}

/// Decodes `word` against `bitfield` (PSD4xx 3.6/3.7, PSx3xx 3.5).
pub fn decode_bits(bitfield: &Bitfield, word: u64) -> BitsDecoded {
    let mut set = Vec::new();
    let mut must_be_zero = Vec::new();
    let mut undefined = Vec::new();
    for n in (0..64u32).filter(|n| word >> n & 1 == 1) {
        match bitfield.bit(n).filter(|_| n < bitfield.width) {
            Some(b) => {
                if b.must_be_zero {
                    must_be_zero.push(n);
                }
                set.push(SetBit {
                    bit: n,
                    name: b.name.clone(),
                    reserved: b.reserved,
                });
            }
            None => undefined.push(n),
        }
    }
    let value = bitfield
        .values
        .iter()
        .find(|v| u64::try_from(v.value).ok() == Some(word))
        .map(|v| NamedWord {
            name: v.name.clone(),
            meaning: v.meaning.clone(),
        });
    BitsDecoded {
        bitfield: bitfield.id.clone(),
        width: bitfield.width,
        word,
        set,
        must_be_zero,
        undefined,
        value,
    }
}

impl fmt::Display for BitsDecoded {
    /// `0x0014: bit 2 Transfer target value, bit 4 Release (release-and-transfer)`, then the
    /// violations: `; must be 0: bit 3` and `; undefined: bit 20`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let digits = usize::try_from(self.width.clamp(4, 64).div_ceil(4)).unwrap_or(4);
        write!(f, "0x{:0digits$X}", self.word)?;
        if self.set.is_empty() && self.undefined.is_empty() {
            f.write_str(": no bit set")?;
        }
        for (i, b) in self.set.iter().enumerate() {
            f.write_str(if i == 0 { ": " } else { ", " })?;
            write!(f, "bit {} {}", b.bit, b.name)?;
        }
        if let Some(v) = &self.value {
            write!(f, " ({})", v.name)?;
        }
        let list = |f: &mut fmt::Formatter<'_>, what: &str, bits: &[u32]| -> fmt::Result {
            if bits.is_empty() {
                return Ok(());
            }
            write!(f, "; {what}: bit")?;
            for (i, b) in bits.iter().enumerate() {
                write!(f, "{}{b}", if i == 0 { " " } else { ", " })?;
            }
            Ok(())
        };
        list(f, "must be 0", &self.must_be_zero)?;
        list(f, "undefined", &self.undefined)
    }
}
