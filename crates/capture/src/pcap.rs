//! Reading pcap and pcapng captures through one pull API, on top of `pcap-parser`'s
//! streaming readers.
//!
//! [`CaptureReader::next_record`] lends each record ([`RecordRef`]) straight out of the read
//! buffer; the [`Iterator`] implementation hands out owned [`Record`]s. Either way:
//!
//! - **Bounded memory.** One read buffer, grown only for a block that does not fit, up to
//!   [`Options::max_block`]; a longer block is an error, whatever the file size.
//! - **Errors name the offset** (decompressed stream for gzip input) and the number of the
//!   record that could not be read; every record before the error has been yielded. After an
//!   error the reader yields nothing more.
//! - **No panic** on any input. Block framing is checked here before `pcap-parser` sees a
//!   block (lengths, trailer, captured length), so corrupt lengths give
//!   [`CaptureError::BadBlockLength`] / [`CaptureError::BadCapturedLength`] instead of a wait
//!   for bytes that never come.
//!
//! Timestamps are microseconds since 1970 (UTC). pcap: seconds and micro- or nanoseconds of
//! the record header (pcap draft 5). pcapng: the 64-bit Enhanced Packet Block timestamp
//! (pcapng draft 4.3) in units of the interface's `if_tsresol` (default 10^-6; bit 7 set means
//! a power of two), plus its `if_tsoffset` in seconds (pcapng draft 4.2). Simple Packet Blocks
//! have no timestamp. Record numbers count from 1, as Wireshark's frame numbers do.

use crate::bytes::Endian;
use crate::detect::Format;
use crate::input::{Input, ReadError};
use crate::link::LinkType;
use pcap_parser::pcapng::Block;
use pcap_parser::traits::PcapReaderIterator;
use pcap_parser::{LegacyPcapReader, PcapBlockOwned, PcapError, PcapNGReader};
use std::io::{self, Read};
use std::sync::{Arc, Mutex};

/// pcapng block types (pcapng draft 11.1).
mod block {
    pub const SHB: u32 = 0x0A0D_0D0A;
    pub const IDB: u32 = 0x0000_0001;
    pub const SPB: u32 = 0x0000_0003;
    pub const EPB: u32 = 0x0000_0006;
}

/// Limits of a [`CaptureReader`] (our doc: module `pcap`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Options {
    /// Largest block or record accepted, in bytes (read buffer limit).
    pub max_block: usize,
    /// Most interfaces per pcapng section.
    pub max_interfaces: usize,
}

impl Default for Options {
    fn default() -> Options {
        Options {
            max_block: 4 << 20,
            max_interfaces: 4096,
        }
    }
}

