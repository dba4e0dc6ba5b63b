//! From captured frames to PROFINET events: link layer ([`crate::link`]), then either
//! PROFINET RT (Ethertype 0x8892, or UDP port 0x8892 for RT_CLASS_UDP; [`crate::rt`]) or
//! PNIO-CM (UDP port 34964, DCE/RPC [`crate::dcerpc`], blocks [`crate::pnio`]).
//!
//! [`Decoder`] is sans-IO: it takes a link type and the bytes of one frame and keeps only the
//! DCE/RPC reassembly state (bounded, see [`crate::dcerpc::ReassemblyLimits`]). [`Events`]
//! runs it over a [`CaptureReader`] and yields owned [`PnEvent`]s, skipping frames that are
//! not PROFINET; frames that are PROFINET but malformed become [`PnEventKind::Malformed`],
//! so one bad frame never stops the stream. Only capture errors end it.

use crate::dcerpc::{self, Header, Packet, Reassembler, ReassemblyLimits, RpcError, PNIO_PORT};
use crate::ip::{parse_ipv4_udp, IpError, UdpDatagram};
use crate::link::{ethertype, parse_link, LinkError, LinkFrame, LinkType};
use crate::pcap::{CaptureError, CaptureReader, RecordRef};
use crate::pnio::{self, CmMessage, PnioError};
use crate::rt::{ApduStatus, FrameClass, FrameId, RtError, RtFrame};
use std::io::Read;

/// UDP port of RT_CLASS_UDP frames (IEC 61158-6-10: 0x8892).
pub const RT_UDP_PORT: u16 = 0x8892;

/// One frame, decoded as far as PROFINET goes (our doc: module `profinet`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Pdu<'a> {
    /// A PROFINET RT frame.
    Rt {
        /// The link header.
        link: LinkFrame<'a>,
        /// The RT frame.
        frame: RtFrame<'a>,
        /// Carried in UDP (RT_CLASS_UDP) rather than directly in Ethernet.
        udp: bool,
    },
    /// A DCE/RPC PDU on the PNIO-CM port, or with a PNIO interface UUID on any port.
    Rpc {
        /// The link header.
        link: LinkFrame<'a>,
        /// The UDP datagram.
        udp: UdpDatagram<'a>,
        /// The RPC PDU.
        packet: Packet<'a>,
        /// The call this PDU completes, decoded as PNIO-CM (requests and responses to a PNIO
        /// interface only).
        message: Option<Result<CmMessage, PnioError>>,
    },
    /// Not PROFINET (another Ethertype, another UDP port).
    Other {
        /// The link header.
        link: LinkFrame<'a>,
    },
}

/// Why a frame that looked like PROFINET cannot be decoded (our doc: module `profinet`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum PduError {
    /// Link header.
    #[error(transparent)]
    Link(#[from] LinkError),
    /// IPv4/UDP of a PROFINET port.
    #[error(transparent)]
    Ip(#[from] IpError),
    /// RT frame.
    #[error(transparent)]
    Rt(#[from] RtError),
    /// DCE/RPC PDU or reassembly.
    #[error(transparent)]
    Rpc(#[from] RpcError),
}

/// Decodes frames one at a time, reassembling fragmented PNIO-CM calls (our doc: module
/// `profinet`).
#[derive(Debug, Default)]
pub struct Decoder {
    rpc: Reassembler,
}

/// Reads the UDP datagram of an IPv4 frame when it uses `port` on either side (any port
/// for `None`).
fn udp_on<'a>(link: &LinkFrame<'a>, port: Option<u16>) -> Option<Result<UdpDatagram<'a>, IpError>> {
    if link.ethertype != ethertype::IPV4 {
        return None;
    }
    match parse_ipv4_udp(link.payload) {
        Ok(u) if port.is_none_or(|p| u.src_port == p || u.dst_port == p) => Some(Ok(u)),
        Ok(_) | Err(IpError::NotUdp(_)) => None,
        Err(IpError::Fragment { .. }) => None,
        Err(_) if port.is_none() => None,
        Err(e) => {
            let port = port.unwrap_or(0);
            // Only report damaged IPv4 when the UDP header still names the port.
            let ihl = usize::from(link.payload.first().map_or(5, |b| b & 0x0f)) * 4;
            let ports = [
                crate::bytes::be16_at(link.payload, ihl),
                crate::bytes::be16_at(link.payload, ihl + 2),
            ];
            ports.contains(&Some(port)).then_some(Err(e))
        }
    }
}

impl Decoder {
    /// A decoder with the given reassembly limits.
    pub fn new(limits: ReassemblyLimits) -> Decoder {
        Decoder {
            rpc: Reassembler::new(limits),
        }
    }

    /// Unfinished PNIO-CM calls dropped because too many were pending.
    pub fn dropped_calls(&self) -> u64 {
        self.rpc.dropped()
    }

    fn rpc<'a>(
        &mut self,
        link: LinkFrame<'a>,
        udp: UdpDatagram<'a>,
        packet: Packet<'a>,
    ) -> Result<Pdu<'a>, PduError> {
        let call = matches!(
            packet.header.ptype,
            dcerpc::PacketType::REQUEST | dcerpc::PacketType::RESPONSE
        );
        let message = if call && packet.header.interface.is_pnio_interface() {
            self.rpc.push(&packet)?.map(|m| pnio::decode(&m))
        } else {
            None
        };
        Ok(Pdu::Rpc {
            link,
            udp,
            packet,
            message,
        })
    }

    /// Decodes one frame of the given link type.
    pub fn decode<'a>(
        &mut self,
        link_type: LinkType,
        bytes: &'a [u8],
    ) -> Result<Pdu<'a>, PduError> {
        let link = parse_link(link_type, bytes)?;
        if link.ethertype == ethertype::PROFINET {
            let frame = RtFrame::parse(link.payload)?;
            return Ok(Pdu::Rt {
                link,
                frame,
                udp: false,
            });
        }
        if let Some(udp) = udp_on(&link, Some(PNIO_PORT)) {
            let udp = udp?;
            let packet = dcerpc::parse(udp.payload)?;
            return self.rpc(link, udp, packet);
        }
        if let Some(Ok(udp)) = udp_on(&link, None) {
            // PNIO-CM answers and device-initiated calls may use ephemeral ports on both
            // sides; the PNIO interface UUID identifies them.
            if let Ok(packet) = dcerpc::parse(udp.payload) {
                if packet.header.interface.is_pnio_interface() {
                    return self.rpc(link, udp, packet);
                }
            }
        }
        if let Some(udp) = udp_on(&link, Some(RT_UDP_PORT)) {
            let udp = udp?;
            let frame = RtFrame::parse(udp.payload)?;
            return Ok(Pdu::Rt {
                link,
                frame,
                udp: true,
            });
        }
        Ok(Pdu::Other { link })
    }
}

