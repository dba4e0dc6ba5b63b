//! Link layers: Ethernet II (DIX, IEEE 802.3 clause 3.2.6) with 802.1Q / 802.1ad tags
//! (IEEE 802.1Q 9.6, stacked as QinQ), Linux cooked capture v1 and v2 (LINKTYPE_LINUX_SLL
//! 113, LINKTYPE_LINUX_SLL2 276 in the tcpdump linktypes registry).
//!
//! Parsing borrows the frame, never allocates and never panics. The payload ends where the
//! captured bytes end: Ethernet padding stays in it (upper layers trim by their own
//! lengths), and a trailing FCS is assumed absent, as Wireshark assumes.

use crate::bytes::{Reader, Truncated};
use std::fmt;

/// A pcap/pcapng link type (LINKTYPE_* value, tcpdump linktypes registry).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct LinkType(pub u16);

impl LinkType {
    /// LINKTYPE_ETHERNET (1): IEEE 802.3 Ethernet.
    pub const ETHERNET: LinkType = LinkType(1);
    /// LINKTYPE_RAW (101): raw IPv4 or IPv6.
    pub const RAW: LinkType = LinkType(101);
    /// LINKTYPE_LINUX_SLL (113): Linux cooked capture v1.
    pub const LINUX_SLL: LinkType = LinkType(113);
    /// LINKTYPE_USER0 (147): private use; drivespec stores raw serial bytes here.
    pub const USER0: LinkType = LinkType(147);
    /// LINKTYPE_IPV4 (228): raw IPv4.
    pub const IPV4: LinkType = LinkType(228);
    /// LINKTYPE_RTAC_SERIAL (250): SEL RTAC serial line with a 12-byte event header.
    pub const RTAC_SERIAL: LinkType = LinkType(250);
    /// LINKTYPE_LINUX_SLL2 (276): Linux cooked capture v2.
    pub const LINUX_SLL2: LinkType = LinkType(276);
}

impl fmt::Display for LinkType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let name = match *self {
            LinkType::ETHERNET => "ETHERNET",
            LinkType::RAW => "RAW",
            LinkType::LINUX_SLL => "LINUX_SLL",
            LinkType::USER0 => "USER0",
            LinkType::IPV4 => "IPV4",
            LinkType::RTAC_SERIAL => "RTAC_SERIAL",
            LinkType::LINUX_SLL2 => "LINUX_SLL2",
            _ => return write!(f, "LINKTYPE {}", self.0),
        };
        write!(f, "{name} ({})", self.0)
    }
}

/// Ethertypes used here (IEEE Registration Authority EtherType list).
pub mod ethertype {
    /// IPv4.
    pub const IPV4: u16 = 0x0800;
    /// IEEE 802.1Q customer VLAN tag.
    pub const VLAN: u16 = 0x8100;
    /// IEEE 802.1ad service VLAN tag (QinQ outer tag).
    pub const QINQ: u16 = 0x88A8;
    /// Pre-standard QinQ outer tag.
    pub const QINQ_OLD: u16 = 0x9100;
    /// PROFINET (IEC 61158-6-10: RT, DCP, PTCP, alarms).
    pub const PROFINET: u16 = 0x8892;
    /// LLDP (IEEE 802.1AB).
    pub const LLDP: u16 = 0x88CC;
}

/// Most VLAN tags read in one frame.
pub const MAX_TAGS: usize = 4;

/// One 802.1Q / 802.1ad tag (IEEE 802.1Q 9.6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct VlanTag {
    /// Tag protocol identifier (0x8100, 0x88A8 or 0x9100).
    pub tpid: u16,
    /// Priority code point (3 bits).
    pub pcp: u8,
    /// Drop eligible indicator.
    pub dei: bool,
    /// VLAN identifier (12 bits).
    pub vid: u16,
}

/// The tags of a frame, outermost first (IEEE 802.1Q 9.6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Tags {
    tags: [VlanTag; MAX_TAGS],
    len: usize,
}

impl Tags {
    /// The tags, outermost first.
    pub fn as_slice(&self) -> &[VlanTag] {
        self.tags.get(..self.len).unwrap_or(&[])
    }

    /// The innermost VLAN id, if tagged.
    pub fn vid(&self) -> Option<u16> {
        self.as_slice().last().map(|t| t.vid)
    }

    fn push(&mut self, tag: VlanTag) -> bool {
        match self.tags.get_mut(self.len) {
            Some(slot) => {
                *slot = tag;
                self.len += 1;
                true
            }
            None => false,
        }
    }
}

/// Why a frame's link header cannot be read (our doc: module `link`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum LinkError {
    /// The frame ends inside the link header.
    #[error("link header: {0}")]
    Truncated(#[from] Truncated),
    /// More VLAN tags than [`MAX_TAGS`].
    #[error("more than {MAX_TAGS} VLAN tags")]
    TooManyTags,
    /// A link type this crate does not decode.
    #[error("link type {0} is not decoded")]
    Unsupported(LinkType),
}