/// Why a capture cannot be read further (our doc: module `pcap`).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CaptureError {
    /// The underlying reader failed.
    #[error(transparent)]
    Read(#[from] ReadError),
    /// The input is not pcap or pcapng.
    #[error("not a pcap or pcapng capture: detected {detected}")]
    NotACapture {
        /// What detection saw.
        detected: crate::detect::Detection,
    },
    /// A variant `pcap-parser` does not read.
    #[error("unsupported capture variant: {what}")]
    Unsupported {
        /// Which.
        what: &'static str,
    },
    /// The file ends inside a header, block or record.
    #[error("truncated {what} at byte {offset} (record {record}): {have} byte(s) left{}", need.map(|n| format!(", the block needs {n}")).unwrap_or_default())]
    Truncated {
        /// Offset of the unfinished header, block or record.
        offset: u64,
        /// Number the next record would have had.
        record: u64,
        /// What was cut: "file header", "block", "record".
        what: &'static str,
        /// Bytes present from `offset` to the end.
        have: usize,
        /// Bytes the block or record declares, when known.
        need: Option<u64>,
    },
    /// A pcapng block length is impossible (pcapng draft 3.1: at least 12, a multiple of 4,
    /// equal in header and trailer).
    #[error("bad block length at byte {offset} (record {record}): block type {block_type:#010x}, length {length}{}", trailer.map(|t| format!(", trailer says {t}")).unwrap_or_default())]
    BadBlockLength {
        /// Offset of the block.
        offset: u64,
        /// Number the next record would have had.
        record: u64,
        /// Block type.
        block_type: u32,
        /// Length in the block header.
        length: u32,
        /// Length in the block trailer, when it differs.
        trailer: Option<u32>,
    },
    /// A block or record larger than [`Options::max_block`].
    #[error("block at byte {offset} (record {record}) declares {length} bytes, more than the limit of {limit}")]
    TooLarge {
        /// Offset of the block or record.
        offset: u64,
        /// Number of the record.
        record: u64,
        /// Declared length.
        length: u64,
        /// The limit.
        limit: usize,
    },
    /// A packet's captured length does not fit in its block (pcapng draft 4.3).
    #[error("record {record} at byte {offset}: captured length {captured} does not fit in a block of {block_length} bytes")]
    BadCapturedLength {
        /// Offset of the block.
        offset: u64,
        /// Record number.
        record: u64,
        /// Captured length declared.
        captured: u32,
        /// Block length.
        block_length: u32,
    },
    /// A packet names an interface that no Interface Description Block declared.
    #[error("record {record} at byte {offset} names interface {interface}, but the section declares {declared}")]
    UnknownInterface {
        /// Offset of the block.
        offset: u64,
        /// Record number.
        record: u64,
        /// Interface id in the packet.
        interface: u32,
        /// Interfaces declared in this section.
        declared: usize,
    },
    /// Too many interfaces in one section.
    #[error("interface description at byte {offset}: more than {limit} interfaces in one section")]
    TooManyInterfaces {
        /// Offset of the block.
        offset: u64,
        /// The limit.
        limit: usize,
    },
    /// An `if_tsresol` that gives no usable unit (pcapng draft 4.2).
    #[error("interface description at byte {offset}: if_tsresol {value:#04x} is not a usable resolution")]
    BadResolution {
        /// Offset of the block.
        offset: u64,
        /// The option value.
        value: u8,
    },
    /// `pcap-parser` rejected a header or block.
    #[error("corrupt {what} at byte {offset} (record {record}): {detail}")]
    Corrupt {
        /// Offset of the header or block.
        offset: u64,
        /// Number the next record would have had.
        record: u64,
        /// What: "file header", "block", "record".
        what: &'static str,
        /// The parser's message.
        detail: String,
    },
}

/// One capture interface: pcap has one, pcapng one per Interface Description Block
/// (pcapng draft 4.2).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Interface {
    /// Link type (LINKTYPE_* value, pcap draft 5 / linktypes registry).
    pub link_type: LinkType,
    /// Snapshot length (0: none).
    pub snaplen: u32,
    /// The `if_tsresol` byte (6 = microseconds; pcap: 6 or 9).
    pub tsresol: u8,
    /// `if_tsoffset`, seconds added to every timestamp.
    pub tsoffset: i64,
    /// `if_name`, if given.
    pub name: Option<String>,
    units_per_second: u128,
}

impl Interface {
    fn new(link_type: LinkType, snaplen: u32, tsresol: u8, tsoffset: i64) -> Option<Interface> {
        let exp = u32::from(tsresol & 0x7f);
        let units_per_second = if tsresol & 0x80 == 0 {
            10u128.checked_pow(exp).filter(|_| exp <= 19)?
        } else {
            1u128.checked_shl(exp).filter(|_| exp <= 63)?
        };
        Some(Interface {
            link_type,
            snaplen,
            tsresol,
            tsoffset,
            name: None,
            units_per_second,
        })
    }

    /// Converts a timestamp in this interface's units to microseconds since 1970.
    pub fn micros(&self, ts: u64) -> Option<u64> {
        let us = u128::from(ts).checked_mul(1_000_000)? / self.units_per_second.max(1);
        let total = i128::try_from(us).ok()? + i128::from(self.tsoffset) * 1_000_000;
        u64::try_from(total).ok()
    }
}

/// A record lent out of the read buffer (pcap draft 5 record / pcapng draft 4.3, 4.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RecordRef<'a> {
    /// Record number, from 1.
    pub number: u64,
    /// Offset of its record header or block.
    pub offset: u64,
    /// Microseconds since 1970 (UTC); `None` for Simple Packet Blocks or out of range.
    pub time: Option<u64>,
    /// Interface id (0 in pcap).
    pub interface: u32,
    /// Link type of the interface.
    pub link_type: LinkType,
    /// Length on the wire.
    pub orig_len: u32,
    /// The captured bytes (their count is the captured length).
    pub data: &'a [u8],
}