/// Frame counts by kind, for summaries and the real-capture expectations (our doc: module
/// `profinet`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Counts {
    /// Records seen.
    pub records: u64,
    /// RT frames in a cyclic FrameID range.
    pub rt_cyclic: u64,
    /// DCP frames (FrameID 0xFEFC–0xFEFF).
    pub dcp: u64,
    /// Alarm frames (0xFC01, 0xFE01).
    pub alarm: u64,
    /// PTCP frames.
    pub ptcp: u64,
    /// Other RT frames (fragments, reserved or other acyclic FrameIDs).
    pub rt_other: u64,
    /// PNIO-CM DCE/RPC PDUs: on UDP port 34964, or with a PNIO interface UUID.
    pub pnio_cm: u64,
    /// Of these, the ones on UDP port 34964.
    pub pnio_cm_port: u64,
    /// PNIO-CM calls and answers completed and decoded.
    pub cm_messages: u64,
    /// Frames that are not PROFINET.
    pub other: u64,
    /// Frames that looked like PROFINET but did not decode (or completed an undecodable call).
    pub errors: u64,
}

impl Counts {
    /// Counts one decoded frame.
    pub fn add(&mut self, pdu: &Result<Pdu<'_>, PduError>) {
        self.records += 1;
        match pdu {
            Ok(Pdu::Rt { frame, .. }) => match frame.class() {
                FrameClass::Cyclic(_) => self.rt_cyclic += 1,
                c if c.is_dcp() => self.dcp += 1,
                c if c.is_ptcp() => self.ptcp += 1,
                FrameClass::AlarmHigh | FrameClass::AlarmLow => self.alarm += 1,
                _ => self.rt_other += 1,
            },
            Ok(Pdu::Rpc { message, udp, .. }) => {
                self.pnio_cm += 1;
                if udp.src_port == PNIO_PORT || udp.dst_port == PNIO_PORT {
                    self.pnio_cm_port += 1;
                }
                match message {
                    Some(Ok(_)) => self.cm_messages += 1,
                    Some(Err(_)) => self.errors += 1,
                    None => {}
                }
            }
            Ok(Pdu::Other { .. }) => self.other += 1,
            Err(PduError::Link(LinkError::Unsupported(_))) => self.other += 1,
            Err(_) => self.errors += 1,
        }
    }
}

/// A PROFINET event taken from a capture (our doc: module `profinet`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PnEvent {
    /// Record number in the capture (from 1).
    pub record: u64,
    /// Microseconds since 1970, when known.
    pub time: Option<u64>,
    /// Source MAC, when the link layer has one.
    pub src: Option<[u8; 6]>,
    /// Destination MAC, when the link layer has one.
    pub dst: Option<[u8; 6]>,
    /// What happened.
    pub kind: PnEventKind,
}

