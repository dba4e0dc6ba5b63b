//! Serial captures for the HPD line decoder: every supported recording becomes a stream of
//! [`SerialChunk`]s `(time, direction, bytes)` ready for `drivespec_hpd::LineDecoder::feed`.
//!
//! Supported recordings:
//!
//! - **raw bytes**: one direction, or both interleaved, without times; read in chunks of
//!   [`RAW_CHUNK`] bytes.
//! - **socat `-v -x` dumps**: a header line `> 2024/01/02 10:00:00.123456  length=5 from=0
//!   to=4` (`>` data from the first address to the second, `<` the other way; the time is
//!   taken as UTC), then hex lines of up to 16 bytes (` 02 41 …` followed by their ASCII
//!   rendering), then a line `--`. One chunk per header.
//! - **our serial text format**, one chunk per line:
//!
//!   ```text
//!   # comment; blank lines are ignored
//!   # TIME  DIR  HEX
//!   0        >  02 41 00 13 54
//!   1500     <  02 21
//!   2024-01-02T10:00:00.001200Z > 0241001354
//!   -        -  02 41
//!   ```
//!
//!   TIME is integer microseconds (any epoch), an ISO 8601 time (UTC unless it names an
//!   offset), or `-` for unknown. DIR is `>` (transmitted, [`Dir::Tx`]), `<` (received,
//!   [`Dir::Rx`]) or `-`. HEX is one or more bytes as hex digit pairs, blanks allowed
//!   between bytes.
//! - **pcap/pcapng with a serial link type**: LINKTYPE_USER0 (147) records hold the raw bytes;
//!   LINKTYPE_RTAC_SERIAL (250) records start with the 12-byte RTAC header (seconds and
//!   microseconds, event type, UART control lines, 2-byte footer, all big-endian). Data events
//!   1 and 3 (DATA_TX_*) are [`Dir::Tx`], 2 and 4 (DATA_RX_*) [`Dir::Rx`]; other events carry
//!   no line data and are skipped (counted by [`PcapSerial::skipped`]). The record time is used.
//!
//! Text lines are limited to [`MAX_LINE`] bytes and socat chunks to [`MAX_SOCAT_CHUNK`]; a
//! line error is reported and reading goes on with the next line. I/O and capture errors end the stream. Nothing here panics.

use crate::detect::Format;
use crate::input::{Input, Line, LineError, Lines, ReadError};
use crate::link::LinkType;
use crate::pcap::{CaptureError, CaptureReader, Options};
use crate::time::{parse_iso, parse_socat, Micros};
use drivespec_spec::hex::{hex_digit, parse_hex};
use std::io::Read;

/// Bytes per chunk of a raw recording.
pub const RAW_CHUNK: usize = 4096;

/// Longest text line accepted.
pub const MAX_LINE: usize = 64 * 1024;

/// Largest chunk a socat header may announce (socat's own buffer is 8192 bytes by default).
pub const MAX_SOCAT_CHUNK: usize = 1 << 20;

/// Direction of serial data (our doc: module `serial`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Dir {
    /// `>`: sent by the recording side (socat: first address to second; RTAC: DATA_TX).
    Tx,
    /// `<`: received (socat: second address to first; RTAC: DATA_RX).
    Rx,
}

impl Dir {
    /// The direction character of the text formats.
    pub fn symbol(self) -> char {
        match self {
            Dir::Tx => '>',
            Dir::Rx => '<',
        }
    }
}

/// Where a chunk or error came from (our doc: module `serial`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Origin {
    /// Byte offset in a raw recording.
    Byte(u64),
    /// 1-based line of a text recording (socat: the header line).
    Line(u64),
    /// Record number of a capture.
    Record(u64),
}

/// Bytes seen on the line, with their time and direction when known (our doc: module
/// `serial`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SerialChunk {
    /// Microseconds (socat, ISO and capture times: since 1970, UTC).
    pub time: Option<Micros>,
    /// Direction, when known.
    pub dir: Option<Dir>,
    /// The bytes.
    pub bytes: Vec<u8>,
    /// Where in the recording.
    pub origin: Origin,
}

