//! A small pcap / pcapng writer for generating test captures: Ethernet or serial records with
//! timestamps, one or more pcapng interfaces with their own resolution and offset, either
//! byte order. Its output reads back through [`crate::pcap::CaptureReader`].
//!
//! Layouts: pcap file header and record header (pcap draft 4, 5); pcapng Section Header,
//! Interface Description, Enhanced and Simple Packet Blocks (pcapng draft 4.1–4.4). Errors are
//! the writer's I/O errors, or `InvalidInput` for an unknown interface, a time that does not
//! fit the format, or data longer than `u32::MAX` bytes.

use crate::bytes::Endian;
use crate::link::LinkType;
use std::io::{self, Write};

fn invalid(what: &'static str) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, what)
}

fn len32(data: &[u8]) -> io::Result<u32> {
    u32::try_from(data.len()).map_err(|_| invalid("record longer than u32::MAX bytes"))
}

struct Out<W> {
    w: W,
    endian: Endian,
}

impl<W: Write> Out<W> {
    fn u16(&mut self, v: u16) -> io::Result<()> {
        match self.endian {
            Endian::Big => self.w.write_all(&v.to_be_bytes()),
            Endian::Little => self.w.write_all(&v.to_le_bytes()),
        }
    }

    fn u32(&mut self, v: u32) -> io::Result<()> {
        match self.endian {
            Endian::Big => self.w.write_all(&v.to_be_bytes()),
            Endian::Little => self.w.write_all(&v.to_le_bytes()),
        }
    }

    fn u64(&mut self, v: u64) -> io::Result<()> {
        match self.endian {
            Endian::Big => self.w.write_all(&v.to_be_bytes()),
            Endian::Little => self.w.write_all(&v.to_le_bytes()),
        }
    }

    fn bytes(&mut self, b: &[u8]) -> io::Result<()> {
        self.w.write_all(b)
    }

    fn padded(&mut self, b: &[u8]) -> io::Result<()> {
        self.w.write_all(b)?;
        self.w
            .write_all([0u8; 3].get(..pad4(b.len())).unwrap_or(&[]))
    }
}

fn pad4(n: usize) -> usize {
    (4 - n % 4) % 4
}

/// Writes classic pcap (pcap draft 4, 5).
pub struct PcapWriter<W: Write> {
    out: Out<W>,
    nanos: bool,
}

impl<W: Write> PcapWriter<W> {
    /// A little-endian, microsecond pcap of `link` records.
    pub fn new(w: W, link: LinkType, snaplen: u32) -> io::Result<PcapWriter<W>> {
        PcapWriter::with_format(w, link, snaplen, Endian::Little, false)
    }

    /// A pcap in the given byte order, with nanosecond timestamps if `nanos`.
    pub fn with_format(
        w: W,
        link: LinkType,
        snaplen: u32,
        endian: Endian,
        nanos: bool,
    ) -> io::Result<PcapWriter<W>> {
        let mut out = Out { w, endian };
        out.u32(if nanos { 0xa1b2_3c4d } else { 0xa1b2_c3d4 })?;
        out.u16(2)?;
        out.u16(4)?;
        out.u32(0)?;
        out.u32(0)?;
        out.u32(snaplen)?;
        out.u32(u32::from(link.0))?;
        Ok(PcapWriter { out, nanos })
    }

    /// Writes a whole packet at `time` (microseconds since 1970).
    pub fn write_packet(&mut self, time: u64, data: &[u8]) -> io::Result<()> {
        self.write_record(time, len32(data)?, data)
    }

    /// Writes a record whose original length may exceed the captured bytes.
    pub fn write_record(&mut self, time: u64, orig_len: u32, data: &[u8]) -> io::Result<()> {
        let secs = u32::try_from(time / 1_000_000).map_err(|_| invalid("time beyond 2106"))?;
        let frac = (time % 1_000_000) as u32;
        self.out.u32(secs)?;
        self.out.u32(if self.nanos { frac * 1000 } else { frac })?;
        self.out.u32(len32(data)?)?;
        self.out.u32(orig_len)?;
        self.out.bytes(data)
    }

    /// Flushes and returns the writer.
    pub fn into_inner(mut self) -> io::Result<W> {
        self.out.w.flush()?;
        Ok(self.out.w)
    }
}

/// An interface to declare in a pcapng section (pcapng draft 4.2).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InterfaceSpec {
    /// Link type.
    pub link_type: LinkType,
    /// Snapshot length (0: none).
    pub snaplen: u32,
    /// `if_tsresol` (6 = µs, 9 = ns, 0x80 | n = 2^-n s).
    pub tsresol: u8,
    /// `if_tsoffset` in seconds.
    pub tsoffset: i64,
    /// `if_name`.
    pub name: Option<String>,
}

impl InterfaceSpec {
    /// An interface with microsecond timestamps and no offset or name.
    pub fn new(link_type: LinkType) -> InterfaceSpec {
        InterfaceSpec {
            link_type,
            snaplen: 0,
            tsresol: 6,
            tsoffset: 0,
            name: None,
        }
    }
}

/// Writes pcapng (pcapng draft 4).
pub struct PcapNgWriter<W: Write> {
    out: Out<W>,
    interfaces: Vec<InterfaceSpec>,
}

impl<W: Write> PcapNgWriter<W> {
    /// A little-endian pcapng; writes the first Section Header Block.
    pub fn new(w: W) -> io::Result<PcapNgWriter<W>> {
        PcapNgWriter::with_endian(w, Endian::Little)
    }

