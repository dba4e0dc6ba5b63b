//! Format detection from the first bytes of a recording: magic numbers for pcap (pcap draft
//! `draft-ietf-opsawg-pcap` section 4), pcapng (`draft-ietf-opsawg-pcapng` 4.1) and gzip
//! (RFC 1952 2.3.1), the shape of the first line for the text formats (socat `-v -x`,
//! our serial text format in [`crate::serial`], IO-Link JSON lines and CSV in
//! [`crate::iolink`]), and raw bytes when nothing matches.
//!
//! Detection never fails: it always names a format and says what it saw.

use crate::bytes::Endian;
use drivespec_spec::hex::to_hex_lower;
use std::fmt;

/// A recording format (our doc: module `detect`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Format {
    /// Classic pcap (pcap draft section 4).
    Pcap {
        /// Byte order of the file.
        endian: Endian,
        /// Timestamps in nanoseconds (magic `a1b23c4d`) rather than microseconds.
        nanos: bool,
        /// The "modified" (Kuznetzov) variant with 24-byte record headers (magic `a1b2cd34`).
        modified: bool,
    },
    /// pcapng (pcapng draft 4.1), byte order of the first section.
    PcapNg {
        /// Byte order of the first section.
        endian: Endian,
    },
    /// gzip-compressed data whose content was not looked into (RFC 1952).
    Gzip,
    /// A socat `-v -x` dump (crate::serial).
    Socat,
    /// Our serial text format (crate::serial).
    SerialText,
    /// IO-Link master log, JSON lines (IOLINK-LOG.md).
    JsonLines,
    /// IO-Link master log, CSV (IOLINK-LOG.md).
    Csv,
    /// Text in none of the layouts above (UTF-16 included): not a recording drivespec can
    /// tell; reading it needs `--format`.
    UnknownText,
    /// None of the above: raw bytes.
    Raw,
}

impl fmt::Display for Format {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Format::Pcap {
                endian,
                nanos,
                modified,
            } => write!(
                f,
                "pcap ({}, {}{})",
                endian_name(*endian),
                if *nanos { "ns" } else { "µs" },
                if *modified { ", modified" } else { "" }
            ),
            Format::PcapNg { endian } => write!(f, "pcapng ({})", endian_name(*endian)),
            Format::Gzip => f.write_str("gzip"),
            Format::Socat => f.write_str("socat -v -x dump"),
            Format::SerialText => f.write_str("serial text"),
            Format::JsonLines => f.write_str("IO-Link JSON lines"),
            Format::Csv => f.write_str("IO-Link CSV"),
            Format::UnknownText => f.write_str("text in no known layout"),
            Format::Raw => f.write_str("raw bytes"),
        }
    }
}

fn endian_name(e: Endian) -> &'static str {
    match e {
        Endian::Big => "big-endian",
        Endian::Little => "little-endian",
    }
}

/// The detected format and the evidence (our doc: module `detect`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Detection {
    /// The format.
    pub format: Format,
    /// The input was gzip-compressed (set by [`crate::input::Input::open`]).
    pub gzip: bool,
    /// The first (up to 16) bytes looked at.
    pub head: Vec<u8>,
    /// What decided it, in words.
    pub reason: String,
}

impl fmt::Display for Detection {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}{}: {} (first bytes {})",
            if self.gzip { "gzip-compressed " } else { "" },
            self.format,
            self.reason,
            to_hex_lower(&self.head)
        )
    }
}

/// Detects the format of a recording from its first bytes (ideally [`crate::input::PEEK`]).
pub fn detect(prefix: &[u8]) -> Detection {
    let head = prefix.get(..16).unwrap_or(prefix).to_vec();
    let (format, reason) = classify(prefix);
    Detection {
        format,
        gzip: false,
        head,
        reason,
    }
}