/// Why a serial recording cannot be read (further) (our doc: module `serial`).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SerialError {
    /// Reading failed; the stream ends.
    #[error(transparent)]
    Read(#[from] ReadError),
    /// A text line is too long or not UTF-8; reading goes on.
    #[error(transparent)]
    Line(LineError),
    /// A socat dump line is not what the format allows; reading goes on.
    #[error("socat dump line {line}: {reason}")]
    Socat {
        /// 1-based line number.
        line: u64,
        /// What is wrong.
        reason: String,
    },
    /// A serial text line is malformed; reading goes on.
    #[error("serial text line {line}: {reason}")]
    Text {
        /// 1-based line number.
        line: u64,
        /// What is wrong.
        reason: &'static str,
    },
    /// The capture cannot be read further; the stream ends.
    #[error(transparent)]
    Capture(#[from] CaptureError),
    /// A capture record of a link type that carries no serial data; reading goes on.
    #[error("record {record}: link type {link_type} carries no serial data")]
    LinkType {
        /// Record number.
        record: u64,
        /// Its link type.
        link_type: LinkType,
    },
    /// An RTAC record shorter than its 12-byte header; reading goes on.
    #[error(
        "record {record}: RTAC serial record of {len} byte(s), shorter than its 12-byte header"
    )]
    RtacHeader {
        /// Record number.
        record: u64,
        /// Captured length.
        len: usize,
    },
    /// The recording is in a format that holds no serial data.
    #[error("not a serial recording: detected {0}")]
    NotSerial(crate::detect::Detection),
}

fn line_error(e: LineError) -> SerialError {
    match e {
        LineError::Read(r) => SerialError::Read(r),
        other => SerialError::Line(other),
    }
}

/// Whether `line` is a socat `-v` header (`> YYYY/MM/DD HH:MM:SS.f  length=N from=A to=B`).
pub(crate) fn is_socat_header(line: &str) -> bool {
    parse_socat_header(line).is_some()
}

/// Direction, time and length of a socat header line.
fn parse_socat_header(line: &str) -> Option<(Dir, Option<Micros>, usize)> {
    let mut words = line.split_whitespace();
    let dir = match words.next()? {
        ">" => Dir::Tx,
        "<" => Dir::Rx,
        _ => return None,
    };
    let date = words.next()?;
    let clock = words.next()?;
    let time = parse_socat(date, clock);
    time?;
    let length = words.next()?.strip_prefix("length=")?.parse().ok()?;
    Some((dir, time, length))
}

/// Bytes of one socat hex line: ` xx xx …` (up to 16, at fixed columns), then blanks and the
/// ASCII rendering from column 50 on. Reads at most `want` bytes; a line with none is an error.
fn parse_socat_hex(line: &str, want: usize) -> Result<Vec<u8>, String> {
    let bytes = line.as_bytes();
    let mut out = Vec::new();
    for i in 0..want.min(16) {
        let at = 3 * i;
        match (bytes.get(at), bytes.get(at + 1), bytes.get(at + 2)) {
            (Some(b' '), Some(&h), Some(&l)) => match (hex_digit(h), hex_digit(l)) {
                (Some(h), Some(l)) => out.push(h << 4 | l),
                _ => break,
            },
            _ => break,
        }
    }
    if out.is_empty() {
        return Err("expected hex bytes ` xx xx …`".into());
    }
    Ok(out)
}

/// One parsed line of our serial text format.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct TextLine {
    pub(crate) time: Option<Micros>,
    pub(crate) dir: Option<Dir>,
    pub(crate) bytes: Vec<u8>,
}

/// Parses a data line of our serial text format.
pub(crate) fn parse_text_line(line: &str) -> Result<TextLine, &'static str> {
    let line = line.trim();
    let (time_text, rest) = line
        .split_once([' ', '\t'])
        .ok_or("expected TIME DIR HEX")?;
    let rest = rest.trim_start();
    let (dir_text, hex_text) = rest
        .split_once([' ', '\t'])
        .ok_or("expected TIME DIR HEX")?;
    let time = match time_text {
        "-" => None,
        t if t.bytes().all(|b| b.is_ascii_digit()) => {
            Some(t.parse().map_err(|_| "time out of range")?)
        }
        t => Some(parse_iso(t).ok_or("time is neither microseconds nor ISO 8601")?),
    };
    let dir = match dir_text {
        ">" => Some(Dir::Tx),
        "<" => Some(Dir::Rx),
        "-" => None,
        _ => return Err("direction must be >, < or -"),
    };
    let bytes = parse_hex(hex_text.trim()).map_err(|_| "bytes must be hex digit pairs")?;
    if bytes.is_empty() {
        return Err("no bytes");
    }
    Ok(TextLine { time, dir, bytes })
}

/// Reads a raw recording in chunks (our doc: module `serial`).
#[derive(Debug)]
pub struct RawChunks<R> {
    input: Input<R>,
    done: bool,
}

impl<R: Read> RawChunks<R> {
    /// Chunks of an opened input.
    pub fn new(input: Input<R>) -> RawChunks<R> {
        RawChunks { input, done: false }
    }
}

