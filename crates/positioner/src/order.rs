//! Byte order of multi-byte values as a setting (PSD4xx manual 3.5 notice "UseAsBits";
//! PSx3xx manual 3.3.2).
//!
//! Neither manual pins the order down for every tool: the PSD4xx manual only says that control
//! and status words are inverted relative to the other values (3.5 notice), and some IO-Link
//! masters swap the bytes of the PSx3xx (3.3.2). The order is therefore a value passed to the
//! codecs, defaulting to the spec's adopted reading, never a constant.

use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// Order of the bytes of a multi-byte value (PSD4xx 3.5, PSx3xx 3.3.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ByteOrder {
    /// Most significant byte first (PROFINET and IO-Link network order).
    BigEndian,
    /// Least significant byte first.
    LittleEndian,
}

impl ByteOrder {
    /// Both orders, big-endian first (PSD4xx 3.5).
    pub const ALL: [ByteOrder; 2] = [ByteOrder::BigEndian, ByteOrder::LittleEndian];

    /// The other order (PSD4xx 3.5: control and status word are inverted).
    pub fn flipped(self) -> ByteOrder {
        match self {
            ByteOrder::BigEndian => ByteOrder::LittleEndian,
            ByteOrder::LittleEndian => ByteOrder::BigEndian,
        }
    }

    /// `self`, or the other order when `invert` holds (PSD4xx 3.5 notice "UseAsBits").
    pub fn inverted_if(self, invert: bool) -> ByteOrder {
        if invert {
            self.flipped()
        } else {
            self
        }
    }

    /// The name used in the spec and on the command line: `big-endian`, `little-endian` (PSD4xx 3.5).
    pub fn as_str(self) -> &'static str {
        match self {
            ByteOrder::BigEndian => "big-endian",
            ByteOrder::LittleEndian => "little-endian",
        }
    }

    /// The unsigned value of up to 8 bytes in this order; None for more than 8 bytes (PSD4xx 3.5).
    pub fn decode(self, bytes: &[u8]) -> Option<u64> {
        if bytes.len() > 8 {
            return None;
        }
        let fold = |acc: u64, b: &u8| (acc << 8) | u64::from(*b);
        Some(match self {
            ByteOrder::BigEndian => bytes.iter().fold(0, fold),
            ByteOrder::LittleEndian => bytes.iter().rev().fold(0, fold),
        })
    }

    /// Writes the low `out.len()` bytes of `value` in this order (at most 8 bytes are
    /// meaningful; further bytes are written as 0 in the value's position) (PSD4xx 3.5).
    pub fn encode(self, value: u64, out: &mut [u8]) {
        let n = out.len();
        for (i, slot) in out.iter_mut().enumerate() {
            let shift = match self {
                ByteOrder::BigEndian => n - 1 - i,
                ByteOrder::LittleEndian => i,
            };
            *slot = value
                .checked_shr(u32::try_from(shift * 8).unwrap_or(u32::MAX))
                .map_or(0, |v| (v & 0xFF) as u8);
        }
    }
}

impl fmt::Display for ByteOrder {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A text that names no byte order (PSD4xx 3.5).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown byte order {found:?}: expected big-endian (be) or little-endian (le)")]
pub struct ByteOrderParseError {
    /// The text given.
    pub found: String,
}

impl FromStr for ByteOrder {
    type Err = ByteOrderParseError;

    /// Parses `big-endian`, `big`, `be`, `msb-first`, `little-endian`, `little`, `le`,
    /// `lsb-first` (case-insensitive).
    fn from_str(s: &str) -> Result<ByteOrder, ByteOrderParseError> {
        match s.trim().to_ascii_lowercase().as_str() {
            "big-endian" | "big" | "be" | "msb-first" | "motorola" => Ok(ByteOrder::BigEndian),
            "little-endian" | "little" | "le" | "lsb-first" | "intel" => {
                Ok(ByteOrder::LittleEndian)
            }
            _ => Err(ByteOrderParseError {
                found: s.to_owned(),
            }),
        }
    }
}

impl From<drivespec_spec::psd4xx::ByteOrder> for ByteOrder {
    /// The PSD4xx spec's order (`protocol.byte_order`, erratum PSD-ERRATUM-050).
    fn from(o: drivespec_spec::psd4xx::ByteOrder) -> ByteOrder {
        match o {
            drivespec_spec::psd4xx::ByteOrder::BigEndian => ByteOrder::BigEndian,
            drivespec_spec::psd4xx::ByteOrder::LittleEndian => ByteOrder::LittleEndian,
        }
    }
}

impl From<drivespec_spec::psx3xx::ByteOrder> for ByteOrder {
    /// The PSx3xx spec's order (`protocol.byte_order.wire`, manual 3.3.2).
    fn from(o: drivespec_spec::psx3xx::ByteOrder) -> ByteOrder {
        match o {
            drivespec_spec::psx3xx::ByteOrder::BigEndian => ByteOrder::BigEndian,
            drivespec_spec::psx3xx::ByteOrder::LittleEndian => ByteOrder::LittleEndian,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decode_and_encode_both_orders() {
        assert_eq!(ByteOrder::BigEndian.decode(&[0x12, 0x34]), Some(0x1234));
        assert_eq!(ByteOrder::LittleEndian.decode(&[0x12, 0x34]), Some(0x3412));
        assert_eq!(ByteOrder::BigEndian.decode(&[]), Some(0));
        assert_eq!(ByteOrder::BigEndian.decode(&[0; 9]), None);
        let mut b = [0u8; 4];
        ByteOrder::BigEndian.encode(0x000C_4950, &mut b);
        assert_eq!(b, [0x00, 0x0C, 0x49, 0x50]);
        ByteOrder::LittleEndian.encode(0x000C_4950, &mut b);
        assert_eq!(b, [0x50, 0x49, 0x0C, 0x00]);
        let mut wide = [0xAAu8; 10];
        ByteOrder::LittleEndian.encode(u64::MAX, &mut wide);
        assert_eq!(wide, [0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0, 0]);
    }

    #[test]
    fn names() {
        for o in ByteOrder::ALL {
            assert_eq!(o.as_str().parse::<ByteOrder>(), Ok(o));
            assert_eq!(o.flipped().flipped(), o);
            assert_eq!(o.inverted_if(false), o);
            assert_eq!(o.inverted_if(true), o.flipped());
        }
        assert_eq!("LE".parse::<ByteOrder>(), Ok(ByteOrder::LittleEndian));
        assert!("middle".parse::<ByteOrder>().is_err());
    }
}