impl RecordRef<'_> {
    /// An owned copy.
    pub fn to_record(&self) -> Record {
        Record {
            number: self.number,
            offset: self.offset,
            time: self.time,
            interface: self.interface,
            link_type: self.link_type,
            orig_len: self.orig_len,
            data: self.data.to_vec(),
        }
    }
}

/// An owned record (see [`RecordRef`]; pcap draft 5 / pcapng draft 4.3).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Record {
    /// Record number, from 1.
    pub number: u64,
    /// Offset of its record header or block.
    pub offset: u64,
    /// Microseconds since 1970 (UTC).
    pub time: Option<u64>,
    /// Interface id (0 in pcap).
    pub interface: u32,
    /// Link type of the interface.
    pub link_type: LinkType,
    /// Length on the wire.
    pub orig_len: u32,
    /// The captured bytes.
    pub data: Vec<u8>,
}

impl Record {
    /// Borrowed view.
    pub fn view(&self) -> RecordRef<'_> {
        RecordRef {
            number: self.number,
            offset: self.offset,
            time: self.time,
            interface: self.interface,
            link_type: self.link_type,
            orig_len: self.orig_len,
            data: &self.data,
        }
    }
}

/// The reader handed to `pcap-parser`: retries interrupted reads and keeps the I/O error,
/// which `pcap-parser` reduces to `ReadError`.
struct Tap<R> {
    input: Input<R>,
    error: Arc<Mutex<Option<io::Error>>>,
}

impl<R: Read> Read for Tap<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        loop {
            match self.input.read(buf) {
                Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
                Err(e) => {
                    let copy = io::Error::new(e.kind(), e.to_string());
                    if let Ok(mut slot) = self.error.lock() {
                        *slot = Some(e);
                    }
                    return Err(copy);
                }
                ok => return ok,
            }
        }
    }
}

enum Inner<R: Read> {
    Legacy(LegacyPcapReader<Tap<R>>),
    Ng(PcapNGReader<Tap<R>>),
}

/// What one parsed block amounts to.
enum Step {
    Record {
        start: usize,
        len: usize,
        interface: u32,
        time: Option<u64>,
        orig_len: u32,
    },
    Skip,
}

/// A streaming reader of pcap and pcapng captures (our doc: module `pcap`).
pub struct CaptureReader<R: Read> {
    inner: Inner<R>,
    format: Format,
    gzip: bool,
    options: Options,
    capacity: usize,
    interfaces: Vec<Interface>,
    /// Byte order of the current pcapng section (or of the pcap file).
    endian: Endian,
    /// Bytes of the last block still to be consumed.
    pending: usize,
    records: u64,
    skipped: u64,
    done: bool,
    error: Arc<Mutex<Option<io::Error>>>,
}

impl<R: Read> std::fmt::Debug for CaptureReader<R> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CaptureReader")
            .field("format", &self.format)
            .field("gzip", &self.gzip)
            .field("records", &self.records)
            .field("interfaces", &self.interfaces)
            .finish_non_exhaustive()
    }
}

const INITIAL_CAPACITY: usize = 64 * 1024;

fn u32_at(bytes: &[u8], at: usize, endian: Endian) -> Option<u32> {
    let b = <[u8; 4]>::try_from(bytes.get(at..at.checked_add(4)?)?).ok()?;
    Some(match endian {
        Endian::Big => u32::from_be_bytes(b),
        Endian::Little => u32::from_le_bytes(b),
    })
}

fn shb_endian(bytes: &[u8]) -> Option<Endian> {
    match bytes.get(8..12)? {
        [0x4d, 0x3c, 0x2b, 0x1a] => Some(Endian::Little),
        [0x1a, 0x2b, 0x3c, 0x4d] => Some(Endian::Big),
        _ => None,
    }
}