impl<R: Read> Iterator for RawChunks<R> {
    type Item = Result<SerialChunk, SerialError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done {
            return None;
        }
        let offset = self.input.position();
        let mut buf = vec![0u8; RAW_CHUNK];
        let mut filled = 0;
        while filled < buf.len() {
            let slot = buf.get_mut(filled..).unwrap_or(&mut []);
            match self.input.read(slot) {
                Ok(0) => break,
                Ok(n) => filled += n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(source) => {
                    self.done = true;
                    return Some(Err(SerialError::Read(ReadError {
                        offset: offset + filled as u64,
                        gzip: self.input.detection().gzip,
                        source,
                    })));
                }
            }
        }
        if filled == 0 {
            self.done = true;
            return None;
        }
        buf.truncate(filled);
        Some(Ok(SerialChunk {
            time: None,
            dir: None,
            bytes: buf,
            origin: Origin::Byte(offset),
        }))
    }
}

/// Reads a socat `-v -x` dump (our doc: module `serial`).
#[derive(Debug)]
pub struct SocatReader<R> {
    lines: Lines<R>,
    held: Option<Line>,
    /// After a bad hex line: skip to the next header quietly.
    resync: bool,
}

impl<R: Read> SocatReader<R> {
    /// A reader of the dump in `reader` (not decompressed; see [`SerialReader`]).
    pub fn new(reader: R) -> SocatReader<R> {
        SocatReader {
            lines: Lines::new(reader, MAX_LINE, false),
            held: None,
            resync: false,
        }
    }

    fn line(&mut self) -> Option<Result<Line, LineError>> {
        match self.held.take() {
            Some(l) => Some(Ok(l)),
            None => self.lines.next_line(),
        }
    }
}

impl<R: Read> Iterator for SocatReader<R> {
    type Item = Result<SerialChunk, SerialError>;

    fn next(&mut self) -> Option<Self::Item> {
        let header = loop {
            let line = match self.line()? {
                Ok(l) => l,
                Err(e) => return Some(Err(line_error(e))),
            };
            let t = line.text.trim();
            if t.is_empty() || t == "--" {
                continue;
            }
            match parse_socat_header(t) {
                Some(h) => {
                    self.resync = false;
                    break (line.number, h);
                }
                None if self.resync => continue,
                None => {
                    return Some(Err(SerialError::Socat {
                        line: line.number,
                        reason: "expected a `> date time  length=N from=A to=B` header".into(),
                    }))
                }
            }
        };
        let (number, (dir, time, length)) = header;
        if length > MAX_SOCAT_CHUNK {
            self.resync = true;
            return Some(Err(SerialError::Socat {
                line: number,
                reason: format!("length={length} is more than {MAX_SOCAT_CHUNK}"),
            }));
        }
        let mut bytes = Vec::with_capacity(length.min(4096));
        while bytes.len() < length {
            let line = match self.line() {
                None => break,
                Some(Ok(l)) => l,
                Some(Err(e)) => return Some(Err(line_error(e))),
            };
            if line.text.trim() == "--" || parse_socat_header(line.text.trim()).is_some() {
                self.held = Some(line);
                break;
            }
            let want = (length - bytes.len()).min(16);
            match parse_socat_hex(&line.text, want) {
                Ok(b) if b.len() < want => {
                    // A short line ends the dump of this chunk.
                    bytes.extend(b);
                    break;
                }
                Ok(b) => bytes.extend(b),
                Err(reason) => {
                    self.resync = true;
                    return Some(Err(SerialError::Socat {
                        line: line.number,
                        reason,
                    }));
                }
            }
        }
        if bytes.len() != length {
            self.resync = true;
            return Some(Err(SerialError::Socat {
                line: number,
                reason: format!(
                    "header says length={length}, the dump has {} byte(s)",
                    bytes.len()
                ),
            }));
        }
        Some(Ok(SerialChunk {
            time,
            dir: Some(dir),
            bytes,
            origin: Origin::Line(number),
        }))
    }
}

/// Reads our serial text format (our doc: module `serial`).
#[derive(Debug)]
pub struct TextReader<R> {
    lines: Lines<R>,
}

impl<R: Read> TextReader<R> {
    /// A reader of the text in `reader` (not decompressed; see [`SerialReader`]).
    pub fn new(reader: R) -> TextReader<R> {
        TextReader {
            lines: Lines::new(reader, MAX_LINE, false),
        }
    }
}

