//! IO-Link master logs for the PSx3xx drives, in the two forms documented in
//! `crates/capture/IOLINK-LOG.md`: JSON lines and CSV. Both hold the same fields and decode
//! into the same typed [`IoLinkEvent`]s.
//!
//! One event per line (per row in CSV), with a `kind`:
//!
//! | kind | fields |
//! | --- | --- |
//! | `pd` | `out` and/or `in`: process data as hex (master to device, device to master) |
//! | `isdu_req` | `rw` (`read`/`write`), `index`, `subindex` (default 0), `data` (hex, writes) |
//! | `isdu_res` | `index`, `subindex` (optional, to pair), and `data` (hex) or `error` (u16, e.g. `0x8011`) |
//! | `event` | `code` (u16 EventCode), `qualifier` (u8 EventQualifier, optional), `text` (optional) |
//!
//! Every kind may have `time` (integer microseconds, or ISO 8601) and `port` (master port,
//! 1–255). Numbers may be written as JSON numbers or as strings in decimal or `0x` hex. Hex
//! data may separate bytes with blanks, `:` or `-`. Unknown keys (JSON) or columns (CSV) are
//! errors. Errors name the line; a bad line is reported and reading goes on with the next one.
//! Lines are limited to [`MAX_LINE`] bytes. Nothing here panics.

use crate::detect::Format;
use crate::input::{Input, LineError, Lines, ReadError};
use crate::time::{parse_time_field, Micros};
use drivespec_spec::hex::{parse_hex, parse_int};
use serde::Deserialize;
use std::io::Read;

/// Longest line accepted.
pub const MAX_LINE: usize = 64 * 1024;

/// The columns (CSV) and keys (JSON) of a log line (IOLINK-LOG.md).
pub const COLUMNS: &[&str] = &[
    "time",
    "port",
    "kind",
    "out",
    "in",
    "rw",
    "index",
    "subindex",
    "data",
    "error",
    "code",
    "qualifier",
    "text",
];

/// ISDU access direction (IO-Link spec "ISDU": read or write service).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Access {
    /// Read.
    Read,
    /// Write.
    Write,
}

/// The outcome of an ISDU request (IO-Link spec "ISDU": response or error with ErrorCode and
/// AdditionalCode).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum IsduResult {
    /// Success, with the data read (empty for a write).
    Data(Vec<u8>),
    /// Failure: ErrorCode << 8 | AdditionalCode (e.g. 0x8011 index not available).
    Error(u16),
}

/// What an IO-Link log line records (IOLINK-LOG.md).
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum IoLinkKind {
    /// Cyclic process data.
    ProcessData {
        /// PDout: master to device.
        out: Option<Vec<u8>>,
        /// PDin: device to master.
        input: Option<Vec<u8>>,
    },
    /// An ISDU request.
    IsduRequest {
        /// Read or write.
        access: Access,
        /// Index.
        index: u16,
        /// Subindex.
        subindex: u8,
        /// Data written (empty for a read).
        data: Vec<u8>,
    },
    /// An ISDU response.
    IsduResponse {
        /// Index, if logged.
        index: Option<u16>,
        /// Subindex, if logged.
        subindex: Option<u8>,
        /// Data or error code.
        result: IsduResult,
    },
    /// A port or device event.
    PortEvent {
        /// EventCode.
        code: u16,
        /// EventQualifier, if logged.
        qualifier: Option<u8>,
        /// Text, if logged.
        text: Option<String>,
    },
}

/// One event of an IO-Link master log (IOLINK-LOG.md).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct IoLinkEvent {
    /// 1-based line number (CSV: counting the header).
    pub line: u64,
    /// Microseconds (ISO times: since 1970, UTC).
    pub time: Option<Micros>,
    /// Master port.
    pub port: Option<u8>,
    /// What it records.
    pub kind: IoLinkKind,
}

/// Why a log line cannot be decoded (our doc: module `iolink`).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum IoLinkError {
    /// Reading failed; the stream ends.
    #[error(transparent)]
    Read(#[from] ReadError),
    /// A line is too long or not UTF-8.
    #[error(transparent)]
    Line(LineError),
    /// A JSON line is not a JSON object of the log's keys.
    #[error("line {line}: {message}")]
    Json {
        /// 1-based line number.
        line: u64,
        /// serde_json's message.
        message: String,
    },
    /// The CSV header names an unknown or repeated column, or lacks `kind`.
    #[error("line {line}: CSV header: {reason}")]
    Header {
        /// 1-based line number.
        line: u64,
        /// What is wrong.
        reason: String,
    },
    /// A CSV row does not match the header.
    #[error("line {line}: {cells} cell(s) where the header has {columns}")]
    Cells {
        /// 1-based line number.
        line: u64,
        /// Cells in the row.
        cells: usize,
        /// Columns in the header.
        columns: usize,
    },
    /// A field is missing, out of range or not allowed for the kind.
    #[error("line {line}: field `{field}`: {reason}")]
    Field {
        /// 1-based line number.
        line: u64,
        /// The key or column.
        field: &'static str,
        /// What is wrong.
        reason: String,
    },
    /// The input is not an IO-Link log.
    #[error("not an IO-Link log: detected {0}")]
    NotIoLink(crate::detect::Detection),
}

