//! Hex text as written in vectors, on the command line and in the manuals: bytes in the
//! spaced (`7E 80 01`), compact (`7E8001`) and bracketed (`[$7E][$80][$01]`) forms, and
//! integers in decimal or `0x` hex.

use std::fmt::Write as _;

/// Why a text is not hex bytes.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum HexError {
    /// A character that is neither a hex digit nor a separator.
    #[error("invalid character {found:?} at offset {offset}")]
    Char {
        /// Byte offset in the text.
        offset: usize,
        /// The character.
        found: char,
    },
    /// A group with an odd number of digits.
    #[error("odd number of hex digits in {group:?} at offset {offset}")]
    Odd {
        /// Byte offset of the group.
        offset: usize,
        /// The group.
        group: String,
    },
}

/// Parses `7E 80 01 54 D5`, `7E800154D5`, `0x7E,0x80` or the manuals' `[$7E][$80][$01]`.
///
/// Separators are blanks, commas, colons, `[`, `]` and `-`; `$` and `0x` prefixes are
/// allowed. A group of digits between separators must have an even length.
pub fn parse_hex(text: &str) -> Result<Vec<u8>, HexError> {
    let mut out = Vec::with_capacity(text.len() / 2);
    let mut group_start = None;
    let mut digits = String::new();
    let flush =
        |digits: &mut String, start: Option<usize>, out: &mut Vec<u8>| -> Result<(), HexError> {
            if digits.len() % 2 == 1 {
                return Err(HexError::Odd {
                    offset: start.unwrap_or(0),
                    group: digits.clone(),
                });
            }
            for pair in digits.as_bytes().chunks(2) {
                if let [high, low] = pair {
                    out.push(hex_digit(*high).unwrap_or(0) << 4 | hex_digit(*low).unwrap_or(0));
                }
            }
            digits.clear();
            Ok(())
        };
    let mut chars = text.char_indices().peekable();
    while let Some((i, c)) = chars.next() {
        match c {
            c if c.is_ascii_hexdigit() => {
                // "0x" prefix: a 0 directly followed by x at the start of a group.
                if c == '0' && digits.is_empty() && matches!(chars.peek(), Some((_, 'x' | 'X'))) {
                    chars.next();
                    group_start = Some(i);
                    continue;
                }
                if digits.is_empty() {
                    group_start = Some(i);
                }
                digits.push(c);
            }
            '$' if digits.is_empty() => group_start = Some(i),
            ' ' | '\t' | '\n' | '\r' | ',' | ':' | '[' | ']' | '-' | ';' => {
                flush(&mut digits, group_start, &mut out)?
            }
            found => return Err(HexError::Char { offset: i, found }),
        }
    }
    flush(&mut digits, group_start, &mut out)?;
    Ok(out)
}

/// Parses hex digits without separators or prefixes (`7E8001`, either case); `None` unless
/// the text is an even number of hex digits.
pub fn parse_hex_compact(text: &str) -> Option<Vec<u8>> {
    let digits = text.as_bytes();
    if digits.len() % 2 != 0 {
        return None;
    }
    digits
        .chunks(2)
        .map(|pair| match pair {
            [high, low] => Some(hex_digit(*high)? << 4 | hex_digit(*low)?),
            _ => None,
        })
        .collect()
}

/// The value of one hex digit (`0`–`9`, `a`–`f`, `A`–`F`).
pub fn hex_digit(c: u8) -> Option<u8> {
    match c {
        b'0'..=b'9' => Some(c - b'0'),
        b'a'..=b'f' => Some(c - b'a' + 10),
        b'A'..=b'F' => Some(c - b'A' + 10),
        _ => None,
    }
}

/// Letter case of hex digits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Case {
    /// `7E`, as in the manuals and the spec.
    Upper,
    /// `7e`, as in capture tools' output.
    Lower,
}

/// Formats bytes as two hex digits each in `case`, with `sep` between bytes: `7E 21 02`
/// (`Upper`, `" "`), `7E2102` (`Upper`, `""`), `7e:21:02` (`Lower`, `":"`).
pub fn encode(bytes: &[u8], case: Case, sep: &str) -> String {
    let mut s = String::with_capacity(bytes.len() * (2 + sep.len()));
    for (i, b) in bytes.iter().enumerate() {
        if i > 0 {
            s.push_str(sep);
        }
        let _ = match case {
            Case::Upper => write!(s, "{b:02X}"),
            Case::Lower => write!(s, "{b:02x}"),
        };
    }
    s
}