fn classify(prefix: &[u8]) -> (Format, String) {
    let magic = prefix.get(..4).unwrap_or(&[]);
    let pcap = |endian, nanos, modified, m: &str| {
        (
            Format::Pcap {
                endian,
                nanos,
                modified,
            },
            format!("pcap magic {m}"),
        )
    };
    match magic {
        [0xd4, 0xc3, 0xb2, 0xa1] => return pcap(Endian::Little, false, false, "d4c3b2a1"),
        [0xa1, 0xb2, 0xc3, 0xd4] => return pcap(Endian::Big, false, false, "a1b2c3d4"),
        [0x4d, 0x3c, 0xb2, 0xa1] => return pcap(Endian::Little, true, false, "4d3cb2a1"),
        [0xa1, 0xb2, 0x3c, 0x4d] => return pcap(Endian::Big, true, false, "a1b23c4d"),
        [0x34, 0xcd, 0xb2, 0xa1] => return pcap(Endian::Little, false, true, "34cdb2a1"),
        [0xa1, 0xb2, 0xcd, 0x34] => return pcap(Endian::Big, false, true, "a1b2cd34"),
        [0x0a, 0x0d, 0x0d, 0x0a] => {
            return match prefix.get(8..12) {
                Some([0x4d, 0x3c, 0x2b, 0x1a]) => (
                    Format::PcapNg {
                        endian: Endian::Little,
                    },
                    "pcapng section header 0a0d0d0a, byte-order magic 4d3c2b1a".into(),
                ),
                Some([0x1a, 0x2b, 0x3c, 0x4d]) => (
                    Format::PcapNg {
                        endian: Endian::Big,
                    },
                    "pcapng section header 0a0d0d0a, byte-order magic 1a2b3c4d".into(),
                ),
                other => (
                    Format::PcapNg {
                        endian: Endian::Little,
                    },
                    format!(
                        "pcapng section header 0a0d0d0a, byte-order magic {} not recognised",
                        to_hex_lower(other.unwrap_or(&[]))
                    ),
                ),
            };
        }
        _ => {}
    }
    if prefix.starts_with(&[0x1f, 0x8b]) {
        return (Format::Gzip, "gzip magic 1f8b".into());
    }
    text_format(prefix)
}

/// The UTF-8 byte-order mark, which some editors write before the first line (Unicode 3.10).
pub(crate) const BOM: &[u8] = &[0xef, 0xbb, 0xbf];

/// The complete lines of `prefix` when it is text (after a byte-order mark, if any).
fn text_lines(prefix: &[u8]) -> Option<Vec<&str>> {
    let prefix = prefix.strip_prefix(BOM).unwrap_or(prefix);
    let valid = match std::str::from_utf8(prefix) {
        Ok(s) => s,
        Err(e) => {
            // A multi-byte character cut by the end of the prefix is fine; anything else is not.
            if e.error_len().is_some() {
                return None;
            }
            std::str::from_utf8(prefix.get(..e.valid_up_to())?).ok()?
        }
    };
    if valid
        .chars()
        .any(|c| c.is_control() && !matches!(c, '\n' | '\r' | '\t'))
    {
        return None;
    }
    let complete = if valid.len() == prefix.len() && prefix.len() < crate::input::PEEK {
        valid
    } else {
        match valid.rsplit_once('\n') {
            Some((lines, _)) => lines,
            // A first line longer than the prefix: judge it by its words seen whole.
            None => valid.rsplit_once([' ', '\t']).map_or("", |(a, _)| a),
        }
    };
    Some(complete.lines().collect())
}

fn text_format(prefix: &[u8]) -> (Format, String) {
    let raw = |why: &str| (Format::Raw, why.to_string());
    if prefix.is_empty() {
        return raw("empty input");
    }
    if let Some(mark) = [[0xff, 0xfe], [0xfe, 0xff]]
        .iter()
        .find(|m| prefix.starts_with(m.as_slice()))
    {
        return (
            Format::UnknownText,
            format!(
                "UTF-16 text (byte-order mark {}): convert it to UTF-8",
                to_hex_lower(mark)
            ),
        );
    }
    let Some(lines) = text_lines(prefix) else {
        return raw("no known magic and not text");
    };
    let first = lines
        .iter()
        .map(|l| l.trim())
        .find(|l| !l.is_empty() && !l.starts_with('#'));
    let Some(first) = first else {
        return raw("text without a data line");
    };
    let shown: String = first.chars().take(60).collect();
    if crate::serial::is_socat_header(first) {
        return (Format::Socat, format!("socat header line `{shown}`"));
    }
    if first.starts_with('{') {
        return (Format::JsonLines, format!("JSON object line `{shown}`"));
    }
    if crate::iolink::is_csv_header(first) {
        return (Format::Csv, format!("CSV header `{shown}`"));
    }
    if crate::serial::parse_text_line(first).is_ok() {
        return (Format::SerialText, format!("serial text line `{shown}`"));
    }
    (
        Format::UnknownText,
        format!("first line `{shown}` is in none of the text layouts"),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn magics() {
        assert!(matches!(
            detect(&[0xd4, 0xc3, 0xb2, 0xa1, 2, 0]).format,
            Format::Pcap {
                endian: Endian::Little,
                nanos: false,
                ..
            }
        ));
        assert_eq!(detect(&[0x1f, 0x8b, 8]).format, Format::Gzip);
        assert_eq!(detect(b"").format, Format::Raw);
        assert_eq!(detect(&[0x02, 0x41, 0x00]).format, Format::Raw);
        assert_eq!(
            detect(b"> 2024/01/02 10:00:00.123456  length=2 from=0 to=1\n 02 41\n--\n").format,
            Format::Socat
        );
        assert_eq!(detect(b"# x\n0 > 02 41\n").format, Format::SerialText);
        assert_eq!(detect(b"{\"time\":0}\n").format, Format::JsonLines);
        assert_eq!(detect(b"time,port,kind,out\n").format, Format::Csv);
    }
}