impl<R: Read> CaptureReader<R> {
    /// Opens a pcap or pcapng capture (gzip-compressed or not) with default [`Options`].
    pub fn new(reader: R) -> Result<CaptureReader<R>, CaptureError> {
        CaptureReader::with_options(reader, Options::default())
    }

    /// Opens a capture with the given limits.
    pub fn with_options(reader: R, options: Options) -> Result<CaptureReader<R>, CaptureError> {
        CaptureReader::from_input(Input::open(reader)?, options)
    }

    /// Reads a capture from an opened [`Input`].
    pub fn from_input(
        mut input: Input<R>,
        options: Options,
    ) -> Result<CaptureReader<R>, CaptureError> {
        let detection = input.detection().clone();
        let gzip = detection.gzip;
        let format = detection.format;
        let error = Arc::new(Mutex::new(None));
        let corrupt = |detail: String| CaptureError::Corrupt {
            offset: 0,
            record: 1,
            what: "file header",
            detail,
        };
        let (inner, endian, capacity) = match format {
            Format::Pcap {
                endian, modified, ..
            } => {
                if modified && endian == Endian::Big {
                    return Err(CaptureError::Unsupported {
                        what: "big-endian modified pcap",
                    });
                }
                let have = input.peek().len();
                if have < 24 {
                    return Err(CaptureError::Truncated {
                        offset: 0,
                        record: 1,
                        what: "file header",
                        have,
                        need: Some(24),
                    });
                }
                let tap = Tap {
                    input,
                    error: Arc::clone(&error),
                };
                let r = LegacyPcapReader::new(INITIAL_CAPACITY, tap)
                    .map_err(|e| corrupt(e.to_string()))?;
                (Inner::Legacy(r), endian, INITIAL_CAPACITY)
            }
            Format::PcapNg { .. } => {
                let head = input.peek_at_least(12)?;
                let have = head.len();
                let Some(endian) = shb_endian(head) else {
                    if have < 12 {
                        return Err(CaptureError::Truncated {
                            offset: 0,
                            record: 1,
                            what: "block",
                            have,
                            need: None,
                        });
                    }
                    return Err(corrupt(
                        "section header byte-order magic not recognised".into(),
                    ));
                };
                let length = u32_at(head, 4, endian).unwrap_or(0);
                check_length(0, 1, block::SHB, length, &options)?;
                let length = length as usize;
                let head = input.peek_at_least(length)?;
                if head.len() < length {
                    return Err(CaptureError::Truncated {
                        offset: 0,
                        record: 1,
                        what: "block",
                        have: head.len(),
                        need: Some(length as u64),
                    });
                }
                check_trailer(head, 0, 1, block::SHB, length, endian)?;
                let capacity = INITIAL_CAPACITY.max(length.saturating_add(1));
                let tap = Tap {
                    input,
                    error: Arc::clone(&error),
                };
                let r = PcapNGReader::new(capacity, tap).map_err(|e| corrupt(e.to_string()))?;
                (Inner::Ng(r), endian, capacity)
            }
            _ => {
                // A file cut inside the magic number is a truncated capture, not another format.
                let head = input.peek();
                let magics: [&[u8]; 7] = [
                    &[0xd4, 0xc3, 0xb2, 0xa1],
                    &[0xa1, 0xb2, 0xc3, 0xd4],
                    &[0x4d, 0x3c, 0xb2, 0xa1],
                    &[0xa1, 0xb2, 0x3c, 0x4d],
                    &[0x34, 0xcd, 0xb2, 0xa1],
                    &[0xa1, 0xb2, 0xcd, 0x34],
                    &[0x0a, 0x0d, 0x0d, 0x0a],
                ];
                if !head.is_empty() && head.len() < 4 && magics.iter().any(|m| m.starts_with(head))
                {
                    return Err(CaptureError::Truncated {
                        offset: 0,
                        record: 1,
                        what: "file header",
                        have: head.len(),
                        need: None,
                    });
                }
                return Err(CaptureError::NotACapture {
                    detected: detection,
                });
            }
        };
        Ok(CaptureReader {
            inner,
            format,
            gzip,
            options,
            capacity,
            interfaces: Vec::new(),
            endian,
            pending: 0,
            records: 0,
            skipped: 0,
            done: false,
            error,
        })
    }

