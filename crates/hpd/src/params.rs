//! Parameters by name on the serial line (manual 4.1, 4.2): `Pr31`, `Pr64:65` (a double word
//! over consecutive addresses), `b99.14` (one bit), with values scaled as the keypad shows them.

use crate::repr::{Data, Message};
use drivespec_spec::quote::quote;
use drivespec_spec::{Family, Parameter};

/// Why a parameter reference or value is not usable.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ParamError {
    /// No parameter of that name.
    #[error("unknown parameter {name:?}")]
    Unknown {
        /// The name given.
        name: String,
    },
    /// The parameter has no serial address (manual 4.2 lists none).
    #[error("{id} has no serial address")]
    NoAddress {
        /// Parameter id.
        id: String,
    },
    /// `PrN:M` where M is not at the address after N.
    #[error("{low}:{high} is not a double word: {high} does not follow {low} in memory")]
    NotConsecutive {
        /// Low word.
        low: String,
        /// High word.
        high: String,
    },
    /// A bit number outside the parameter.
    #[error("bit {bit} outside {id} ({bits} bits)")]
    Bit {
        /// Parameter id.
        id: String,
        /// The bit given.
        bit: u32,
        /// Bits in the parameter.
        bits: u32,
    },
    /// A value the target cannot take.
    #[error("value {}: {why}", quote(.text))]
    Value {
        /// The text given.
        text: String,
        /// What is wrong with it.
        why: &'static str,
    },
    /// A value outside the parameter's range.
    #[error("{id} = {value} outside range {range}")]
    Range {
        /// Parameter id.
        id: String,
        /// Raw value.
        value: i64,
        /// Allowed raw values.
        range: String,
    },
    /// Writing a read-only parameter.
    #[error("{id} is read-only")]
    ReadOnly {
        /// Parameter id.
        id: String,
    },
}