/// The kinds of [`PnEvent`] (our doc: module `profinet`).
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum PnEventKind {
    /// A cyclic frame (IEC 61158-6-10).
    Cyclic {
        /// The FrameID.
        frame_id: FrameId,
        /// C_SDU and padding (cut with the Connect's DataLength).
        data: Vec<u8>,
        /// The APDU status.
        apdu: ApduStatus,
    },
    /// Any acyclic RT frame: DCP, alarm, PTCP, fragment, other.
    Acyclic {
        /// The FrameID.
        frame_id: FrameId,
        /// Its class.
        class: FrameClass,
        /// Bytes after the FrameID.
        body: Vec<u8>,
    },
    /// A completed PNIO-CM call or answer.
    Cm {
        /// RPC header (of fragment 0).
        header: Header,
        /// IPv4 source address and UDP port.
        src: ([u8; 4], u16),
        /// IPv4 destination address and UDP port.
        dst: ([u8; 4], u16),
        /// The decoded message.
        message: CmMessage,
    },
    /// A DCE/RPC PDU that carries no PNIO-CM call: ping, working, fault, reject, ack, fack,
    /// a fragment's acknowledgement, or a call to another interface (endpoint mapper).
    RpcOther {
        /// Its header.
        header: Header,
        /// Its body (a fault or reject carries a status).
        body: Vec<u8>,
    },
    /// A PROFINET frame or call that could not be decoded.
    Malformed {
        /// Why.
        error: MalformedError,
    },
}

/// Why a PROFINET frame or call could not be decoded (our doc: module `profinet`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum MalformedError {
    /// The frame.
    #[error(transparent)]
    Frame(#[from] PduError),
    /// The completed call's PNIO-CM body.
    #[error(transparent)]
    Cm(#[from] PnioError),
}

/// PROFINET events of a capture, in order (our doc: module `profinet`).
#[derive(Debug)]
pub struct Events<R: Read> {
    reader: CaptureReader<R>,
    decoder: Decoder,
    counts: Counts,
}

impl<R: Read> Events<R> {
    /// Events of the records `reader` yields.
    pub fn new(reader: CaptureReader<R>) -> Events<R> {
        Events {
            reader,
            decoder: Decoder::default(),
            counts: Counts::default(),
        }
    }

    /// Counts of the frames read so far.
    pub fn counts(&self) -> Counts {
        self.counts
    }

    /// The capture reader.
    pub fn reader(&self) -> &CaptureReader<R> {
        &self.reader
    }
}

fn event(record: &RecordRef<'_>, pdu: Result<Pdu<'_>, PduError>) -> Option<PnEvent> {
    let (src, dst) = match &pdu {
        Ok(Pdu::Rt { link, .. } | Pdu::Rpc { link, .. } | Pdu::Other { link }) => {
            (link.src, link.dst)
        }
        Err(_) => (None, None),
    };
    let kind = match pdu {
        Ok(Pdu::Rt { frame, .. }) => match frame.cyclic() {
            Ok(c) => PnEventKind::Cyclic {
                frame_id: c.frame_id,
                data: c.data.to_vec(),
                apdu: c.apdu,
            },
            Err(RtError::WrongClass { .. }) => PnEventKind::Acyclic {
                frame_id: frame.frame_id,
                class: frame.class(),
                body: frame.body.to_vec(),
            },
            Err(e) => PnEventKind::Malformed {
                error: MalformedError::Frame(e.into()),
            },
        },
        Ok(Pdu::Rpc {
            udp,
            packet,
            message,
            ..
        }) => match message {
            Some(Ok(message)) => PnEventKind::Cm {
                header: packet.header,
                src: (udp.src, udp.src_port),
                dst: (udp.dst, udp.dst_port),
                message,
            },
            Some(Err(e)) => PnEventKind::Malformed { error: e.into() },
            None if packet.header.is_fragment()
                && !packet.header.is_last_fragment()
                && packet.header.interface.is_pnio_interface() =>
            {
                return None; // a fragment of a call not yet complete
            }
            None => PnEventKind::RpcOther {
                header: packet.header,
                body: packet.body.to_vec(),
            },
        },
        Ok(Pdu::Other { .. }) | Err(PduError::Link(LinkError::Unsupported(_))) => return None,
        Err(e) => PnEventKind::Malformed { error: e.into() },
    };
    Some(PnEvent {
        record: record.number,
        time: record.time,
        src,
        dst,
        kind,
    })
}

impl<R: Read> Iterator for Events<R> {
    type Item = Result<PnEvent, CaptureError>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            let record = match self.reader.next_record() {
                Ok(Some(r)) => r,
                Ok(None) => return None,
                Err(e) => return Some(Err(e)),
            };
            let pdu = self.decoder.decode(record.link_type, record.data);
            self.counts.add(&pdu);
            if let Some(e) = event(&record, pdu) {
                return Some(Ok(e));
            }
        }
    }
}