impl<R: Read> Iterator for TextReader<R> {
    type Item = Result<SerialChunk, SerialError>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            let line = match self.lines.next_line()? {
                Ok(l) => l,
                Err(e) => return Some(Err(line_error(e))),
            };
            let t = line.text.trim();
            if t.is_empty() || t.starts_with('#') {
                continue;
            }
            return Some(match parse_text_line(t) {
                Ok(TextLine { time, dir, bytes }) => Ok(SerialChunk {
                    time,
                    dir,
                    bytes,
                    origin: Origin::Line(line.number),
                }),
                Err(reason) => Err(SerialError::Text {
                    line: line.number,
                    reason,
                }),
            });
        }
    }
}

/// RTAC serial event types that carry line data (LINKTYPE_RTAC_SERIAL).
fn rtac_dir(event: u8) -> Option<Dir> {
    match event {
        0x01 | 0x03 => Some(Dir::Tx),
        0x02 | 0x04 => Some(Dir::Rx),
        _ => None,
    }
}

/// Serial data from a capture with a serial link type (our doc: module `serial`).
#[derive(Debug)]
pub struct PcapSerial<R: Read> {
    reader: CaptureReader<R>,
    skipped: u64,
}

impl<R: Read> PcapSerial<R> {
    /// Serial chunks of the records of `reader`.
    pub fn new(reader: CaptureReader<R>) -> PcapSerial<R> {
        PcapSerial { reader, skipped: 0 }
    }

    /// RTAC records without line data (status changes, errors) skipped so far.
    pub fn skipped(&self) -> u64 {
        self.skipped
    }
}

impl<R: Read> Iterator for PcapSerial<R> {
    type Item = Result<SerialChunk, SerialError>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            let record = match self.reader.next_record() {
                Ok(Some(r)) => r,
                Ok(None) => return None,
                Err(e) => return Some(Err(e.into())),
            };
            let origin = Origin::Record(record.number);
            match record.link_type {
                LinkType::USER0 => {
                    return Some(Ok(SerialChunk {
                        time: record.time,
                        dir: None,
                        bytes: record.data.to_vec(),
                        origin,
                    }))
                }
                LinkType::RTAC_SERIAL => {
                    let Some((header, payload)) = record.data.split_at_checked(12) else {
                        return Some(Err(SerialError::RtacHeader {
                            record: record.number,
                            len: record.data.len(),
                        }));
                    };
                    let event = header.get(8).copied().unwrap_or(0);
                    match rtac_dir(event) {
                        Some(dir) if !payload.is_empty() => {
                            return Some(Ok(SerialChunk {
                                time: record.time,
                                dir: Some(dir),
                                bytes: payload.to_vec(),
                                origin,
                            }))
                        }
                        _ => self.skipped += 1,
                    }
                }
                link_type => {
                    return Some(Err(SerialError::LinkType {
                        record: record.number,
                        link_type,
                    }))
                }
            }
        }
    }
}

/// Any serial recording, by detected format (our doc: module `serial`).
#[derive(Debug)]
pub enum SerialReader<R: Read> {
    /// Raw bytes.
    Raw(RawChunks<R>),
    /// socat dump.
    Socat(SocatReader<Input<R>>),
    /// Our text format.
    Text(TextReader<Input<R>>),
    /// A capture with a serial link type.
    Pcap(PcapSerial<R>),
}

impl<R: Read> SerialReader<R> {
    /// Opens a serial recording (gzip-compressed or not) and picks the reader by format.
    pub fn open(reader: R) -> Result<SerialReader<R>, SerialError> {
        let input = Input::open(reader)?;
        let detection = input.detection().clone();
        let gzip = detection.gzip;
        Ok(match detection.format {
            Format::Pcap { .. } | Format::PcapNg { .. } => SerialReader::Pcap(PcapSerial::new(
                CaptureReader::from_input(input, Options::default())?,
            )),
            Format::Socat => SerialReader::Socat(SocatReader {
                lines: Lines::new(input, MAX_LINE, gzip),
                held: None,
                resync: false,
            }),
            Format::SerialText => SerialReader::Text(TextReader {
                lines: Lines::new(input, MAX_LINE, gzip),
            }),
            Format::Raw => SerialReader::Raw(RawChunks::new(input)),
            _ => return Err(SerialError::NotSerial(detection)),
        })
    }
}

impl<R: Read> Iterator for SerialReader<R> {
    type Item = Result<SerialChunk, SerialError>;

    fn next(&mut self) -> Option<Self::Item> {
        match self {
            SerialReader::Raw(r) => r.next(),
            SerialReader::Socat(r) => r.next(),
            SerialReader::Text(r) => r.next(),
            SerialReader::Pcap(r) => r.next(),
        }
    }
}
