//! Hex text as written in vectors, on the command line and in the manuals.

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
                let s = std::str::from_utf8(pair).unwrap_or("00");
                out.push(u8::from_str_radix(s, 16).unwrap_or(0));
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

/// Formats bytes as `7E 21 02`.
pub fn to_hex(bytes: &[u8]) -> String {
    let mut s = String::with_capacity(bytes.len() * 3);
    for (i, b) in bytes.iter().enumerate() {
        if i > 0 {
            s.push(' ');
        }
        let _ = write!(s, "{b:02X}");
    }
    s
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
}