    /// The capture format.
    pub fn format(&self) -> Format {
        self.format
    }

    /// Whether the input was gzip-compressed.
    pub fn gzip(&self) -> bool {
        self.gzip
    }

    /// Interfaces of the current section (pcap: the one of the file header, once read).
    pub fn interfaces(&self) -> &[Interface] {
        &self.interfaces
    }

    /// Records yielded so far.
    pub fn records_read(&self) -> u64 {
        self.records
    }

    /// Blocks skipped (pcapng blocks other than SHB, IDB, EPB and SPB).
    pub fn skipped_blocks(&self) -> u64 {
        self.skipped
    }

    /// Offset of the next unread block or record.
    pub fn offset(&self) -> u64 {
        let consumed = match &self.inner {
            Inner::Legacy(r) => r.consumed(),
            Inner::Ng(r) => r.consumed(),
        };
        (consumed + self.pending) as u64
    }

    fn fail(&mut self, e: CaptureError) -> Result<Option<RecordRef<'_>>, CaptureError> {
        self.done = true;
        Err(e)
    }

    /// The next record, `Ok(None)` at the end of the capture.
    pub fn next_record(&mut self) -> Result<Option<RecordRef<'_>>, CaptureError> {
        if self.done {
            return Ok(None);
        }
        loop {
            self.consume_pending();
            let offset = self.offset();
            let record = self.records + 1;
            if let Err(e) = self.check_framing(offset, record) {
                return self.fail(e);
            }
            let outcome = match &mut self.inner {
                Inner::Legacy(r) => {
                    let header_len = match self.format {
                        Format::Pcap { modified: true, .. } => 24,
                        _ => 16,
                    };
                    match r.next() {
                        Ok((n, block)) => {
                            Ok((n, Ok(legacy_step(block, &mut self.interfaces, header_len))))
                        }
                        Err(e) => Err(Failure::from(e)),
                    }
                }
                Inner::Ng(r) => match r.next() {
                    Ok((n, block)) => Ok((
                        n,
                        ng_step(
                            block,
                            offset,
                            record,
                            &mut self.interfaces,
                            &mut self.endian,
                            &self.options,
                            &mut self.skipped,
                        ),
                    )),
                    Err(e) => Err(Failure::from(e)),
                },
            };
            match outcome {
                Ok((n, Ok(Step::Skip))) => {
                    self.pending = n;
                }
                Ok((
                    n,
                    Ok(Step::Record {
                        start,
                        len,
                        interface,
                        time,
                        orig_len,
                    }),
                )) => {
                    self.pending = n;
                    self.records += 1;
                    let link_type = self
                        .interfaces
                        .get(interface as usize)
                        .map_or(LinkType(0), |i| i.link_type);
                    let data = match &self.inner {
                        Inner::Legacy(r) => r.data(),
                        Inner::Ng(r) => r.data(),
                    };
                    let data = data.get(start..start.saturating_add(len)).unwrap_or(&[]);
                    return Ok(Some(RecordRef {
                        number: record,
                        offset,
                        time,
                        interface,
                        link_type,
                        orig_len,
                        data,
                    }));
                }
                Ok((_, Err(e))) => return self.fail(e),
                Err(Failure::Eof) => {
                    self.done = true;
                    return Ok(None);
                }
                Err(Failure::Incomplete) => {
                    if let Err(e) = self.refill(offset, record) {
                        return self.fail(e);
                    }
                }
                Err(Failure::Truncated) => {
                    let have = self.buffered();
                    let need = self.declared_length();
                    return self.fail(CaptureError::Truncated {
                        offset,
                        record,
                        what: self.unit(),
                        have,
                        need,
                    });
                }
                Err(Failure::BufferTooSmall) => {
                    if let Err(e) = self.grow(offset, record) {
                        return self.fail(e);
                    }
                }
                Err(Failure::Read) => {
                    let source = self
                        .error
                        .lock()
                        .ok()
                        .and_then(|mut s| s.take())
                        .unwrap_or_else(|| io::Error::other("read error"));
                    let e = CaptureError::Read(ReadError {
                        offset: offset + self.buffered() as u64,
                        gzip: self.gzip,
                        source,
                    });
                    return self.fail(e);
                }
                Err(Failure::Parse(detail)) => {
                    let what = self.unit();
                    return self.fail(CaptureError::Corrupt {
                        offset,
                        record,
                        what,
                        detail,
                    });
                }
            }
        }
    }

    fn unit(&self) -> &'static str {
        match self.inner {
            Inner::Legacy(_) => "record",
            Inner::Ng(_) => "block",
        }
    }

    fn consume_pending(&mut self) {
        let n = std::mem::take(&mut self.pending);
        if n > 0 {
            match &mut self.inner {
                Inner::Legacy(r) => r.consume(n),
                Inner::Ng(r) => r.consume(n),
            }
        }
    }

    fn buffered(&self) -> usize {
        match &self.inner {
            Inner::Legacy(r) => r.data().len(),
            Inner::Ng(r) => r.data().len(),
        }
    }

    /// Length the next block or record declares, if its header is buffered.
    fn declared_length(&self) -> Option<u64> {
        match &self.inner {
            Inner::Legacy(r) => {
                let header = self.legacy_header_len();
                let caplen = u32_at(r.data(), 8, self.endian)?;
                Some(u64::from(caplen) + header as u64)
            }
            Inner::Ng(r) => {
                let data = r.data();
                let endian = if u32_at(data, 0, Endian::Little)? == block::SHB {
                    shb_endian(data)?
                } else {
                    self.endian
                };
                u32_at(data, 4, endian).map(u64::from)
            }
        }
    }

    fn legacy_header_len(&self) -> usize {
        match self.format {
            Format::Pcap { modified: true, .. } => 24,
            _ => 16,
        }
    }

    /// Checks the framing of the block or record at the start of the buffer, as far as it
    /// is buffered.
    fn check_framing(&self, offset: u64, record: u64) -> Result<(), CaptureError> {
        match &self.inner {
            Inner::Legacy(r) => {
                if r.consumed() == 0 {
                    return Ok(()); // the file header, checked when opening
                }
                let Some(caplen) = u32_at(r.data(), 8, self.endian) else {
                    return Ok(());
                };
                let total = u64::from(caplen) + self.legacy_header_len() as u64;
                if total > self.options.max_block as u64 {
                    return Err(CaptureError::TooLarge {
                        offset,
                        record,
                        length: total,
                        limit: self.options.max_block,
                    });
                }
                Ok(())
            }
            Inner::Ng(r) => {
                let data = r.data();
                let Some(block_type) = u32_at(data, 0, Endian::Little) else {
                    return Ok(());
                };
                let endian = if block_type == block::SHB {
                    match shb_endian(data) {
                        Some(e) => e,
                        None if data.len() < 12 => return Ok(()),
                        None => {
                            return Err(CaptureError::Corrupt {
                                offset,
                                record,
                                what: "block",
                                detail: "section header byte-order magic not recognised".into(),
                            })
                        }
                    }
                } else {
                    self.endian
                };
                let block_type = match endian {
                    Endian::Little => block_type,
                    Endian::Big => block_type.swap_bytes(),
                };
                let Some(length) = u32_at(data, 4, endian) else {
                    return Ok(());
                };
                check_length(offset, record, block_type, length, &self.options)?;
                if data.len() >= length as usize {
                    check_trailer(data, offset, record, block_type, length as usize, endian)?;
                }
                if block_type == block::EPB {
                    if let Some(captured) = u32_at(data, 20, endian) {
                        if u64::from(captured) + 32 > u64::from(length) {
                            return Err(CaptureError::BadCapturedLength {
                                offset,
                                record,
                                captured,
                                block_length: length,
                            });
                        }
                    }
                }
                Ok(())
            }
        }
    }

    fn refill(&mut self, offset: u64, record: u64) -> Result<(), CaptureError> {
        let before = self.buffered();
        let result = match &mut self.inner {
            Inner::Legacy(r) => r.refill().map_err(|e| e.to_string()),
            Inner::Ng(r) => r.refill().map_err(|e| e.to_string()),
        };
        if result.is_err() {
            let source = self
                .error
                .lock()
                .ok()
                .and_then(|mut s| s.take())
                .unwrap_or_else(|| io::Error::other("read error"));
            return Err(CaptureError::Read(ReadError {
                offset: offset + before as u64,
                gzip: self.gzip,
                source,
            }));
        }
        let exhausted = match &self.inner {
            Inner::Legacy(r) => r.reader_exhausted(),
            Inner::Ng(r) => r.reader_exhausted(),
        };
        if self.buffered() == before && !exhausted {
            // The buffer is full and the parser still wants more: make room.
            self.grow(offset, record)?;
        }
        Ok(())
    }

    fn grow(&mut self, offset: u64, record: u64) -> Result<(), CaptureError> {
        let limit = self.options.max_block.saturating_add(64);
        if self.capacity >= limit {
            return Err(CaptureError::TooLarge {
                offset,
                record,
                length: self.declared_length().unwrap_or(self.capacity as u64),
                limit: self.options.max_block,
            });
        }
        let wanted = self.declared_length().map_or(0, |n| {
            usize::try_from(n).unwrap_or(usize::MAX).saturating_add(1)
        });
        let new = self.capacity.saturating_mul(2).max(wanted).min(limit);
        let grown = match &mut self.inner {
            Inner::Legacy(r) => r.grow(new),
            Inner::Ng(r) => r.grow(new),
        };
        if grown {
            self.capacity = new;
        }
        Ok(())
    }
}

