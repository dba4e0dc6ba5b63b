//! DCE/RPC connectionless PDUs (C706 "DCE 1.1: Remote Procedure Call", chapter 12.5: the
//! 80-byte header), as PNIO-CM uses them over UDP port 34964 (IEC 61158-6-10 "RPC").
//!
//! Integers in the header and the UUIDs' first three fields follow the header's data
//! representation (`drep`, C706 14.1: integer representation nibble 0 = big-endian,
//! 1 = little-endian). [`Uuid`] holds the canonical (big-endian) form.
//!
//! Fragmented calls (C706 12.5.3.3: `flags1` FRAG/LASTFRAG, `fragnum`) are put back together
//! by [`Reassembler`] within limits on the message size, the fragments per message and the
//! calls pending at once (the oldest is dropped and counted). Parsing never panics.

use crate::bytes::{Endian, Reader, Truncated};
use drivespec_spec::hex::to_hex_lower;
use std::collections::{BTreeMap, VecDeque};
use std::fmt;

/// The UDP port of the PNIO-CM RPC endpoint mapper and calls (IEC 61158-6-10: 0x8894).
pub const PNIO_PORT: u16 = 34964;

/// Length of the connectionless header (C706 12.5.1).
pub const HEADER_LEN: usize = 80;

/// A UUID in canonical byte order (C706 appendix A).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
pub struct Uuid(pub [u8; 16]);

impl Uuid {
    /// PNIO device interface (IEC 61158-6-10: DEA00001-6C97-11D1-8271-00A02442DF7D).
    pub const PNIO_DEVICE: Uuid = Uuid([
        0xDE, 0xA0, 0x00, 0x01, 0x6C, 0x97, 0x11, 0xD1, 0x82, 0x71, 0x00, 0xA0, 0x24, 0x42, 0xDF,
        0x7D,
    ]);
    /// PNIO controller interface (DEA00002-…).
    pub const PNIO_CONTROLLER: Uuid = Uuid([
        0xDE, 0xA0, 0x00, 0x02, 0x6C, 0x97, 0x11, 0xD1, 0x82, 0x71, 0x00, 0xA0, 0x24, 0x42, 0xDF,
        0x7D,
    ]);
    /// PNIO supervisor interface (DEA00003-…).
    pub const PNIO_SUPERVISOR: Uuid = Uuid([
        0xDE, 0xA0, 0x00, 0x03, 0x6C, 0x97, 0x11, 0xD1, 0x82, 0x71, 0x00, 0xA0, 0x24, 0x42, 0xDF,
        0x7D,
    ]);
    /// PNIO parameter server interface (DEA00004-…).
    pub const PNIO_PARAMETER_SERVER: Uuid = Uuid([
        0xDE, 0xA0, 0x00, 0x04, 0x6C, 0x97, 0x11, 0xD1, 0x82, 0x71, 0x00, 0xA0, 0x24, 0x42, 0xDF,
        0x7D,
    ]);

    /// Reads a UUID whose first three fields are in `order`.
    pub(crate) fn read(r: &mut Reader<'_>, order: Endian) -> Result<Uuid, Truncated> {
        let mut b = r.array::<16>()?;
        if order == Endian::Little {
            if let Some(f) = b.get_mut(0..4) {
                f.reverse();
            }
            if let Some(f) = b.get_mut(4..6) {
                f.reverse();
            }
            if let Some(f) = b.get_mut(6..8) {
                f.reverse();
            }
        }
        Ok(Uuid(b))
    }

    /// Whether this is one of the four PNIO interface UUIDs.
    pub fn is_pnio_interface(&self) -> bool {
        [
            Uuid::PNIO_DEVICE,
            Uuid::PNIO_CONTROLLER,
            Uuid::PNIO_SUPERVISOR,
            Uuid::PNIO_PARAMETER_SERVER,
        ]
        .contains(self)
    }
}

