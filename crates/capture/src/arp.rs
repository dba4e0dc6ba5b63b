//! ARP for IPv4 over Ethernet (RFC 826): the 28-byte packet after Ethertype 0x0806.
//! Never panics, never allocates.

use crate::bytes::{Reader, Truncated};

/// Ethertype of ARP.
pub const ETHERTYPE: u16 = 0x0806;

/// Operation: request (RFC 826 `ares_op$REQUEST`).
pub const REQUEST: u16 = 1;
/// Operation: reply (RFC 826 `ares_op$REPLY`).
pub const REPLY: u16 = 2;

/// An ARP packet for IPv4 over Ethernet (RFC 826).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Arp {
    /// Operation (1 request, 2 reply).
    pub operation: u16,
    /// Sender hardware address.
    pub sender_mac: [u8; 6],
    /// Sender protocol address.
    pub sender_ip: [u8; 4],
    /// Target hardware address.
    pub target_mac: [u8; 6],
    /// Target protocol address.
    pub target_ip: [u8; 4],
}

/// Why bytes are not an Ethernet/IPv4 ARP packet (our doc: module `arp`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum ArpError {
    /// The packet ends inside a field.
    #[error("ARP: {0}")]
    Truncated(#[from] Truncated),
    /// Hardware or protocol type or address lengths other than Ethernet and IPv4.
    #[error("ARP for hardware type {htype} and protocol {ptype:#06x}, not Ethernet and IPv4")]
    NotEthernetIpv4 {
        /// Hardware type.
        htype: u16,
        /// Protocol type.
        ptype: u16,
    },
}

/// Parses the ARP packet of a frame's payload (after the Ethertype).
pub fn parse_arp(bytes: &[u8]) -> Result<Arp, ArpError> {
    let mut r = Reader::new(bytes);
    let htype = r.be16()?;
    let ptype = r.be16()?;
    let hlen = r.u8()?;
    let plen = r.u8()?;
    if htype != 1 || ptype != 0x0800 || hlen != 6 || plen != 4 {
        return Err(ArpError::NotEthernetIpv4 { htype, ptype });
    }
    Ok(Arp {
        operation: r.be16()?,
        sender_mac: r.array::<6>()?,
        sender_ip: r.array::<4>()?,
        target_mac: r.array::<6>()?,
        target_ip: r.array::<4>()?,
    })
}
