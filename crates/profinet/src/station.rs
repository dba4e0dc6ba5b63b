//! What both stations share: the addresses of a station, classifying a received frame into
//! DCP, PNIO-CM, cyclic or alarm traffic (through `drivespec_capture`'s decoders), and
//! building a PNIO-CM datagram as a whole Ethernet frame.

use crate::eth::{self, Mac};
use crate::rpc;
use crate::udp::{self, Endpoints, Ipv4};
use drivespec_capture::dcerpc::{self, Header, PacketType};
use drivespec_capture::ip::parse_ipv4_udp;
use drivespec_capture::link::{ethertype, parse_ethernet};
use drivespec_capture::pnio::{self, CmMessage};
use drivespec_capture::rt::{AlarmHeader, CyclicFrame, DcpHeader, FrameClass, RtFrame};
use std::time::Duration;

/// A time as µs for the drive model (saturating).
pub(crate) fn micros(t: Duration) -> u64 {
    u64::try_from(t.as_micros()).unwrap_or(u64::MAX)
}

/// One cycle of `send_clock_factor` × `reduction_ratio` × 31.25 µs (IEC 61158-6-10).
pub(crate) fn cycle(send_clock_factor: u16, reduction_ratio: u16) -> Duration {
    Duration::from_nanos(
        u64::from(send_clock_factor) * u64::from(reduction_ratio) * crate::rt::COUNT_NS,
    )
}

/// The CycleCounter of a frame sent at `t` (units of 31.25 µs, wrapping).
pub(crate) fn cycle_counter(t: Duration) -> u16 {
    let units = t.as_nanos() / u128::from(crate::rt::COUNT_NS);
    (units & 0xFFFF) as u16
}

/// A received frame, decoded as far as a station needs.
#[derive(Debug)]
pub(crate) enum Incoming<'a> {
    /// A DCP PDU.
    Dcp {
        /// Sender.
        src: Mac,
        /// Destination.
        dst: Mac,
        /// The FrameID class.
        class: FrameClass,
        /// The header and blocks.
        dcp: DcpHeader<'a>,
    },
    /// A cyclic frame.
    Cyclic {
        /// Sender.
        src: Mac,
        /// Destination.
        dst: Mac,
        /// The frame.
        frame: CyclicFrame<'a>,
    },
    /// An alarm frame.
    Alarm {
        /// Sender.
        src: Mac,
        /// Destination.
        dst: Mac,
        /// The RTA-PDU.
        alarm: AlarmHeader<'a>,
    },
    /// An ARP packet (the payload after the Ethertype).
    Arp(&'a [u8]),
    /// A DCE/RPC PDU that is no PNIO-CM call or answer: another interface (e.g. the endpoint
    /// mapper), or a ping, working, nocall, fault or reject.
    OtherRpc {
        /// Sender MAC.
        src: Mac,
        /// Destination MAC.
        dst: Mac,
        /// UDP endpoints as received.
        ep: Endpoints,
        /// The RPC header.
        header: Header,
        /// The body (a fault or reject carries its status).
        body: &'a [u8],
    },
    /// A PNIO-CM call or answer (not fragmented).
    Cm {
        /// Sender MAC.
        src: Mac,
        /// Destination MAC.
        dst: Mac,
        /// UDP endpoints as received.
        ep: Endpoints,
        /// The RPC header.
        header: Header,
        /// The decoded body.
        message: CmMessage,
    },
}

/// Decodes a received Ethernet frame; `None` for anything a station ignores (other
/// protocols, fragments of RPC calls, malformed frames).
pub(crate) fn classify(frame: &[u8]) -> Option<Incoming<'_>> {
    let link = parse_ethernet(frame).ok()?;
    let (src, dst) = (link.src?, link.dst?);
    match link.ethertype {
        ethertype::PROFINET => {
            let rt = RtFrame::parse(link.payload).ok()?;
            let class = rt.class();
            match class {
                FrameClass::Cyclic(_) => Some(Incoming::Cyclic {
                    src,
                    dst,
                    frame: rt.cyclic().ok()?,
                }),
                FrameClass::AlarmHigh | FrameClass::AlarmLow => Some(Incoming::Alarm {
                    src,
                    dst,
                    alarm: rt.alarm().ok()?,
                }),
                c if c.is_dcp() => Some(Incoming::Dcp {
                    src,
                    dst,
                    class,
                    dcp: rt.dcp().ok()?,
                }),
                _ => None,
            }
        }
        ethertype::IPV4 => {
            let udp = parse_ipv4_udp(link.payload).ok()?;
            let packet = dcerpc::parse(udp.payload).ok()?;
            let h = packet.header;
            if h.is_fragment() {
                return None;
            }
            let call = matches!(h.ptype, PacketType::REQUEST | PacketType::RESPONSE);
            if !h.interface.is_pnio_interface() || !call {
                return Some(Incoming::OtherRpc {
                    src,
                    ep: Endpoints {
                        src: udp.src,
                        src_port: udp.src_port,
                        dst: udp.dst,
                        dst_port: udp.dst_port,
                    },
                    dst,
                    header: h,
                    body: packet.body,
                });
            }
            let message = pnio::decode_body(h.ptype, h.opnum, h.drep.integer, packet.body).ok()?;
            Some(Incoming::Cm {
                src,
                dst,
                ep: Endpoints {
                    src: udp.src,
                    src_port: udp.src_port,
                    dst: udp.dst,
                    dst_port: udp.dst_port,
                },
                header: h,
                message,
            })
        }
        drivespec_capture::arp::ETHERTYPE => Some(Incoming::Arp(link.payload)),
        _ => None,
    }
}

/// A whole Ethernet frame carrying one RPC PDU over IPv4/UDP.
pub(crate) fn rpc_frame(
    src_mac: Mac,
    dst_mac: Mac,
    ep: Endpoints,
    ip_id: u16,
    header: &Header,
    body: &[u8],
) -> Vec<u8> {
    let pdu = rpc::encode(header, body);
    let ip = udp::ipv4_udp(ep, ip_id, &pdu);
    eth::frame(dst_mac, src_mac, None, ethertype::IPV4, &ip)
}

/// The reply endpoints of a datagram received on `ep`.
pub(crate) fn reply(ep: Endpoints) -> Endpoints {
    Endpoints {
        src: ep.dst,
        src_port: ep.dst_port,
        dst: ep.src,
        dst_port: ep.src_port,
    }
}

/// Whether `ip` is usable as a unicast address here (not 0.0.0.0).
pub(crate) fn has_ip(ip: Ipv4) -> bool {
    ip != [0; 4]
}