fn check_length(
    offset: u64,
    record: u64,
    block_type: u32,
    length: u32,
    options: &Options,
) -> Result<(), CaptureError> {
    let min = match block_type {
        block::SHB => 28,
        block::IDB => 20,
        block::EPB => 32,
        block::SPB => 16,
        _ => 12,
    };
    if length < min || length % 4 != 0 {
        return Err(CaptureError::BadBlockLength {
            offset,
            record,
            block_type,
            length,
            trailer: None,
        });
    }
    if length as usize > options.max_block {
        return Err(CaptureError::TooLarge {
            offset,
            record,
            length: u64::from(length),
            limit: options.max_block,
        });
    }
    Ok(())
}

fn check_trailer(
    data: &[u8],
    offset: u64,
    record: u64,
    block_type: u32,
    length: usize,
    endian: Endian,
) -> Result<(), CaptureError> {
    let trailer = u32_at(data, length.saturating_sub(4), endian);
    let header = u32_at(data, 4, endian);
    if trailer != header {
        return Err(CaptureError::BadBlockLength {
            offset,
            record,
            block_type,
            length: header.unwrap_or(0),
            trailer,
        });
    }
    Ok(())
}

/// A `pcap-parser` error, without the borrow of its buffer.
enum Failure {
    Eof,
    Incomplete,
    Truncated,
    BufferTooSmall,
    Read,
    Parse(String),
}