/// Formats bytes as `7E 21 02`, the spec's form.
pub fn to_hex(bytes: &[u8]) -> String {
    encode(bytes, Case::Upper, " ")
}

/// Formats bytes as `7E2102`, as the cyclic-exchange protocol writes them.
pub fn to_hex_compact(bytes: &[u8]) -> String {
    encode(bytes, Case::Upper, "")
}

/// Formats bytes as `7e2102`, as capture tools and IO-Link master logs write them.
pub fn to_hex_lower(bytes: &[u8]) -> String {
    encode(bytes, Case::Lower, "")
}

/// Why a text is not an integer of the wanted type.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum IntError {
    /// No digits (only blanks and `_`).
    #[error("no number")]
    Empty,
    /// Not a decimal or `0x` hex number.
    #[error("{text:?} is not a number (decimal or 0x hex)")]
    Syntax {
        /// The text as given.
        text: String,
    },
    /// A number outside the wanted type's range.
    #[error("{text:?} is out of range")]
    Range {
        /// The text as given.
        text: String,
    },
}

/// Parses bare hex digits (`7E`, `1f4`; no sign, prefix or separator) into any integer type
/// `T`; `None` for other text or a value out of `T`'s range.
pub fn parse_hex_digits<T: TryFrom<u128>>(digits: &str) -> Option<T> {
    if digits.is_empty() || !digits.bytes().all(|c| c.is_ascii_hexdigit()) {
        return None;
    }
    T::try_from(u128::from_str_radix(digits, 16).ok()?).ok()
}

