//! ARP replies (RFC 826) so that stations that resolve addresses the usual way (a PLC, a
//! tool on kernel UDP sockets) reach a station whose IP lives only here; decoding is
//! `drivespec_capture::arp`.

use crate::buf::Buf;
use crate::eth::{self, Mac};
use crate::udp::Ipv4;
use drivespec_capture::arp::{parse_arp, Arp, ETHERTYPE, REPLY, REQUEST};

/// An ARP packet as a whole Ethernet frame.
pub fn frame(dst: Mac, arp: &Arp) -> Vec<u8> {
    let mut b = Buf::default();
    b.be16(1)
        .be16(0x0800)
        .u8(6)
        .u8(4)
        .be16(arp.operation)
        .bytes(&arp.sender_mac)
        .bytes(&arp.sender_ip)
        .bytes(&arp.target_mac)
        .bytes(&arp.target_ip);
    eth::frame(dst, arp.sender_mac, None, ETHERTYPE, &b.0)
}

/// The reply of a station at (`mac`, `ip`) to an ARP payload, if it asks for `ip`.
pub fn answer(payload: &[u8], mac: Mac, ip: Ipv4) -> Option<Vec<u8>> {
    let req = parse_arp(payload).ok()?;
    if req.operation != REQUEST || req.target_ip != ip || ip == [0; 4] {
        return None;
    }
    Some(frame(
        req.sender_mac,
        &Arp {
            operation: REPLY,
            sender_mac: mac,
            sender_ip: ip,
            target_mac: req.sender_mac,
            target_ip: req.sender_ip,
        },
    ))
}