fn line_error(e: LineError) -> IoLinkError {
    match e {
        LineError::Read(r) => IoLinkError::Read(r),
        other => IoLinkError::Line(other),
    }
}

/// A JSON number or string.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(untagged)]
enum Value {
    Num(u64),
    Str(String),
}

/// One line before validation: every key optional.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawEvent {
    time: Option<Value>,
    port: Option<Value>,
    kind: Option<String>,
    out: Option<String>,
    #[serde(rename = "in")]
    input: Option<String>,
    rw: Option<String>,
    index: Option<Value>,
    subindex: Option<Value>,
    data: Option<String>,
    error: Option<Value>,
    code: Option<Value>,
    qualifier: Option<Value>,
    text: Option<String>,
}

struct Check {
    line: u64,
}

impl Check {
    fn err(&self, field: &'static str, reason: impl Into<String>) -> IoLinkError {
        IoLinkError::Field {
            line: self.line,
            field,
            reason: reason.into(),
        }
    }

    fn number(
        &self,
        field: &'static str,
        v: Option<Value>,
        max: u64,
    ) -> Result<Option<u64>, IoLinkError> {
        let n = match v {
            None => return Ok(None),
            Some(Value::Num(n)) => n,
            Some(Value::Str(s)) => {
                let s = s.trim();
                parse_int(s).map_err(|_| self.err(field, format!("`{s}` is not a number")))?
            }
        };
        if n > max {
            return Err(self.err(field, format!("{n} is more than {max}")));
        }
        Ok(Some(n))
    }

    fn hex(&self, field: &'static str, v: Option<String>) -> Result<Option<Vec<u8>>, IoLinkError> {
        let Some(s) = v else { return Ok(None) };
        parse_hex(s.trim())
            .map(Some)
            .map_err(|_| self.err(field, format!("`{s}` is not hex bytes")))
    }

    fn absent(&self, kind: &str, field: &'static str, present: bool) -> Result<(), IoLinkError> {
        if present {
            return Err(self.err(field, format!("not allowed for kind `{kind}`")));
        }
        Ok(())
    }
}