impl From<PcapError<&[u8]>> for Failure {
    fn from(e: PcapError<&[u8]>) -> Failure {
        match e {
            PcapError::Eof => Failure::Eof,
            PcapError::Incomplete(_) => Failure::Incomplete,
            PcapError::UnexpectedEof => Failure::Truncated,
            PcapError::BufferTooSmall => Failure::BufferTooSmall,
            PcapError::ReadError => Failure::Read,
            PcapError::HeaderNotRecognized => Failure::Parse("header not recognised".into()),
            PcapError::NomError(_, kind) | PcapError::OwnedNomError(_, kind) => {
                Failure::Parse(format!("invalid block ({kind:?})"))
            }
        }
    }
}

fn legacy_step(
    block: PcapBlockOwned<'_>,
    interfaces: &mut Vec<Interface>,
    header_len: usize,
) -> Step {
    match block {
        PcapBlockOwned::LegacyHeader(h) => {
            // The upper bits of the link-type field may carry FCS information (pcap draft 4).
            let link = LinkType((h.network.0 as u32 & 0xffff) as u16);
            let tsresol = if h.is_nanosecond_precision() { 9 } else { 6 };
            interfaces.clear();
            interfaces.extend(Interface::new(link, h.snaplen, tsresol, 0));
            Step::Skip
        }
        PcapBlockOwned::Legacy(b) => {
            let nanos = interfaces.first().is_some_and(|i| i.tsresol == 9);
            let frac = if nanos {
                u64::from(b.ts_usec) / 1000
            } else {
                u64::from(b.ts_usec)
            };
            let time = u64::from(b.ts_sec)
                .checked_mul(1_000_000)
                .and_then(|t| t.checked_add(frac));
            Step::Record {
                start: header_len,
                len: b.data.len(),
                interface: 0,
                time,
                orig_len: b.origlen,
            }
        }
        PcapBlockOwned::NG(_) => Step::Skip,
    }
}

