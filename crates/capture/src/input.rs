//! Opening a recording: gzip is peeled off (detected by its magic `1f 8b`, RFC 1952 2.3.1)
//! and the first bytes are kept so the format can be detected without seeking.
//!
//! Memory: the kept prefix is at most [`PEEK`] bytes, or one pcapng section header block when
//! a caller asks for it (bounded by that caller's block limit). Offsets count bytes of the
//! decompressed stream.

use crate::detect::{detect, Detection};
use flate2::read::MultiGzDecoder;
use std::io::{self, BufRead, Read};

/// Bytes read ahead for format detection.
pub const PEEK: usize = 4096;

/// Reading the underlying input failed (our doc: module `input`).
#[derive(Debug, thiserror::Error)]
#[error("read error at byte {offset}{}: {source}", if *.gzip { " of the decompressed stream" } else { "" })]
pub struct ReadError {
    /// Offset (in the decompressed stream) where the read was attempted.
    pub offset: u64,
    /// Whether the input is gzip-compressed (a corrupt gzip stream fails here).
    pub gzip: bool,
    /// The I/O error.
    #[source]
    pub source: io::Error,
}

/// Bytes before an inner reader (our doc: module `input`).
#[derive(Debug)]
struct Prefixed<R> {
    prefix: Vec<u8>,
    pos: usize,
    inner: R,
}

impl<R: Read> Read for Prefixed<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        if let Some(rest) = self.prefix.get(self.pos..).filter(|r| !r.is_empty()) {
            let n = rest.len().min(buf.len());
            if let (Some(dst), Some(src)) = (buf.get_mut(..n), rest.get(..n)) {
                dst.copy_from_slice(src);
            }
            self.pos += n;
            if self.pos >= self.prefix.len() {
                self.prefix = Vec::new();
                self.pos = 0;
            }
            return Ok(n);
        }
        self.inner.read(buf)
    }
}

#[derive(Debug)]
enum Source<R> {
    Plain(Prefixed<R>),
    Gzip(Box<MultiGzDecoder<Prefixed<R>>>),
}

impl<R: Read> Read for Source<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        match self {
            Source::Plain(r) => r.read(buf),
            Source::Gzip(r) => r.read(buf),
        }
    }
}

/// A recording opened for reading: decompressed, with its format detected (our doc: module
/// `input`).
#[derive(Debug)]
pub struct Input<R> {
    inner: Prefixed<Source<R>>,
    detection: Detection,
    delivered: u64,
}

/// Reads until `buf` holds `want` bytes or the reader ends.
fn fill<R: Read>(r: &mut R, buf: &mut Vec<u8>, want: usize) -> io::Result<()> {
    let mut chunk = [0u8; 1024];
    while buf.len() < want {
        let space = (want - buf.len()).min(chunk.len());
        let slot = chunk.get_mut(..space).unwrap_or(&mut []);
        match r.read(slot) {
            Ok(0) => break,
            Ok(n) => buf.extend_from_slice(slot.get(..n).unwrap_or(&[])),
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(())
}

impl<R: Read> Input<R> {
    /// Opens `reader`: peels gzip, reads up to [`PEEK`] bytes and detects the format.
    pub fn open(mut reader: R) -> Result<Input<R>, ReadError> {
        let mut raw = Vec::new();
        fill(&mut reader, &mut raw, PEEK).map_err(|source| ReadError {
            offset: 0,
            gzip: false,
            source,
        })?;
        let gzip = raw.starts_with(&[0x1f, 0x8b]);
        let mut source = if gzip {
            Source::Gzip(Box::new(MultiGzDecoder::new(Prefixed {
                prefix: raw,
                pos: 0,
                inner: reader,
            })))
        } else {
            Source::Plain(Prefixed {
                prefix: raw,
                pos: 0,
                inner: reader,
            })
        };
        let mut prefix = Vec::new();
        fill(&mut source, &mut prefix, PEEK).map_err(|source| ReadError {
            offset: 0,
            gzip,
            source,
        })?;
        let mut detection = detect(&prefix);
        detection.gzip = gzip;
        Ok(Input {
            inner: Prefixed {
                prefix,
                pos: 0,
                inner: source,
            },
            detection,
            delivered: 0,
        })
    }

    /// What the first bytes look like.
    pub fn detection(&self) -> &Detection {
        &self.detection
    }

    /// Bytes delivered so far by `read`.
    pub fn position(&self) -> u64 {
        self.delivered
    }

    /// The bytes read ahead and not yet delivered.
    pub(crate) fn peek(&self) -> &[u8] {
        self.inner.prefix.get(self.inner.pos..).unwrap_or(&[])
    }

    /// Extends the read-ahead to at least `want` bytes (fewer at the end of the input).
    pub(crate) fn peek_at_least(&mut self, want: usize) -> Result<&[u8], ReadError> {
        if self.peek().len() < want {
            let mut rest = self.peek().to_vec();
            let gzip = self.detection.gzip;
            let offset = self.delivered + rest.len() as u64;
            fill(&mut self.inner.inner, &mut rest, want).map_err(|source| ReadError {
                offset,
                gzip,
                source,
            })?;
            self.inner.prefix = rest;
            self.inner.pos = 0;
        }
        Ok(self.peek())
    }
}

impl<R: Read> Read for Input<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.delivered += n as u64;
        Ok(n)
    }
}