/// A frame with its link header read (our doc: module `link`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LinkFrame<'a> {
    /// Destination MAC (Ethernet only).
    pub dst: Option<[u8; 6]>,
    /// Source MAC (Ethernet), or the link-layer address of a cooked capture when 6 bytes.
    pub src: Option<[u8; 6]>,
    /// VLAN tags, outermost first.
    pub tags: Tags,
    /// Ethertype of the payload; below 0x0600 it is an IEEE 802.3 length (LLC follows).
    pub ethertype: u16,
    /// Linux packet type (SLL: 0 to us, 1 broadcast, 2 multicast, 3 other host, 4 outgoing).
    pub packet_type: Option<u8>,
    /// Offset of the payload in the captured bytes.
    pub header_len: usize,
    /// Bytes after the link header (may include Ethernet padding).
    pub payload: &'a [u8],
}

fn is_tag(tpid: u16) -> bool {
    matches!(
        tpid,
        ethertype::VLAN | ethertype::QINQ | ethertype::QINQ_OLD
    )
}

/// Reads VLAN tags while the ethertype is a tag protocol identifier.
fn tags(r: &mut Reader<'_>, mut ethertype: u16) -> Result<(Tags, u16), LinkError> {
    let mut tags = Tags::default();
    while is_tag(ethertype) {
        let tci = r.be16()?;
        let tag = VlanTag {
            tpid: ethertype,
            pcp: (tci >> 13) as u8,
            dei: tci & 0x1000 != 0,
            vid: tci & 0x0fff,
        };
        if !tags.push(tag) {
            return Err(LinkError::TooManyTags);
        }
        ethertype = r.be16()?;
    }
    Ok((tags, ethertype))
}

/// Parses an Ethernet II frame (destination, source, tags, ethertype).
pub fn parse_ethernet(bytes: &[u8]) -> Result<LinkFrame<'_>, LinkError> {
    let mut r = Reader::new(bytes);
    let dst = r.array::<6>()?;
    let src = r.array::<6>()?;
    let first = r.be16()?;
    let (tags, ethertype) = tags(&mut r, first)?;
    Ok(LinkFrame {
        dst: Some(dst),
        src: Some(src),
        tags,
        ethertype,
        packet_type: None,
        header_len: r.pos(),
        payload: r.rest(),
    })
}

fn cooked_addr(len: usize, addr: [u8; 8]) -> Option<[u8; 6]> {
    if len == 6 {
        let mut a = [0u8; 6];
        a.copy_from_slice(addr.get(..6)?);
        Some(a)
    } else {
        None
    }
}

/// Parses a Linux cooked capture v1 header (16 bytes: packet type, ARPHRD type, address
/// length, 8 address bytes, protocol).
pub fn parse_sll(bytes: &[u8]) -> Result<LinkFrame<'_>, LinkError> {
    let mut r = Reader::new(bytes);
    let packet_type = r.be16()?;
    let _arphrd = r.be16()?;
    let addr_len = r.be16()?;
    let addr = r.array::<8>()?;
    let protocol = r.be16()?;
    let (tags, ethertype) = tags(&mut r, protocol)?;
    Ok(LinkFrame {
        dst: None,
        src: cooked_addr(usize::from(addr_len), addr),
        tags,
        ethertype,
        packet_type: u8::try_from(packet_type).ok(),
        header_len: r.pos(),
        payload: r.rest(),
    })
}

/// Parses a Linux cooked capture v2 header (20 bytes: protocol, reserved, interface index,
/// ARPHRD type, packet type, address length, 8 address bytes).
pub fn parse_sll2(bytes: &[u8]) -> Result<LinkFrame<'_>, LinkError> {
    let mut r = Reader::new(bytes);
    let protocol = r.be16()?;
    r.skip(2)?;
    let _ifindex = r.be32()?;
    let _arphrd = r.be16()?;
    let packet_type = r.u8()?;
    let addr_len = r.u8()?;
    let addr = r.array::<8>()?;
    let (tags, ethertype) = tags(&mut r, protocol)?;
    Ok(LinkFrame {
        dst: None,
        src: cooked_addr(usize::from(addr_len), addr),
        tags,
        ethertype,
        packet_type: Some(packet_type),
        header_len: r.pos(),
        payload: r.rest(),
    })
}

/// Parses the link header of a record of the given link type (Ethernet, SLL, SLL2, and raw
/// IPv4 as ethertype 0x0800 without a header).
pub fn parse_link(link: LinkType, bytes: &[u8]) -> Result<LinkFrame<'_>, LinkError> {
    match link {
        LinkType::ETHERNET => parse_ethernet(bytes),
        LinkType::LINUX_SLL => parse_sll(bytes),
        LinkType::LINUX_SLL2 => parse_sll2(bytes),
        LinkType::RAW | LinkType::IPV4 if bytes.first().is_some_and(|b| b >> 4 == 4) => {
            Ok(LinkFrame {
                dst: None,
                src: None,
                tags: Tags::default(),
                ethertype: ethertype::IPV4,
                packet_type: None,
                header_len: 0,
                payload: bytes,
            })
        }
        other => Err(LinkError::Unsupported(other)),
    }
}