fn ng_step(
    block: PcapBlockOwned<'_>,
    offset: u64,
    record: u64,
    interfaces: &mut Vec<Interface>,
    endian: &mut Endian,
    options: &Options,
    skipped: &mut u64,
) -> Result<Step, CaptureError> {
    let PcapBlockOwned::NG(block) = block else {
        return Ok(Step::Skip);
    };
    match block {
        Block::SectionHeader(shb) => {
            *endian = if shb.big_endian() {
                Endian::Big
            } else {
                Endian::Little
            };
            interfaces.clear();
            Ok(Step::Skip)
        }
        Block::InterfaceDescription(idb) => {
            if interfaces.len() >= options.max_interfaces {
                return Err(CaptureError::TooManyInterfaces {
                    offset,
                    limit: options.max_interfaces,
                });
            }
            let mut tsresol = 6u8;
            let mut tsoffset = 0i64;
            let mut name = None;
            for opt in &idb.options {
                let value = opt.value.get(..usize::from(opt.len)).unwrap_or(&[]);
                match opt.code.0 {
                    9 => {
                        if let Some(&v) = value.first() {
                            tsresol = v;
                        }
                    }
                    14 => {
                        if let Ok(b) = <[u8; 8]>::try_from(value) {
                            tsoffset = match endian {
                                Endian::Big => i64::from_be_bytes(b),
                                Endian::Little => i64::from_le_bytes(b),
                            };
                        }
                    }
                    2 => {
                        let text = String::from_utf8_lossy(value);
                        name = Some(text.chars().take(256).collect::<String>());
                    }
                    _ => {}
                }
            }
            let link = LinkType((idb.linktype.0 as u32 & 0xffff) as u16);
            let mut iface = Interface::new(link, idb.snaplen, tsresol, tsoffset).ok_or(
                CaptureError::BadResolution {
                    offset,
                    value: tsresol,
                },
            )?;
            iface.name = name;
            interfaces.push(iface);
            Ok(Step::Skip)
        }
        Block::EnhancedPacket(epb) => {
            let iface =
                interfaces
                    .get(epb.if_id as usize)
                    .ok_or(CaptureError::UnknownInterface {
                        offset,
                        record,
                        interface: epb.if_id,
                        declared: interfaces.len(),
                    })?;
            let ts = u64::from(epb.ts_high) << 32 | u64::from(epb.ts_low);
            let len = (epb.caplen as usize).min(epb.data.len());
            Ok(Step::Record {
                start: 28,
                len,
                interface: epb.if_id,
                time: iface.micros(ts),
                orig_len: epb.origlen,
            })
        }
        Block::SimplePacket(spb) => {
            let iface = interfaces.first().ok_or(CaptureError::UnknownInterface {
                offset,
                record,
                interface: 0,
                declared: 0,
            })?;
            let mut len = (spb.origlen as usize).min(spb.data.len());
            if iface.snaplen > 0 {
                len = len.min(iface.snaplen as usize);
            }
            Ok(Step::Record {
                start: 12,
                len,
                interface: 0,
                time: None,
                orig_len: spb.origlen,
            })
        }
        _ => {
            *skipped += 1;
            Ok(Step::Skip)
        }
    }
}

impl<R: Read> Iterator for CaptureReader<R> {
    type Item = Result<Record, CaptureError>;

    fn next(&mut self) -> Option<Self::Item> {
        match self.next_record() {
            Ok(Some(r)) => Some(Ok(r.to_record())),
            Ok(None) => None,
            Err(e) => Some(Err(e)),
        }
    }
}

impl<R: Read> std::iter::FusedIterator for CaptureReader<R> {}
