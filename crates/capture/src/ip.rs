//! IPv4 (RFC 791 3.1) and UDP (RFC 768), as far as PNIO-CM needs: the UDP payload of an
//! unfragmented datagram, trimmed to the IPv4 total length and the UDP length (so Ethernet
//! padding never reaches DCE/RPC). Fragmented datagrams are reported, not reassembled.
//! Checksums are not verified. Never panics, never allocates.

use crate::bytes::{Reader, Truncated};

/// IP protocol number of UDP (IANA).
pub const PROTO_UDP: u8 = 17;

/// Why bytes are not an unfragmented IPv4/UDP datagram (our doc: module `ip`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum IpError {
    /// The bytes end inside a header.
    #[error("IPv4/UDP: {0}")]
    Truncated(#[from] Truncated),
    /// Version is not 4.
    #[error("IP version {0}, expected 4")]
    Version(u8),
    /// Header length below 20 bytes or beyond the total length.
    #[error("IPv4 header length {ihl} bytes with total length {total}")]
    HeaderLength {
        /// Header length in bytes.
        ihl: usize,
        /// Total length field.
        total: usize,
    },
    /// The total length says more than was captured.
    #[error("IPv4 total length {total}, only {captured} byte(s) captured")]
    Short {
        /// Total length field.
        total: usize,
        /// Bytes available from the IPv4 header on.
        captured: usize,
    },
    /// Not UDP.
    #[error("IP protocol {0} is not UDP")]
    NotUdp(u8),
    /// A fragment (RFC 791: MF set or a non-zero fragment offset).
    #[error("IPv4 fragment (offset {offset} bytes, more fragments {more}); not reassembled")]
    Fragment {
        /// Fragment offset in bytes.
        offset: u32,
        /// More-fragments flag.
        more: bool,
    },
    /// The UDP length is below 8 or beyond the IPv4 payload.
    #[error("UDP length {udp} with {available} byte(s) of IPv4 payload")]
    UdpLength {
        /// UDP length field.
        udp: usize,
        /// IPv4 payload bytes.
        available: usize,
    },
}

/// A UDP datagram over IPv4 (RFC 768, RFC 791).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UdpDatagram<'a> {
    /// IPv4 source address.
    pub src: [u8; 4],
    /// IPv4 destination address.
    pub dst: [u8; 4],
    /// UDP source port.
    pub src_port: u16,
    /// UDP destination port.
    pub dst_port: u16,
    /// The UDP payload.
    pub payload: &'a [u8],
}

/// Parses an IPv4 packet carrying one unfragmented UDP datagram.
pub fn parse_ipv4_udp(bytes: &[u8]) -> Result<UdpDatagram<'_>, IpError> {
    let mut r = Reader::new(bytes);
    let vihl = r.u8()?;
    if vihl >> 4 != 4 {
        return Err(IpError::Version(vihl >> 4));
    }
    let ihl = usize::from(vihl & 0x0f) * 4;
    let _tos = r.u8()?;
    let total = usize::from(r.be16()?);
    let _id = r.be16()?;
    let frag = r.be16()?;
    let _ttl = r.u8()?;
    let proto = r.u8()?;
    let _checksum = r.be16()?;
    let src = r.array::<4>()?;
    let dst = r.array::<4>()?;
    if ihl < 20 || ihl > total {
        return Err(IpError::HeaderLength { ihl, total });
    }
    if total > bytes.len() {
        return Err(IpError::Short {
            total,
            captured: bytes.len(),
        });
    }
    let more = frag & 0x2000 != 0;
    let offset = u32::from(frag & 0x1fff) * 8;
    if more || offset != 0 {
        return Err(IpError::Fragment { offset, more });
    }
    if proto != PROTO_UDP {
        return Err(IpError::NotUdp(proto));
    }
    let body = bytes.get(ihl..total).unwrap_or(&[]);
    let mut u = Reader::new(body);
    let src_port = u.be16()?;
    let dst_port = u.be16()?;
    let udp = usize::from(u.be16()?);
    let _checksum = u.be16()?;
    if udp < 8 || udp > body.len() {
        return Err(IpError::UdpLength {
            udp,
            available: body.len(),
        });
    }
    Ok(UdpDatagram {
        src,
        dst,
        src_port,
        dst_port,
        payload: body.get(8..udp).unwrap_or(&[]),
    })
}