fn validate(line: u64, raw: RawEvent) -> Result<IoLinkEvent, IoLinkError> {
    let c = Check { line };
    let time = match raw.time {
        None => None,
        Some(Value::Num(n)) => Some(n),
        Some(Value::Str(s)) => Some(parse_time_field(&s).ok_or_else(|| {
            c.err(
                "time",
                format!("`{s}` is neither microseconds nor ISO 8601"),
            )
        })?),
    };
    let port = c.number("port", raw.port, 255)?.map(|p| p as u8);
    let kind_name = raw.kind.ok_or_else(|| c.err("kind", "missing"))?;
    let k = kind_name.as_str();
    let kind = match k {
        "pd" => {
            for (f, p) in [
                ("rw", raw.rw.is_some()),
                ("index", raw.index.is_some()),
                ("subindex", raw.subindex.is_some()),
                ("data", raw.data.is_some()),
                ("error", raw.error.is_some()),
                ("code", raw.code.is_some()),
                ("qualifier", raw.qualifier.is_some()),
                ("text", raw.text.is_some()),
            ] {
                c.absent(k, f, p)?;
            }
            let out = c.hex("out", raw.out)?;
            let input = c.hex("in", raw.input)?;
            if out.is_none() && input.is_none() {
                return Err(c.err("out", "a `pd` line needs `out` or `in`"));
            }
            IoLinkKind::ProcessData { out, input }
        }
        "isdu_req" => {
            for (f, p) in [
                ("out", raw.out.is_some()),
                ("in", raw.input.is_some()),
                ("error", raw.error.is_some()),
                ("code", raw.code.is_some()),
                ("qualifier", raw.qualifier.is_some()),
                ("text", raw.text.is_some()),
            ] {
                c.absent(k, f, p)?;
            }
            let access = match raw.rw.as_deref().map(str::trim) {
                Some("read" | "r") => Access::Read,
                Some("write" | "w") => Access::Write,
                Some(other) => return Err(c.err("rw", format!("`{other}` is not read or write"))),
                None => return Err(c.err("rw", "missing")),
            };
            let index = c
                .number("index", raw.index, 0xffff)?
                .ok_or_else(|| c.err("index", "missing"))? as u16;
            let subindex = c.number("subindex", raw.subindex, 0xff)?.unwrap_or(0) as u8;
            let data = c.hex("data", raw.data)?;
            let data = match (access, data) {
                (Access::Read, Some(_)) => {
                    return Err(c.err("data", "a read request carries no data"))
                }
                (Access::Read, None) => Vec::new(),
                (Access::Write, Some(d)) => d,
                (Access::Write, None) => return Err(c.err("data", "missing for a write")),
            };
            IoLinkKind::IsduRequest {
                access,
                index,
                subindex,
                data,
            }
        }
        "isdu_res" => {
            for (f, p) in [
                ("out", raw.out.is_some()),
                ("in", raw.input.is_some()),
                ("rw", raw.rw.is_some()),
                ("code", raw.code.is_some()),
                ("qualifier", raw.qualifier.is_some()),
                ("text", raw.text.is_some()),
            ] {
                c.absent(k, f, p)?;
            }
            let index = c.number("index", raw.index, 0xffff)?.map(|n| n as u16);
            let subindex = c.number("subindex", raw.subindex, 0xff)?.map(|n| n as u8);
            let data = c.hex("data", raw.data)?;
            let error = c.number("error", raw.error, 0xffff)?.map(|n| n as u16);
            let result = match (data, error) {
                (Some(_), Some(_)) => {
                    return Err(c.err("error", "a response has data or an error, not both"))
                }
                (Some(d), None) => IsduResult::Data(d),
                (None, Some(e)) => IsduResult::Error(e),
                (None, None) => IsduResult::Data(Vec::new()),
            };
            IoLinkKind::IsduResponse {
                index,
                subindex,
                result,
            }
        }
        "event" => {
            for (f, p) in [
                ("out", raw.out.is_some()),
                ("in", raw.input.is_some()),
                ("rw", raw.rw.is_some()),
                ("index", raw.index.is_some()),
                ("subindex", raw.subindex.is_some()),
                ("data", raw.data.is_some()),
                ("error", raw.error.is_some()),
            ] {
                c.absent(k, f, p)?;
            }
            let code = c
                .number("code", raw.code, 0xffff)?
                .ok_or_else(|| c.err("code", "missing"))? as u16;
            let qualifier = c.number("qualifier", raw.qualifier, 0xff)?.map(|n| n as u8);
            IoLinkKind::PortEvent {
                code,
                qualifier,
                text: raw.text,
            }
        }
        other => {
            return Err(c.err(
                "kind",
                format!("`{other}` is not pd, isdu_req, isdu_res or event"),
            ))
        }
    };
    Ok(IoLinkEvent {
        line,
        time,
        port,
        kind,
    })
}

/// Decodes one JSON line (our doc: module `iolink`).
pub fn parse_json_line(line: u64, text: &str) -> Result<IoLinkEvent, IoLinkError> {
    let raw: RawEvent = serde_json::from_str(text).map_err(|e| IoLinkError::Json {
        line,
        message: e.to_string(),
    })?;
    validate(line, raw)
}

/// Splits a CSV row: commas separate cells; a cell in double quotes may hold commas and `""`.
fn split_csv(row: &str) -> Option<Vec<String>> {
    let mut cells = Vec::new();
    let mut cell = String::new();
    let mut quoted = false;
    let mut chars = row.chars().peekable();
    let mut at_start = true;
    while let Some(ch) = chars.next() {
        if quoted {
            if ch == '"' {
                if chars.peek() == Some(&'"') {
                    chars.next();
                    cell.push('"');
                } else {
                    quoted = false;
                }
            } else {
                cell.push(ch);
            }
        } else if ch == '"' && at_start {
            quoted = true;
            at_start = false;
        } else if ch == ',' {
            cells.push(std::mem::take(&mut cell));
            at_start = true;
        } else {
            cell.push(ch);
            if !ch.is_whitespace() {
                at_start = false;
            }
        }
    }
    if quoted {
        return None;
    }
    cells.push(cell);
    Some(cells)
}

/// Whether `line` is a CSV header of the log (comma-separated known column names, `kind`
/// among them).
pub(crate) fn is_csv_header(line: &str) -> bool {
    parse_header(line).is_ok()
}