/// Parses an integer: decimal or `0x`/`0X` hex, an optional `+` or `-` sign in front, `_`
/// between digits and blanks around ignored (`-250`, `0x14`, `12_000`), into any integer
/// type `T`.
pub fn parse_int<T: TryFrom<i128>>(text: &str) -> Result<T, IntError> {
    let t = text.trim().replace('_', "");
    if t.is_empty() {
        return Err(IntError::Empty);
    }
    let syntax = || IntError::Syntax {
        text: text.to_owned(),
    };
    let range = || IntError::Range {
        text: text.to_owned(),
    };
    let (neg, body) = match t.strip_prefix('-') {
        Some(rest) => (true, rest),
        None => (false, t.strip_prefix('+').unwrap_or(&t)),
    };
    let (radix, digits) = match body.strip_prefix("0x").or_else(|| body.strip_prefix("0X")) {
        Some(hex) => (16, hex),
        None => (10, body),
    };
    if digits.is_empty() || !digits.chars().all(|c| c.is_digit(radix)) {
        return Err(syntax());
    }
    let magnitude = i128::from_str_radix(digits, radix).map_err(|_| range())?;
    let value = if neg { -magnitude } else { magnitude };
    T::try_from(value).map_err(|_| range())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_three_forms() {
        let want = vec![0x7E, 0x21, 0x02, 0x42, 0xD0, 0x07, 0x3C];
        assert_eq!(parse_hex("7E 21 02 42 D0 07 3C"), Ok(want.clone()));
        assert_eq!(parse_hex("7E210242D0073C"), Ok(want.clone()));
        assert_eq!(
            parse_hex("[$7E][$21][$02][$42][$D0][$07][$3C]"),
            Ok(want.clone())
        );
        assert_eq!(parse_hex("0x7E,0x21, 0x02 0x42:d0-07 3c"), Ok(want));
        assert_eq!(parse_hex(""), Ok(vec![]));
    }

    #[test]
    fn errors_name_the_offset() {
        assert_eq!(
            parse_hex("7E 2"),
            Err(HexError::Odd {
                offset: 3,
                group: "2".into()
            })
        );
        assert_eq!(
            parse_hex("7E G1"),
            Err(HexError::Char {
                offset: 3,
                found: 'G'
            })
        );
        assert_eq!(to_hex(&[0x7E, 0x00]), "7E 00");
    }

    #[test]
    fn encode_styles() {
        let b = [0x7E, 0x0a, 0xFF];
        assert_eq!(to_hex(&b), "7E 0A FF");
        assert_eq!(encode(&b, Case::Upper, ""), "7E0AFF");
        assert_eq!(encode(&b, Case::Lower, ""), "7e0aff");
        assert_eq!(encode(&b, Case::Lower, ":"), "7e:0a:ff");
        assert_eq!(encode(&[], Case::Upper, " "), "");
    }

    #[test]
    fn compact_is_strict() {
        assert_eq!(parse_hex_compact("7e0AfF"), Some(vec![0x7E, 0x0A, 0xFF]));
        assert_eq!(parse_hex_compact(""), Some(vec![]));
        assert_eq!(parse_hex_compact("7E0"), None);
        assert_eq!(parse_hex_compact("7E 0A"), None);
        assert_eq!(parse_hex_compact("0x7E"), None);
        assert_eq!(parse_hex_compact("+7"), None);
        assert_eq!(parse_hex_compact("é0"), None);
    }

    #[test]
    fn bare_hex_digits() {
        assert_eq!(parse_hex_digits::<u8>("7"), Some(7));
        assert_eq!(parse_hex_digits::<u8>("07e"), Some(0x7E));
        assert_eq!(parse_hex_digits::<u16>("8011"), Some(0x8011));
        assert_eq!(parse_hex_digits::<u8>("100"), None);
        for bad in ["", "+7", "0x7", "7 E", "-1"] {
            assert_eq!(parse_hex_digits::<u8>(bad), None, "{bad}");
        }
    }

    #[test]
    fn integers() {
        assert_eq!(parse_int::<i64>(" -250 "), Ok(-250));
        assert_eq!(parse_int::<i64>("+7"), Ok(7));
        assert_eq!(parse_int::<i64>("0x14"), Ok(20));
        assert_eq!(parse_int::<i64>("-0X1_F"), Ok(-31));
        assert_eq!(parse_int::<i64>("12_000"), Ok(12_000));
        assert_eq!(parse_int::<u8>("0xFF"), Ok(255));
        assert_eq!(parse_int::<u64>("18446744073709551615"), Ok(u64::MAX));
        assert_eq!(parse_int::<i64>("_"), Err(IntError::Empty));
        assert_eq!(
            parse_int::<u8>("256"),
            Err(IntError::Range { text: "256".into() })
        );
        assert_eq!(
            parse_int::<u8>("-1"),
            Err(IntError::Range { text: "-1".into() })
        );
        for bad in ["0x", "0x-5", "--5", "1e3", "12a", "0b101", "- 5"] {
            assert_eq!(
                parse_int::<i64>(bad),
                Err(IntError::Syntax { text: bad.into() }),
                "{bad}"
            );
        }
        assert!(matches!(
            parse_int::<i64>(&"9".repeat(60)),
            Err(IntError::Range { .. })
        ));
    }

    mod round_trip {
        use super::super::*;
        use proptest::prelude::*;

        proptest! {
            #[test]
            fn every_form_decodes_to_the_bytes(
                bytes in proptest::collection::vec(any::<u8>(), 0..64)
            ) {
                let spaced = to_hex(&bytes);
                prop_assert_eq!(parse_hex(&spaced), Ok(bytes.clone()));
                let compact = to_hex_compact(&bytes);
                prop_assert_eq!(parse_hex(&compact), Ok(bytes.clone()));
                prop_assert_eq!(parse_hex_compact(&compact), Some(bytes.clone()));
                let lower = to_hex_lower(&bytes);
                prop_assert_eq!(parse_hex_compact(&lower), Some(bytes.clone()));
                let bracketed: String =
                    bytes.iter().map(|b| format!("[${b:02X}]")).collect();
                prop_assert_eq!(parse_hex(&bracketed), Ok(bytes.clone()));
                let prefixed: Vec<String> = bytes.iter().map(|b| format!("0x{b:02x}")).collect();
                let prefixed = prefixed.join(",");
                prop_assert_eq!(parse_hex(&prefixed), Ok(bytes));
            }

            #[test]
            fn integers_round_trip(n in any::<i64>()) {
                prop_assert_eq!(parse_int::<i64>(&n.to_string()), Ok(n));
                let hex = if n < 0 {
                    format!("-0x{:X}", n.unsigned_abs())
                } else {
                    format!("0x{n:x}")
                };
                prop_assert_eq!(parse_int::<i64>(&hex), Ok(n));
            }
        }
    }
}