impl fmt::Display for Uuid {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let h = to_hex_lower(&self.0);
        let part = |a: usize, b: usize| h.get(a..b).unwrap_or("");
        write!(
            f,
            "{}-{}-{}-{}-{}",
            part(0, 8),
            part(8, 12),
            part(12, 16),
            part(16, 20),
            part(20, 32)
        )
    }
}

/// A connectionless PDU type (C706 12.5.2.1), open: unknown values keep their number.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct PacketType(pub u8);

impl PacketType {
    /// request
    pub const REQUEST: PacketType = PacketType(0);
    /// ping
    pub const PING: PacketType = PacketType(1);
    /// response
    pub const RESPONSE: PacketType = PacketType(2);
    /// fault
    pub const FAULT: PacketType = PacketType(3);
    /// working
    pub const WORKING: PacketType = PacketType(4);
    /// nocall
    pub const NOCALL: PacketType = PacketType(5);
    /// reject
    pub const REJECT: PacketType = PacketType(6);
    /// ack
    pub const ACK: PacketType = PacketType(7);
    /// cl_cancel
    pub const CANCEL: PacketType = PacketType(8);
    /// fack
    pub const FACK: PacketType = PacketType(9);
    /// cancel_ack
    pub const CANCEL_ACK: PacketType = PacketType(10);
}

impl fmt::Display for PacketType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let name = match self.0 {
            0 => "request",
            1 => "ping",
            2 => "response",
            3 => "fault",
            4 => "working",
            5 => "nocall",
            6 => "reject",
            7 => "ack",
            8 => "cl_cancel",
            9 => "fack",
            10 => "cancel_ack",
            n => return write!(f, "ptype {n}"),
        };
        f.write_str(name)
    }
}

/// `flags1` bits (C706 12.5.2.2).
pub mod flags1 {
    /// Last fragment of a fragmented call.
    pub const LAST_FRAG: u8 = 0x02;
    /// The PDU is a fragment.
    pub const FRAG: u8 = 0x04;
    /// No FACK wanted.
    pub const NO_FACK: u8 = 0x08;
    /// Maybe semantics.
    pub const MAYBE: u8 = 0x10;
    /// Idempotent.
    pub const IDEMPOTENT: u8 = 0x20;
    /// Broadcast.
    pub const BROADCAST: u8 = 0x40;
}

/// The data representation label (C706 14.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct DataRep {
    /// Integer byte order.
    pub integer: Endian,
    /// Character representation nibble (0 ASCII, 1 EBCDIC).
    pub character: u8,
    /// Floating-point representation (0 IEEE).
    pub float: u8,
}

/// The connectionless header (C706 12.5.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Header {
    /// RPC protocol version (4).
    pub version: u8,
    /// PDU type.
    pub ptype: PacketType,
    /// flags1.
    pub flags1: u8,
    /// flags2.
    pub flags2: u8,
    /// Data representation.
    pub drep: DataRep,
    /// Serial number (serial_hi << 8 | serial_lo).
    pub serial: u16,
    /// Object UUID.
    pub object: Uuid,
    /// Interface UUID.
    pub interface: Uuid,
    /// Activity UUID.
    pub activity: Uuid,
    /// Server boot time.
    pub server_boot: u32,
    /// Interface version.
    pub interface_version: u32,
    /// Sequence number of the call.
    pub sequence: u32,
    /// Operation number.
    pub opnum: u16,
    /// Interface hint.
    pub interface_hint: u16,
    /// Activity hint.
    pub activity_hint: u16,
    /// Body length.
    pub body_len: u16,
    /// Fragment number.
    pub fragment: u16,
    /// Authentication protocol (0 none).
    pub auth_proto: u8,
}

impl Header {
    /// Whether the PDU is a fragment of a larger body.
    pub fn is_fragment(&self) -> bool {
        self.flags1 & flags1::FRAG != 0
    }

    /// Whether this is the last fragment (or not fragmented).
    pub fn is_last_fragment(&self) -> bool {
        !self.is_fragment() || self.flags1 & flags1::LAST_FRAG != 0
    }
}