fn parse_header(line: &str) -> Result<Vec<usize>, String> {
    let cells = split_csv(line).ok_or("unbalanced quotes")?;
    let mut columns = Vec::new();
    for cell in &cells {
        let name = cell.trim();
        let i = COLUMNS
            .iter()
            .position(|c| *c == name)
            .ok_or_else(|| format!("unknown column `{name}`"))?;
        if columns.contains(&i) {
            return Err(format!("column `{name}` repeated"));
        }
        columns.push(i);
    }
    if !columns.contains(&2) {
        return Err("no `kind` column".into());
    }
    Ok(columns)
}

fn csv_row(line: u64, columns: &[usize], text: &str) -> Result<IoLinkEvent, IoLinkError> {
    let cells = split_csv(text).ok_or(IoLinkError::Cells {
        line,
        cells: 0,
        columns: columns.len(),
    })?;
    if cells.len() != columns.len() {
        return Err(IoLinkError::Cells {
            line,
            cells: cells.len(),
            columns: columns.len(),
        });
    }
    let mut raw = RawEvent::default();
    for (&col, cell) in columns.iter().zip(cells) {
        let cell = cell.trim().to_string();
        if cell.is_empty() {
            continue;
        }
        let v = || Some(Value::Str(cell.clone()));
        match col {
            0 => raw.time = v(),
            1 => raw.port = v(),
            2 => raw.kind = Some(cell),
            3 => raw.out = Some(cell),
            4 => raw.input = Some(cell),
            5 => raw.rw = Some(cell),
            6 => raw.index = v(),
            7 => raw.subindex = v(),
            8 => raw.data = Some(cell),
            9 => raw.error = v(),
            10 => raw.code = v(),
            11 => raw.qualifier = v(),
            _ => raw.text = Some(cell),
        }
    }
    validate(line, raw)
}

/// Reads an IO-Link JSON-lines log (our doc: module `iolink`).
#[derive(Debug)]
pub struct JsonLinesReader<R> {
    lines: Lines<R>,
}

impl<R: Read> JsonLinesReader<R> {
    /// A reader of the log in `reader` (not decompressed; see [`IoLinkReader`]).
    pub fn new(reader: R) -> JsonLinesReader<R> {
        JsonLinesReader {
            lines: Lines::new(reader, MAX_LINE, false),
        }
    }
}

impl<R: Read> Iterator for JsonLinesReader<R> {
    type Item = Result<IoLinkEvent, IoLinkError>;

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
            return Some(parse_json_line(line.number, t));
        }
    }
}

/// Reads an IO-Link CSV log (our doc: module `iolink`).
#[derive(Debug)]
pub struct CsvReader<R> {
    lines: Lines<R>,
    columns: Option<Vec<usize>>,
}

impl<R: Read> CsvReader<R> {
    /// A reader of the log in `reader` (not decompressed; see [`IoLinkReader`]).
    pub fn new(reader: R) -> CsvReader<R> {
        CsvReader {
            lines: Lines::new(reader, MAX_LINE, false),
            columns: None,
        }
    }
}

impl<R: Read> Iterator for CsvReader<R> {
    type Item = Result<IoLinkEvent, IoLinkError>;

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
            let Some(columns) = &self.columns else {
                match parse_header(t) {
                    Ok(c) => {
                        self.columns = Some(c);
                        continue;
                    }
                    Err(reason) => {
                        return Some(Err(IoLinkError::Header {
                            line: line.number,
                            reason,
                        }))
                    }
                }
            };
            return Some(csv_row(line.number, columns, t));
        }
    }
}

/// An IO-Link log in either form, by detected format (our doc: module `iolink`).
#[derive(Debug)]
pub enum IoLinkReader<R: Read> {
    /// JSON lines.
    Json(JsonLinesReader<Input<R>>),
    /// CSV.
    Csv(CsvReader<Input<R>>),
}

impl<R: Read> IoLinkReader<R> {
    /// Opens a log (gzip-compressed or not) and picks the form by detection.
    pub fn open(reader: R) -> Result<IoLinkReader<R>, IoLinkError> {
        let input = Input::open(reader)?;
        let detection = input.detection().clone();
        let gzip = detection.gzip;
        Ok(match detection.format {
            Format::JsonLines => IoLinkReader::Json(JsonLinesReader {
                lines: Lines::new(input, MAX_LINE, gzip),
            }),
            Format::Csv => IoLinkReader::Csv(CsvReader {
                lines: Lines::new(input, MAX_LINE, gzip),
                columns: None,
            }),
            _ => return Err(IoLinkError::NotIoLink(detection)),
        })
    }
}

impl<R: Read> Iterator for IoLinkReader<R> {
    type Item = Result<IoLinkEvent, IoLinkError>;

    fn next(&mut self) -> Option<Self::Item> {
        match self {
            IoLinkReader::Json(r) => r.next(),
            IoLinkReader::Csv(r) => r.next(),
        }
    }
}