    /// A pcapng in the given byte order.
    pub fn with_endian(w: W, endian: Endian) -> io::Result<PcapNgWriter<W>> {
        let mut writer = PcapNgWriter {
            out: Out { w, endian },
            interfaces: Vec::new(),
        };
        writer.new_section()?;
        Ok(writer)
    }

    /// Starts a new section (a Section Header Block); interfaces are declared anew.
    pub fn new_section(&mut self) -> io::Result<()> {
        self.interfaces.clear();
        let o = &mut self.out;
        o.u32(0x0A0D_0D0A)?;
        o.u32(28)?;
        o.u32(0x1A2B_3C4D)?;
        o.u16(1)?;
        o.u16(0)?;
        o.u64(u64::MAX)?;
        o.u32(28)
    }

    /// Declares an interface with microsecond timestamps; returns its id.
    pub fn add_interface(&mut self, link_type: LinkType) -> io::Result<u32> {
        self.add_interface_with(InterfaceSpec::new(link_type))
    }

    /// Declares an interface; returns its id.
    pub fn add_interface_with(&mut self, spec: InterfaceSpec) -> io::Result<u32> {
        let id =
            u32::try_from(self.interfaces.len()).map_err(|_| invalid("too many interfaces"))?;
        let mut options: Vec<(u16, Vec<u8>)> = Vec::new();
        if let Some(name) = &spec.name {
            options.push((2, name.as_bytes().to_vec()));
        }
        if spec.tsresol != 6 {
            options.push((9, vec![spec.tsresol]));
        }
        if spec.tsoffset != 0 {
            let b = match self.out.endian {
                Endian::Big => spec.tsoffset.to_be_bytes(),
                Endian::Little => spec.tsoffset.to_le_bytes(),
            };
            options.push((14, b.to_vec()));
        }
        let mut opt_len = 0usize;
        for (_, v) in &options {
            opt_len += 4 + v.len() + pad4(v.len());
        }
        if !options.is_empty() {
            opt_len += 4;
        }
        let total = u32::try_from(20 + opt_len).map_err(|_| invalid("options too long"))?;
        let o = &mut self.out;
        o.u32(1)?;
        o.u32(total)?;
        o.u16(spec.link_type.0)?;
        o.u16(0)?;
        o.u32(spec.snaplen)?;
        for (code, v) in &options {
            o.u16(*code)?;
            o.u16(u16::try_from(v.len()).map_err(|_| invalid("option too long"))?)?;
            o.padded(v)?;
        }
        if !options.is_empty() {
            o.u32(0)?;
        }
        o.u32(total)?;
        self.interfaces.push(spec);
        Ok(id)
    }

    /// Writes a whole packet on interface `if_id` at `time` (microseconds since 1970),
    /// converted to the interface's resolution and offset.
    pub fn write_packet(&mut self, if_id: u32, time: u64, data: &[u8]) -> io::Result<()> {
        let spec = self
            .interfaces
            .get(if_id as usize)
            .ok_or(invalid("unknown interface"))?;
        let exp = u32::from(spec.tsresol & 0x7f);
        let units: u128 = if spec.tsresol & 0x80 == 0 {
            10u128.checked_pow(exp).ok_or(invalid("bad tsresol"))?
        } else {
            1u128.checked_shl(exp).ok_or(invalid("bad tsresol"))?
        };
        let rel = i128::from(time) - i128::from(spec.tsoffset) * 1_000_000;
        let rel = u128::try_from(rel).map_err(|_| invalid("time before the interface offset"))?;
        let ts = rel
            .checked_mul(units)
            .map(|v| v / 1_000_000)
            .and_then(|v| u64::try_from(v).ok())
            .ok_or(invalid("time does not fit 64 bits"))?;
        self.write_epb(if_id, ts, len32(data)?, data)
    }

    /// Writes an Enhanced Packet Block with a raw timestamp in interface units.
    pub fn write_epb(&mut self, if_id: u32, ts: u64, orig_len: u32, data: &[u8]) -> io::Result<()> {
        if self.interfaces.get(if_id as usize).is_none() {
            return Err(invalid("unknown interface"));
        }
        let caplen = len32(data)?;
        let total = u32::try_from(32 + data.len() + pad4(data.len()))
            .map_err(|_| invalid("record too long"))?;
        let o = &mut self.out;
        o.u32(6)?;
        o.u32(total)?;
        o.u32(if_id)?;
        o.u32((ts >> 32) as u32)?;
        o.u32(ts as u32)?;
        o.u32(caplen)?;
        o.u32(orig_len)?;
        o.padded(data)?;
        o.u32(total)
    }

    /// Writes a Simple Packet Block (interface 0, no timestamp).
    pub fn write_simple_packet(&mut self, data: &[u8]) -> io::Result<()> {
        if self.interfaces.is_empty() {
            return Err(invalid("no interface declared"));
        }
        let total = u32::try_from(16 + data.len() + pad4(data.len()))
            .map_err(|_| invalid("record too long"))?;
        let o = &mut self.out;
        o.u32(3)?;
        o.u32(total)?;
        o.u32(len32(data)?)?;
        o.padded(data)?;
        o.u32(total)
    }

    /// Writes a block of any type with the given body (padded), e.g. to test skipping.
    pub fn write_block(&mut self, block_type: u32, body: &[u8]) -> io::Result<()> {
        let total = u32::try_from(12 + body.len() + pad4(body.len()))
            .map_err(|_| invalid("block too long"))?;
        let o = &mut self.out;
        o.u32(block_type)?;
        o.u32(total)?;
        o.padded(body)?;
        o.u32(total)
    }

    /// Flushes and returns the writer.
    pub fn into_inner(mut self) -> io::Result<W> {
        self.out.w.flush()?;
        Ok(self.out.w)
    }
}