/// Why bytes are not a connectionless DCE/RPC PDU (our doc: module `dcerpc`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum RpcError {
    /// The PDU ends inside the header.
    #[error("DCE/RPC header: {0}")]
    Truncated(#[from] Truncated),
    /// Not version 4 (connectionless).
    #[error("DCE/RPC version {0}, expected 4 (connectionless)")]
    Version(u8),
    /// The header's body length exceeds the bytes captured.
    #[error("DCE/RPC body length {declared}, {captured} byte(s) captured")]
    BodyLength {
        /// Body length in the header.
        declared: u16,
        /// Bytes after the header.
        captured: usize,
    },
    /// A reassembled call would exceed the size limit; its fragments were dropped.
    #[error(
        "call {sequence} of activity {activity}: reassembled body of {size}+ bytes exceeds {limit}"
    )]
    TooLarge {
        /// Activity UUID.
        activity: Uuid,
        /// Sequence number.
        sequence: u32,
        /// Bytes collected so far with this fragment.
        size: usize,
        /// The limit.
        limit: usize,
    },
    /// A fragment number beyond the limit.
    #[error(
        "call {sequence} of activity {activity}: fragment {fragment} beyond the limit of {limit}"
    )]
    TooManyFragments {
        /// Activity UUID.
        activity: Uuid,
        /// Sequence number.
        sequence: u32,
        /// Fragment number.
        fragment: u16,
        /// The limit.
        limit: u16,
    },
}

/// A PDU: header and body (C706 12.5).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Packet<'a> {
    /// The header.
    pub header: Header,
    /// The body (`body_len` bytes; trailing bytes such as padding are dropped).
    pub body: &'a [u8],
}

/// Parses a connectionless PDU from a UDP payload.
pub fn parse(bytes: &[u8]) -> Result<Packet<'_>, RpcError> {
    let mut r = Reader::new(bytes);
    let version = r.u8()?;
    if version != 4 {
        return Err(RpcError::Version(version));
    }
    let ptype = PacketType(r.u8()?);
    let flags1 = r.u8()?;
    let flags2 = r.u8()?;
    let [d0, d1, _d2] = r.array::<3>()?;
    let order = if d0 >> 4 == 0 {
        Endian::Big
    } else {
        Endian::Little
    };
    let drep = DataRep {
        integer: order,
        character: d0 & 0x0f,
        float: d1,
    };
    let serial_hi = r.u8()?;
    let object = Uuid::read(&mut r, order)?;
    let interface = Uuid::read(&mut r, order)?;
    let activity = Uuid::read(&mut r, order)?;
    let server_boot = r.u32(order)?;
    let interface_version = r.u32(order)?;
    let sequence = r.u32(order)?;
    let opnum = r.u16(order)?;
    let interface_hint = r.u16(order)?;
    let activity_hint = r.u16(order)?;
    let body_len = r.u16(order)?;
    let fragment = r.u16(order)?;
    let auth_proto = r.u8()?;
    let serial_lo = r.u8()?;
    let rest = r.rest();
    let body = rest
        .get(..usize::from(body_len))
        .ok_or(RpcError::BodyLength {
            declared: body_len,
            captured: rest.len(),
        })?;
    Ok(Packet {
        header: Header {
            version,
            ptype,
            flags1,
            flags2,
            drep,
            serial: u16::from(serial_hi) << 8 | u16::from(serial_lo),
            object,
            interface,
            activity,
            server_boot,
            interface_version,
            sequence,
            opnum,
            interface_hint,
            activity_hint,
            body_len,
            fragment,
            auth_proto,
        },
        body,
    })
}

/// A whole call body, reassembled if it was fragmented (C706 12.5.3.3).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Message {
    /// Header of fragment 0 (or of the PDU when not fragmented).
    pub header: Header,
    /// The body.
    pub body: Vec<u8>,
    /// Number of PDUs it came in.
    pub fragments: u16,
}