/// Why a line of a text log cannot be read (our doc: module `input`).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum LineError {
    /// The line is longer than the limit; it was skipped.
    #[error("line {line} (byte {offset}) is longer than {limit} bytes")]
    TooLong {
        /// 1-based line number.
        line: u64,
        /// Offset of its first byte.
        offset: u64,
        /// The limit.
        limit: usize,
    },
    /// The line is not UTF-8.
    #[error("line {line} (byte {offset}) is not UTF-8")]
    NotUtf8 {
        /// 1-based line number.
        line: u64,
        /// Offset of its first byte.
        offset: u64,
    },
    /// Reading failed.
    #[error(transparent)]
    Read(#[from] ReadError),
}

/// A line read by [`Lines`]: its number, offset and text without the line end.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Line {
    pub(crate) number: u64,
    pub(crate) offset: u64,
    pub(crate) text: String,
}

/// A bounded line reader: lines longer than the limit are skipped and reported.
#[derive(Debug)]
pub(crate) struct Lines<R> {
    reader: io::BufReader<R>,
    limit: usize,
    line: u64,
    offset: u64,
    gzip: bool,
    failed: bool,
}

impl<R: Read> Lines<R> {
    pub(crate) fn new(reader: R, limit: usize, gzip: bool) -> Lines<R> {
        Lines {
            reader: io::BufReader::new(reader),
            limit,
            line: 0,
            offset: 0,
            gzip,
            failed: false,
        }
    }

    /// The next line, `None` at the end; after an I/O error, always `None`.
    pub(crate) fn next_line(&mut self) -> Option<Result<Line, LineError>> {
        if self.failed {
            return None;
        }
        let start = self.offset;
        let mut buf: Vec<u8> = Vec::new();
        let mut too_long = false;
        let mut any = false;
        loop {
            let available = match self.reader.fill_buf() {
                Ok(b) => b,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
                Err(source) => {
                    self.failed = true;
                    return Some(Err(LineError::Read(ReadError {
                        offset: self.offset,
                        gzip: self.gzip,
                        source,
                    })));
                }
            };
            if available.is_empty() {
                break;
            }
            any = true;
            let (used, done) = match available.iter().position(|&b| b == b'\n') {
                Some(i) => (i + 1, true),
                None => (available.len(), false),
            };
            let piece = available.get(..used).unwrap_or(&[]);
            if !too_long {
                if buf.len() + piece.len() > self.limit.saturating_add(2) {
                    too_long = true;
                    buf = Vec::new();
                } else {
                    buf.extend_from_slice(piece);
                }
            }
            self.reader.consume(used);
            self.offset += used as u64;
            if done {
                break;
            }
        }
        if !any {
            return None;
        }
        self.line += 1;
        if too_long {
            return Some(Err(LineError::TooLong {
                line: self.line,
                offset: start,
                limit: self.limit,
            }));
        }
        while matches!(buf.last(), Some(b'\n' | b'\r')) {
            buf.pop();
        }
        if self.line == 1 && buf.starts_with(crate::detect::BOM) {
            buf.drain(..crate::detect::BOM.len());
        }
        if buf.len() > self.limit {
            return Some(Err(LineError::TooLong {
                line: self.line,
                offset: start,
                limit: self.limit,
            }));
        }
        match String::from_utf8(buf) {
            Ok(text) => Some(Ok(Line {
                number: self.line,
                offset: start,
                text,
            })),
            Err(_) => Some(Err(LineError::NotUtf8 {
                line: self.line,
                offset: start,
            })),
        }
    }
}
