//! Ethernet II frames (IEEE 802.3 3.2.6) with an optional 802.1Q tag (IEEE 802.1Q 9.6),
//! padded to the 60-byte minimum without FCS; decoding is `drivespec_capture::link`.

use crate::buf::Buf;
pub use drivespec_capture::link::ethertype;

/// The EtherTypes a PROFINET station receives: RT and DCP, IPv4 (PNIO-CM over UDP), VLAN-tagged
/// frames and ARP (IEC 61158-6-10; RFC 826).
pub const STATION_ETHER_TYPES: [u16; 4] = [
    ethertype::PROFINET,
    ethertype::IPV4,
    ethertype::VLAN,
    drivespec_capture::arp::ETHERTYPE,
];

/// A MAC address.
pub type Mac = [u8; 6];

/// The shortest Ethernet frame without FCS (IEEE 802.3 4.4.2: 64 bytes with FCS).
pub const MIN_FRAME: usize = 60;

/// DCP Identify multicast address (IEC 61158-6-10 "DCP": 01-0E-CF-00-00-00).
pub const DCP_IDENTIFY_MAC: Mac = [0x01, 0x0E, 0xCF, 0x00, 0x00, 0x00];
/// DCP Hello multicast address (IEC 61158-6-10 "DCP": 01-0E-CF-00-00-01).
pub const DCP_HELLO_MAC: Mac = [0x01, 0x0E, 0xCF, 0x00, 0x00, 0x01];
/// The broadcast address.
pub const BROADCAST: Mac = [0xFF; 6];

/// Builds an Ethernet II frame; `tci` adds an 802.1Q tag (priority, DEI, VLAN id).
pub fn frame(dst: Mac, src: Mac, tci: Option<u16>, ethertype: u16, payload: &[u8]) -> Vec<u8> {
    let mut b = Buf::default();
    b.bytes(&dst).bytes(&src);
    if let Some(tci) = tci {
        b.be16(ethertype::VLAN).be16(tci);
    }
    b.be16(ethertype).bytes(payload);
    let mut out = b.0;
    if out.len() < MIN_FRAME {
        out.resize(MIN_FRAME, 0);
    }
    out
}

/// Whether a frame sent to `dst` is for a station with address `own` (unicast to it,
/// broadcast, or a multicast address it listens to).
pub fn accepts(own: Mac, dst: Mac, multicast: &[Mac]) -> bool {
    dst == own || dst == BROADCAST || multicast.contains(&dst)
}