/// Limits of a [`Reassembler`] (our doc: module `dcerpc`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReassemblyLimits {
    /// Largest reassembled body.
    pub max_message: usize,
    /// Highest fragment number + 1.
    pub max_fragments: u16,
    /// Calls being reassembled at once; the oldest is dropped beyond this.
    pub max_pending: usize,
}

impl Default for ReassemblyLimits {
    fn default() -> ReassemblyLimits {
        ReassemblyLimits {
            max_message: 1 << 20,
            max_fragments: 1024,
            max_pending: 16,
        }
    }
}

#[derive(Debug)]
struct Partial {
    key: (Uuid, u32, PacketType),
    header: Header,
    fragments: BTreeMap<u16, Vec<u8>>,
    size: usize,
    last: Option<u16>,
}

/// Puts fragmented calls back together, with bounded memory (our doc: module `dcerpc`).
#[derive(Debug, Default)]
pub struct Reassembler {
    limits: ReassemblyLimits,
    pending: VecDeque<Partial>,
    dropped: u64,
}

impl Reassembler {
    /// A reassembler with the given limits.
    pub fn new(limits: ReassemblyLimits) -> Reassembler {
        Reassembler {
            limits,
            pending: VecDeque::new(),
            dropped: 0,
        }
    }

    /// Unfinished calls dropped because too many were pending.
    pub fn dropped(&self) -> u64 {
        self.dropped
    }

    /// Calls waiting for fragments.
    pub fn pending(&self) -> usize {
        self.pending.len()
    }

    /// Adds a PDU; returns the message it completes, if any. Repeated fragments are ignored.
    pub fn push(&mut self, packet: &Packet<'_>) -> Result<Option<Message>, RpcError> {
        let h = packet.header;
        if !h.is_fragment() {
            return Ok(Some(Message {
                header: h,
                body: packet.body.to_vec(),
                fragments: 1,
            }));
        }
        let key = (h.activity, h.sequence, h.ptype);
        if h.fragment >= self.limits.max_fragments {
            self.pending.retain(|p| p.key != key);
            return Err(RpcError::TooManyFragments {
                activity: h.activity,
                sequence: h.sequence,
                fragment: h.fragment,
                limit: self.limits.max_fragments,
            });
        }
        let index = match self.pending.iter().position(|p| p.key == key) {
            Some(i) => i,
            None => {
                if self.pending.len() >= self.limits.max_pending.max(1) {
                    self.pending.pop_front();
                    self.dropped += 1;
                }
                self.pending.push_back(Partial {
                    key,
                    header: h,
                    fragments: BTreeMap::new(),
                    size: 0,
                    last: None,
                });
                self.pending.len() - 1
            }
        };
        let Some(partial) = self.pending.get_mut(index) else {
            return Ok(None);
        };
        if partial.fragments.contains_key(&h.fragment) {
            return Ok(None);
        }
        let size = partial.size + packet.body.len();
        if size > self.limits.max_message {
            self.pending.remove(index);
            return Err(RpcError::TooLarge {
                activity: h.activity,
                sequence: h.sequence,
                size,
                limit: self.limits.max_message,
            });
        }
        partial.size = size;
        partial.fragments.insert(h.fragment, packet.body.to_vec());
        if h.fragment == 0 {
            partial.header = h;
        }
        if h.flags1 & flags1::LAST_FRAG != 0 {
            partial.last = Some(h.fragment);
        }
        // Keys are unique and sorted: `len == last + 1` with `last` the highest key means
        // exactly the fragments 0..=last are present.
        let complete = partial.last.is_some_and(|last| {
            partial.fragments.len() == usize::from(last) + 1
                && partial.fragments.keys().next_back() == Some(&last)
        });
        if !complete {
            return Ok(None);
        }
        let Some(done) = self.pending.remove(index) else {
            return Ok(None);
        };
        let fragments = u16::try_from(done.fragments.len()).unwrap_or(u16::MAX);
        let mut body = Vec::with_capacity(done.size);
        for (_, piece) in done.fragments {
            body.extend_from_slice(&piece);
        }
        Ok(Some(Message {
            header: done.header,
            body,
            fragments,
        }))
    }
}
