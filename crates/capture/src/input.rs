//! Opening a recording: gzip is peeled off (detected by its magic `1f 8b`, RFC 1952 2.3.1)
//! and the first bytes are kept so the format can be detected without seeking.
//!
//! Every gzip member is read in turn (RFC 1952 2.2); bytes after the last complete member
//! that do not start another one end the stream with a [`GzipTail`] error at their place,
//! after everything before them was delivered. A read error never drops bytes read before
//! it: it is kept and raised when the reader gets there.
//!
//! Memory: the kept prefix is at most [`PEEK`] bytes, or one pcapng section header block when
//! a caller asks for it (bounded by that caller's block limit). Offsets count bytes of the
//! decompressed stream.

use crate::detect::{detect, Detection};
use flate2::bufread::GzDecoder;
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

/// Bytes after the last complete gzip member that are not gzip (our doc: module `input`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("the {members} gzip member(s) before compressed byte {offset} were read; the bytes from there on are not gzip")]
pub struct GzipTail {
    /// Complete members read.
    pub members: u64,
    /// Offset in the compressed file of the first byte that is not gzip.
    pub offset: u64,
}

/// Bytes before an inner reader, then a read error met while filling them (our doc: module
/// `input`).
#[derive(Debug)]
struct Prefixed<R> {
    prefix: Vec<u8>,
    pos: usize,
    pending: Option<io::Error>,
    inner: R,
}

impl<R> Prefixed<R> {
    fn new(prefix: Vec<u8>, pending: Option<io::Error>, inner: R) -> Prefixed<R> {
        Prefixed {
            prefix,
            pos: 0,
            pending,
            inner,
        }
    }
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
        if let Some(e) = self.pending.take() {
            return Err(e);
        }
        self.inner.read(buf)
    }
}

/// Counts the bytes read from the inner reader.
#[derive(Debug)]
struct Counted<R> {
    inner: R,
    count: u64,
}

impl<R: Read> Read for Counted<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.count += n as u64;
        Ok(n)
    }
}

/// The gzip members of a stream one after the other (RFC 1952 2.2), ending at bytes that are
/// not gzip with a [`GzipTail`] error.
#[derive(Debug)]
struct Members<R> {
    decoder: Option<GzDecoder<io::BufReader<Counted<R>>>>,
    /// Complete members read.
    members: u64,
    /// Whether the current member has delivered nothing yet.
    fresh: bool,
    /// Compressed offset where the current member starts.
    start: u64,
}

impl<R: Read> Members<R> {
    fn new(inner: R) -> Members<R> {
        let reader = io::BufReader::new(Counted { inner, count: 0 });
        Members {
            decoder: Some(GzDecoder::new(reader)),
            members: 0,
            fresh: true,
            start: 0,
        }
    }

    fn tail(&self) -> io::Error {
        io::Error::new(
            io::ErrorKind::InvalidData,
            GzipTail {
                members: self.members,
                offset: self.start,
            },
        )
    }
}

impl<R: Read> Read for Members<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        if buf.is_empty() {
            return Ok(0);
        }
        loop {
            let Some(decoder) = self.decoder.as_mut() else {
                return Ok(0);
            };
            match decoder.read(buf) {
                Ok(0) => {
                    let Some(done) = self.decoder.take() else {
                        return Ok(0);
                    };
                    self.members += 1;
                    let mut reader = done.into_inner();
                    let buffered = reader.buffer().len() as u64;
                    self.start = reader.get_ref().count - buffered;
                    if reader.fill_buf()?.is_empty() {
                        return Ok(0);
                    }
                    self.fresh = true;
                    self.decoder = Some(GzDecoder::new(reader));
                }
                Ok(n) => {
                    self.fresh = false;
                    return Ok(n);
                }
                Err(e) if e.kind() == io::ErrorKind::Interrupted => return Err(e),
                Err(_) if self.fresh && self.members > 0 => {
                    self.decoder = None;
                    return Err(self.tail());
                }
                Err(e) => return Err(e),
            }
        }
    }
}

#[derive(Debug)]
enum Source<R> {
    Plain(Prefixed<R>),
    Gzip(Box<Members<Prefixed<R>>>),
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

/// Reads until `buf` holds `want` bytes or the reader ends; on an error `buf` keeps what came
/// before it.
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
            Source::Gzip(Box::new(Members::new(Prefixed::new(raw, None, reader))))
        } else {
            Source::Plain(Prefixed::new(raw, None, reader))
        };
        let mut prefix = Vec::new();
        let pending = match fill(&mut source, &mut prefix, PEEK) {
            Ok(()) => None,
            Err(e) if !prefix.is_empty() => Some(e),
            Err(source) => {
                return Err(ReadError {
                    offset: 0,
                    gzip,
                    source,
                })
            }
        };
        let mut detection = detect(&prefix);
        detection.gzip = gzip;
        Ok(Input {
            inner: Prefixed::new(prefix, pending, source),
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
            if self.inner.pending.is_none() {
                let before = rest.len();
                if let Err(e) = fill(&mut self.inner.inner, &mut rest, want) {
                    if rest.len() == before {
                        return Err(ReadError {
                            offset: self.delivered + before as u64,
                            gzip,
                            source: e,
                        });
                    }
                    self.inner.pending = Some(e);
                }
            }
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
