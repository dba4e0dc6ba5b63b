//! Parameter values on the wire: word or double word by the parameter's type (manual 3.3 types,
//! 3.8 "word"/"double word", 3.2.2 record lengths), signed or not.

use drivespec_spec::{DataType, Family, Parameter};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::sync::Arc;

/// Width of a parameter value: 16 or 32 bits (manual 3.8 word / double word, 3.2.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Width {
    /// 16 bits.
    Word,
    /// 32 bits.
    Dword,
}

impl Width {
    /// Number of bits (manual 3.3, 3.8).
    pub fn bits(self) -> u32 {
        match self {
            Width::Word => 16,
            Width::Dword => 32,
        }
    }

    /// Number of bytes (manual 3.3, 3.8).
    pub fn bytes(self) -> usize {
        match self {
            Width::Word => 2,
            Width::Dword => 4,
        }
    }

    /// The width of `bits` bits (16 or 32) (manual 3.3, 3.8).
    pub fn from_bits(bits: u32) -> Option<Width> {
        match bits {
            16 => Some(Width::Word),
            32 => Some(Width::Dword),
            _ => None,
        }
    }

    /// The width carrying a numeric type (8- and 16-bit types travel as a word) (manual 3.3, 3.8).
    pub fn of_type(t: DataType) -> Option<Width> {
        match t.width()? {
            1 | 2 => Some(Width::Word),
            4 => Some(Width::Dword),
            _ => None,
        }
    }

    /// Smallest and largest value: of the signed type, the unsigned one, or either (`None`) (manual 3.3, 3.8).
    pub fn range(self, signed: Option<bool>) -> (i64, i64) {
        let umax = (1i64 << self.bits()) - 1;
        let smin = -(1i64 << (self.bits() - 1));
        match signed {
            Some(true) => (smin, umax >> 1),
            Some(false) => (0, umax),
            None => (smin, umax),
        }
    }

    /// The value of raw bits: two's complement when `signed` (manual 3.3, 3.8).
    pub fn to_value(self, raw: u32, signed: bool) -> i64 {
        match (self, signed) {
            (Width::Word, true) => i64::from(raw as u16 as i16),
            (Width::Word, false) => i64::from(raw as u16),
            (Width::Dword, true) => i64::from(raw as i32),
            (Width::Dword, false) => i64::from(raw),
        }
    }

    /// The raw bits of a value; `signed = None` accepts both readings (manual 3.3, 3.8).
    pub fn to_raw(self, value: i64, signed: Option<bool>) -> Result<u32, (i64, i64)> {
        let (min, max) = self.range(signed);
        if !(min..=max).contains(&value) {
            return Err((min, max));
        }
        let mask = (1u64 << self.bits()) - 1;
        Ok(u32::try_from(value as u64 & mask).unwrap_or(0))
    }
}

impl fmt::Display for Width {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Width::Word => "word",
            Width::Dword => "double word",
        })
    }
}

/// The PSD4xx parameter table, by number (manual 3.3), shared cheaply between the codecs.
#[derive(Debug, Clone)]
pub struct Params {
    list: Arc<[Parameter]>,
}

impl Params {
    /// The parameters of a family (manual 3.3).
    pub fn from_family(family: &Family) -> Params {
        Params {
            list: family.parameters.iter().cloned().collect(),
        }
    }

    /// The parameter with number `pnu` (manual 3.3 "Par. no.").
    pub fn get(&self, pnu: u32) -> Option<&Parameter> {
        self.list.iter().find(|p| p.number == pnu)
    }

    /// All parameters in spec order (manual 3.3, 3.8).
    pub fn iter(&self) -> impl Iterator<Item = &Parameter> {
        self.list.iter()
    }

    /// Width of a numeric scalar parameter (manual 3.3 types).
    pub fn width(&self, pnu: u32) -> Option<Width> {
        Width::of_type(self.get(pnu)?.data_type)
    }

    /// Whether the parameter is two's complement; None when unknown (manual 3.3, 3.8).
    pub fn signed(&self, pnu: u32) -> Option<bool> {
        self.get(pnu).map(|p| p.data_type.signed())
    }
}

/// `par 44 (Positioning window)`, or `par 20 (not in the parameter table)` (manual 3.3).
pub(crate) fn param_phrase(params: &Params, pnu: u32) -> String {
    match params.get(pnu) {
        Some(p) => format!("par {pnu} ({})", p.name),
        None => format!("par {pnu} (not in the parameter table)"),
    }
}

/// A raw value as shown, with scale and unit: `253` → `25.3 V` (manual 3.3 units).
pub(crate) fn shown(p: Option<&Parameter>, raw: i64) -> String {
    let Some(p) = p else {
        return raw.to_string();
    };
    let mut s = match p.scale {
        Some(scale) if scale != 1.0 && scale > 0.0 => {
            let decimals = (-scale.log10()).ceil().clamp(0.0, 6.0) as usize;
            format!("{:.*}", decimals, p.display_value(raw))
        }
        _ => raw.to_string(),
    };
    if let Some(u) = &p.unit {
        s.push(' ');
        s.push_str(u);
    }
    if let Some(named) = p.value_named(raw) {
        s.push_str(&format!(" ({})", named.name));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn widths() {
        assert_eq!(Width::Word.to_raw(-120, Some(true)), Ok(0xFF88));
        assert_eq!(Width::Word.to_value(0xFF88, true), -120);
        assert_eq!(Width::Word.to_value(0xFF88, false), 0xFF88);
        assert_eq!(Width::Dword.to_raw(-1000, None), Ok(0xFFFF_FC18));
        assert_eq!(Width::Word.to_raw(65536, None), Err((-32768, 65535)));
        assert_eq!(Width::Word.to_raw(-1, Some(false)), Err((0, 65535)));
        assert_eq!(
            Width::Dword.range(Some(true)),
            (i64::from(i32::MIN), i64::from(i32::MAX))
        );
        assert_eq!(Width::of_type(DataType::Bits16), Some(Width::Word));
        assert_eq!(Width::of_type(DataType::I32), Some(Width::Dword));
        assert_eq!(Width::of_type(DataType::String), None);
    }
}
