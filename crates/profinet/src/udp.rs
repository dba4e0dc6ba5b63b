//! IPv4 (RFC 791 3.1) with one UDP datagram (RFC 768), checksums computed (RFC 1071);
//! decoding is `drivespec_capture::ip`.

use crate::buf::{len16, Buf};
use drivespec_capture::ip::PROTO_UDP;

/// An IPv4 address.
pub type Ipv4 = [u8; 4];

/// Time to live of the datagrams sent (RFC 1700's recommended default).
pub const TTL: u8 = 64;

fn sum(data: &[u8], mut acc: u32) -> u32 {
    let mut chunks = data.chunks_exact(2);
    for c in &mut chunks {
        if let [a, b] = c {
            acc += u32::from(u16::from_be_bytes([*a, *b]));
        }
    }
    if let [last] = chunks.remainder() {
        acc += u32::from(u16::from_be_bytes([*last, 0]));
    }
    acc
}

fn fold(mut acc: u32) -> u16 {
    while acc > 0xFFFF {
        acc = (acc & 0xFFFF) + (acc >> 16);
    }
    !(acc as u16)
}

/// The UDP source and destination of a datagram.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Endpoints {
    /// Source address.
    pub src: Ipv4,
    /// Source port.
    pub src_port: u16,
    /// Destination address.
    pub dst: Ipv4,
    /// Destination port.
    pub dst_port: u16,
}

/// An IPv4 packet (no options, DF set) carrying one UDP datagram with `payload`.
pub fn ipv4_udp(ep: Endpoints, id: u16, payload: &[u8]) -> Vec<u8> {
    let udp_len = len16(payload.len() + 8);
    let total = len16(payload.len() + 28);
    let mut ip = Buf::default();
    ip.u8(0x45)
        .u8(0)
        .be16(total)
        .be16(id)
        .be16(0x4000)
        .u8(TTL)
        .u8(PROTO_UDP)
        .be16(0)
        .bytes(&ep.src)
        .bytes(&ep.dst);
    let check = fold(sum(&ip.0, 0));
    ip.patch16(10, check);
    let mut udp = Buf::default();
    udp.be16(ep.src_port)
        .be16(ep.dst_port)
        .be16(udp_len)
        .be16(0)
        .bytes(payload);
    let mut pseudo = Buf::default();
    pseudo
        .bytes(&ep.src)
        .bytes(&ep.dst)
        .u8(0)
        .u8(PROTO_UDP)
        .be16(udp_len);
    let c = fold(sum(&udp.0, sum(&pseudo.0, 0)));
    udp.patch16(6, if c == 0 { 0xFFFF } else { c });
    ip.bytes(&udp.0);
    ip.0
}