/// What a name refers to on the serial line.
#[derive(Debug, Clone, Copy)]
pub enum Target<'s> {
    /// One parameter of 1, 2 or 4 bytes.
    Param(&'s Parameter),
    /// Two word parameters at consecutive addresses read as one double word (low word first).
    Double(&'s Parameter, &'s Parameter),
    /// One bit of a parameter.
    Bit(&'s Parameter, u32),
}

impl<'s> Target<'s> {
    /// Looks up `Pr31`, `Pb40`, `Pr64:65`, `b99.14` (also `Pb99.14`, `P31`, `31`).
    pub fn parse(family: &'s Family, text: &str) -> Result<Target<'s>, ParamError> {
        let text = text.trim();
        let unknown = || ParamError::Unknown {
            name: text.to_owned(),
        };
        if let Some((word, bit)) = text.split_once('.') {
            let digits = word.trim_start_matches(|c: char| c.is_ascii_alphabetic());
            let p = family
                .parameter(digits)
                .or_else(|| family.parameter(word))
                .ok_or_else(unknown)?;
            let bit: u32 = bit.parse().map_err(|_| unknown())?;
            let bits = p.data_type.width().unwrap_or(0) * 8;
            if bit >= bits {
                return Err(ParamError::Bit {
                    id: p.id.clone(),
                    bit,
                    bits,
                });
            }
            return Ok(Target::Bit(p, bit));
        }
        if let Some((low, high)) = text.split_once(':') {
            let lo = family.parameter(low).ok_or_else(unknown)?;
            let prefix: String = low
                .chars()
                .take_while(|c| c.is_ascii_alphabetic())
                .collect();
            let hi = family
                .parameter(&format!("{prefix}{high}"))
                .or_else(|| family.parameter(high))
                .ok_or_else(unknown)?;
            let consecutive = matches!((lo.address, lo.size, hi.address, hi.size), (Some(a), Some(2), Some(b), Some(2)) if b == a + 2);
            if !consecutive {
                return Err(ParamError::NotConsecutive {
                    low: lo.id.clone(),
                    high: hi.id.clone(),
                });
            }
            return Ok(Target::Double(lo, hi));
        }
        family
            .parameter(text)
            .map(Target::Param)
            .ok_or_else(unknown)
    }

    /// The parameter (the low word of a double word).
    pub fn param(&self) -> &'s Parameter {
        match *self {
            Target::Param(p) | Target::Double(p, _) | Target::Bit(p, _) => p,
        }
    }

    /// Serial address and byte count.
    pub fn address(&self) -> Result<(u8, u8), ParamError> {
        let p = self.param();
        let no = || ParamError::NoAddress { id: p.id.clone() };
        let addr = u8::try_from(p.address.ok_or_else(no)?).map_err(|_| no())?;
        let size = u8::try_from(p.size.ok_or_else(no)?).map_err(|_| no())?;
        Ok(match self {
            Target::Double(..) => (addr, 4),
            _ => (addr, size),
        })
    }

    /// A read request for drive `addr` (manual 4.1 CMD 4).
    pub fn read(&self, addr: u8) -> Result<Message, ParamError> {
        let (par, lun) = self.address()?;
        Ok(Message::ReadParam { addr, lun, par })
    }

    /// A write request of the shown value `value` (manual 4.1 CMD 5; CMD 6 for a bit).
    pub fn write(&self, family: &Family, addr: u8, value: &str) -> Result<Message, ParamError> {
        let p = self.param();
        if !p.access.writable() {
            return Err(ParamError::ReadOnly { id: p.id.clone() });
        }
        let (par, lun) = self.address()?;
        match *self {
            Target::Bit(_, bit) => {
                let v = match value.trim() {
                    "1" | "true" | "on" => true,
                    "0" | "false" | "off" => false,
                    other => {
                        return Err(ParamError::Value {
                            text: other.to_owned(),
                            why: "a bit is 0 or 1",
                        })
                    }
                };
                let (par, mask, value) =
                    bit_change(family, par, bit, v).ok_or(ParamError::Bit {
                        id: p.id.clone(),
                        bit,
                        bits: u32::from(lun) * 8,
                    })?;
                Ok(Message::BitChange {
                    addr,
                    par,
                    mask,
                    value,
                })
            }
            Target::Double(..) => {
                let raw = parse_value(p, value)?;
                let data = Data::from_value(raw, 4).ok_or(ParamError::Value {
                    text: value.to_owned(),
                    why: "does not fit a double word",
                })?;
                Ok(Message::WriteParam { addr, par, data })
            }
            Target::Param(_) => {
                let raw = parse_value(p, value)?;
                let r = family.resolve(p, None);
                if let Some(range) = r.range.filter(|range| !range.contains(raw)) {
                    return Err(ParamError::Range {
                        id: p.id.clone(),
                        value: raw,
                        range: range.to_string(),
                    });
                }
                let data = Data::from_value(raw, lun).ok_or(ParamError::Value {
                    text: value.to_owned(),
                    why: "does not fit the parameter's size",
                })?;
                Ok(Message::WriteParam { addr, par, data })
            }
        }
    }

    /// The raw value in `data`, signed as the parameter is (double words: as a signed 32-bit value).
    pub fn value(&self, data: &Data) -> i64 {
        match self {
            Target::Bit(_, bit) => i64::from(data.unsigned() >> bit & 1),
            Target::Double(..) => i64::from(data.signed()),
            Target::Param(p) if p.data_type.signed() => i64::from(data.signed()),
            Target::Param(_) => i64::from(data.unsigned()),
        }
    }
}

/// (PAR, mask, value) of a bit change (manual 4.1 CMD 6), from the spec's bit-change table.
pub fn bit_change(family: &Family, address: u8, bit: u32, value: bool) -> Option<(u8, u8, u8)> {
    let bc = &family.hpd()?.bit_change;
    bc.encode(address, u8::try_from(bit).ok()?, value)
}

/// Parses a shown value (`25.3` for Pr33 with scale 0.1) into the raw value (`253`).
pub fn parse_value(p: &Parameter, text: &str) -> Result<i64, ParamError> {
    let t = text.trim();
    let bad = |why| ParamError::Value {
        text: t.to_owned(),
        why,
    };
    if let Some(hex) = t.strip_prefix("0x").or_else(|| t.strip_prefix("0X")) {
        return drivespec_spec::hex::parse_hex_digits(hex)
            .ok_or_else(|| bad("not a hex number of at most 32 bits"));
    }
    let scale = p.scale.unwrap_or(1.0);
    if scale == 1.0 {
        return t
            .parse::<i64>()
            .map_err(|_| bad("not a whole number (the parameter has no decimals)"));
    }
    let shown: f64 = t.parse().map_err(|_| bad("not a number"))?;
    let raw = (shown / scale).round();
    if !raw.is_finite() || raw.abs() > 4.0e9 {
        return Err(bad("too large for any parameter"));
    }
    Ok(raw as i64)
}
