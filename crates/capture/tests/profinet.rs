//! Link layer, PROFINET RT, DCE/RPC and PNIO-CM on hand-built frames; the PROFINET event
//! stream through the writer; no panic on any bytes.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

mod util;

use drivespec_capture::dcerpc::{self, PacketType, Reassembler, ReassemblyLimits, RpcError, Uuid};
use drivespec_capture::ip::{parse_ipv4_udp, IpError};
use drivespec_capture::link::{self, parse_link, LinkError};
use drivespec_capture::pnio::{
    self, block_type, control_command, Block, ControlKind, Direction, Operation, PnioError,
};
use drivespec_capture::profinet::{Counts, Decoder, Events, Pdu, PnEventKind};
use drivespec_capture::rt::{CyclicClass, FrameClass, FrameId, RtError, RtFrame};
use drivespec_capture::write::PcapNgWriter;
use drivespec_capture::{CaptureReader, Endian, LinkType};
use proptest::prelude::*;
use util::*;

// ---------------------------------------------------------------- link layer

#[test]
fn ethernet_with_no_one_and_two_tags() {
    let plain = ethernet(&[], 0x8892, &[0xc0, 0x01]);
    let f = link::parse_ethernet(&plain).unwrap();
    assert_eq!(f.dst, Some(MAC_B));
    assert_eq!(f.src, Some(MAC_A));
    assert_eq!(f.ethertype, 0x8892);
    assert!(f.tags.as_slice().is_empty());
    assert_eq!(f.payload, &[0xc0, 0x01]);

    // 802.1Q: PCP 6, VID 0 (PROFINET priority tagging).
    let tagged = ethernet(&[(0x8100, 0xc000)], 0x8892, &[1]);
    let f = link::parse_ethernet(&tagged).unwrap();
    assert_eq!(f.tags.as_slice().len(), 1);
    assert_eq!(f.tags.as_slice()[0].pcp, 6);
    assert_eq!(f.tags.vid(), Some(0));
    assert_eq!(f.header_len, 18);

    // QinQ: S-tag VID 100, C-tag VID 7 with DEI.
    let qinq = ethernet(&[(0x88a8, 100), (0x8100, 0x1007)], 0x0800, &[]);
    let f = link::parse_ethernet(&qinq).unwrap();
    let tags = f.tags.as_slice();
    assert_eq!((tags[0].tpid, tags[0].vid), (0x88a8, 100));
    assert_eq!((tags[1].vid, tags[1].dei), (7, true));
    assert_eq!(f.tags.vid(), Some(7));
    assert_eq!(f.ethertype, 0x0800);

    let five = ethernet(&[(0x8100, 1); 5], 0x0800, &[]);
    assert_eq!(link::parse_ethernet(&five), Err(LinkError::TooManyTags));
    assert!(matches!(
        link::parse_ethernet(&plain[..13]),
        Err(LinkError::Truncated(t)) if t.offset == 12 && t.need == 2 && t.have == 1
    ));
}

#[test]
fn linux_cooked_captures_v1_and_v2() {
    // SLL: packet type 4 (outgoing), ARPHRD_ETHER, 6-byte address, protocol 0x8892.
    let mut sll = Be::default()
        .u16(4)
        .u16(1)
        .u16(6)
        .bytes(&MAC_A)
        .bytes(&[0, 0])
        .u16(0x8892)
        .0;
    sll.extend_from_slice(&[0xfe, 0xfe]);
    let f = parse_link(LinkType::LINUX_SLL, &sll).unwrap();
    assert_eq!(
        (f.ethertype, f.packet_type, f.src),
        (0x8892, Some(4), Some(MAC_A))
    );
    assert_eq!(f.payload, &[0xfe, 0xfe]);

    // SLL2: protocol, reserved, ifindex, ARPHRD, packet type, address length, address.
    let mut sll2 = Be::default()
        .u16(0x8100)
        .u16(0)
        .u32(3)
        .u16(1)
        .u8(0)
        .u8(6)
        .bytes(&MAC_B)
        .bytes(&[0, 0])
        .0;
    sll2.extend(Be::default().u16(0xa005).u16(0x8892).u16(0xfefe).0);
    let f = parse_link(LinkType::LINUX_SLL2, &sll2).unwrap();
    assert_eq!(f.tags.vid(), Some(5));
    assert_eq!(f.ethertype, 0x8892);
    assert_eq!(f.payload, &[0xfe, 0xfe]);

    assert_eq!(
        parse_link(LinkType::USER0, &sll),
        Err(LinkError::Unsupported(LinkType::USER0))
    );
}

#[test]
fn ipv4_udp_is_trimmed_to_its_lengths() {
    let udp = ipv4_udp([10, 0, 0, 1], [10, 0, 0, 2], 1000, 34964, b"abc");
    let frame = pad60(ethernet(&[], 0x0800, &udp));
    let f = link::parse_ethernet(&frame).unwrap();
    assert!(
        f.payload.len() > udp.len(),
        "Ethernet padding is in the link payload"
    );
    let d = parse_ipv4_udp(f.payload).unwrap();
    assert_eq!(d.payload, b"abc", "but not in the UDP payload");
    assert_eq!((d.src_port, d.dst_port), (1000, 34964));
    assert_eq!(d.src, [10, 0, 0, 1]);

    let mut frag = udp.clone();
    frag[6] = 0x20; // more fragments
    assert_eq!(
        parse_ipv4_udp(&frag),
        Err(IpError::Fragment {
            offset: 0,
            more: true
        })
    );
    let mut tcp = udp.clone();
    tcp[9] = 6;
    assert_eq!(parse_ipv4_udp(&tcp), Err(IpError::NotUdp(6)));
    assert!(matches!(
        parse_ipv4_udp(&udp[..25]),
        Err(IpError::Short {
            total: 31,
            captured: 25
        })
    ));
}

// ---------------------------------------------------------------- PROFINET RT

#[test]
fn frame_id_classes() {
    let cases = [
        (0x0020, FrameClass::PtcpSync { follow_up: true }),
        (0x0080, FrameClass::PtcpSync { follow_up: false }),
        (
            0x0100,
            FrameClass::Cyclic(CyclicClass::Class3 { redundant: false }),
        ),
        (
            0x0700,
            FrameClass::Cyclic(CyclicClass::Class3 { redundant: true }),
        ),
        (
            0x8000,
            FrameClass::Cyclic(CyclicClass::Class2 { multicast: false }),
        ),
        (
            0xBC00,
            FrameClass::Cyclic(CyclicClass::Class2 { multicast: true }),
        ),
        (
            0xC000,
            FrameClass::Cyclic(CyclicClass::Class1 { multicast: false }),
        ),
        (
            0xF800,
            FrameClass::Cyclic(CyclicClass::Class1 { multicast: true }),
        ),
        (0xFC01, FrameClass::AlarmHigh),
        (0xFE01, FrameClass::AlarmLow),
        (0xFE02, FrameClass::OtherAcyclic),
        (0xFEFC, FrameClass::DcpHello),
        (0xFEFD, FrameClass::DcpGetSet),
        (0xFEFE, FrameClass::DcpIdentifyRequest),
        (0xFEFF, FrameClass::DcpIdentifyResponse),
        (0xFF00, FrameClass::PtcpAnnounce),
        (0xFF20, FrameClass::PtcpFollowUp),
        (0xFF43, FrameClass::PtcpDelay),
        (0xFF80, FrameClass::Fragment),
        (0x0000, FrameClass::Reserved),
        (0x1000, FrameClass::Reserved),
        (0xFFFF, FrameClass::Reserved),
    ];
    for (id, class) in cases {
        assert_eq!(FrameId(id).class(), class, "{id:#06x}");
    }
    assert!(FrameClass::DcpHello.is_dcp());
    assert!(FrameClass::PtcpDelay.is_ptcp());
}

/// A cyclic RT payload: FrameID, C_SDU, padding to 40 bytes, APDU status.
fn cyclic(frame_id: u16, c_sdu: &[u8], cycle: u16, data_status: u8) -> Vec<u8> {
    let mut p = frame_id.to_be_bytes().to_vec();
    p.extend_from_slice(c_sdu);
    while p.len() < 2 + 40 {
        p.push(0);
    }
    p.extend_from_slice(&cycle.to_be_bytes());
    p.push(data_status);
    p.push(0);
    p
}

#[test]
fn cyclic_frames_split_into_c_sdu_padding_and_apdu_status() {
    let c_sdu = [0x80, 0x11, 0x22, 0x80, 0x80];
    let payload = cyclic(0x8001, &c_sdu, 0x1234, 0x35);
    let frame = RtFrame::parse(&payload).unwrap();
    let c = frame.cyclic().unwrap();
    assert_eq!(c.class, CyclicClass::Class2 { multicast: false });
    assert_eq!(c.data.len(), 40, "C_SDU and padding");
    assert_eq!(c.c_sdu(5).unwrap(), &c_sdu);
    assert_eq!(c.padding(5).unwrap(), &[0u8; 35][..]);
    assert_eq!(
        c.c_sdu(41),
        Err(RtError::CsduTooLong {
            frame_id: FrameId(0x8001),
            expected: 41,
            available: 40
        })
    );
    assert_eq!(c.apdu.cycle_counter, 0x1234);
    assert_eq!(c.apdu.transfer_status, 0);
    let ds = c.apdu.data_status;
    // 0x35 = primary, data valid, run, station ok.
    assert!(ds.primary() && ds.data_valid() && ds.provider_run() && ds.station_ok());
    assert!(!ds.redundancy() && !ds.ignore());
    assert_eq!(ds.reserved(), 0);
    assert_eq!(ds.to_string(), "0x35 (primary, valid, run, ok)");
    let ds = drivespec_capture::rt::DataStatus(0x80 | 0x02);
    assert!(ds.ignore() && ds.redundancy() && !ds.primary() && !ds.station_ok());

    assert!(matches!(
        RtFrame::parse(&[0x80, 0x01, 0, 0]).unwrap().cyclic(),
        Err(RtError::Truncated(_))
    ));
    assert!(matches!(
        RtFrame::parse(&[0xfe, 0xfe]).unwrap().cyclic(),
        Err(RtError::WrongClass { .. })
    ));
}

#[test]
fn dcp_alarm_and_fragment_headers() {
    // DCP Identify request: ServiceID 5, type 0, Xid, ResponseDelay 1, length 4, one block.
    let dcp = Be::default()
        .u16(0xfefe)
        .u8(5)
        .u8(0)
        .u32(0x0300_bf9a)
        .u16(1)
        .u16(4)
        .bytes(&[0xff, 0xff, 0x00, 0x00])
        .bytes(&[0; 20])
        .0;
    let h = RtFrame::parse(&dcp).unwrap().dcp().unwrap();
    assert_eq!((h.service_id, h.service_type, h.xid), (5, 0, 0x0300_bf9a));
    assert_eq!(
        h.blocks,
        &[0xff, 0xff, 0, 0],
        "padding after DCPDataLength dropped"
    );

    let alarm = Be::default()
        .u16(0xfc01)
        .u16(0x0001)
        .u16(0x0002)
        .u8(0x11)
        .u8(0)
        .u16(0xffff)
        .u16(0xfffe)
        .u16(2)
        .bytes(&[0xaa, 0xbb, 0xcc])
        .0;
    let a = RtFrame::parse(&alarm).unwrap().alarm().unwrap();
    assert_eq!((a.dst_endpoint, a.src_endpoint, a.pdu_type), (1, 2, 0x11));
    assert_eq!(a.var_part, &[0xaa, 0xbb]);

    let frag = Be::default().u16(0xff81).u8(3).u8(0x82).bytes(&[7; 24]).0;
    let f = RtFrame::parse(&frag).unwrap().fragment().unwrap();
    assert_eq!((f.data_length, f.more_follows, f.number), (3, true, 2));
    assert_eq!(f.data.len(), 24);
}

// ---------------------------------------------------------------- DCE/RPC

#[test]
fn dcerpc_headers_in_both_byte_orders() {
    for order in [Endian::Big, Endian::Little] {
        let pdu = Rpc::request(2, order).pdu(b"body!");
        let p = dcerpc::parse(&pdu).unwrap();
        let h = p.header;
        assert_eq!(h.drep.integer, order);
        assert_eq!(h.ptype, PacketType::REQUEST);
        assert_eq!(h.interface, Uuid::PNIO_DEVICE);
        assert_eq!(h.activity, Uuid(ACTIVITY));
        assert_eq!(
            (h.opnum, h.sequence, h.body_len, h.interface_version),
            (2, 7, 5, 1)
        );
        assert_eq!(p.body, b"body!");
        assert!(h.interface.is_pnio_interface());
    }
    assert_eq!(
        Uuid::PNIO_DEVICE.to_string(),
        "dea00001-6c97-11d1-8271-00a02442df7d"
    );
    let mut pdu = Rpc::request(0, Endian::Little).pdu(b"xy");
    assert!(matches!(
        dcerpc::parse(&pdu[..60]),
        Err(RpcError::Truncated(t)) if t.offset == 60 && t.need == 4 && t.have == 0
    ));
    pdu.truncate(81);
    assert_eq!(
        dcerpc::parse(&pdu),
        Err(RpcError::BodyLength {
            declared: 2,
            captured: 1
        })
    );
    pdu[0] = 5;
    assert_eq!(dcerpc::parse(&pdu), Err(RpcError::Version(5)));
}

fn fragment(rpc: Rpc, number: u16, last: bool, body: &[u8]) -> Vec<u8> {
    Rpc {
        flags1: 0x04 | if last { 0x02 } else { 0 },
        fragment: number,
        ..rpc
    }
    .pdu(body)
}

#[test]
fn fragmented_calls_are_reassembled_in_any_order() {
    let rpc = Rpc::request(0, Endian::Little);
    let pieces = [
        fragment(rpc, 0, false, b"aaa"),
        fragment(rpc, 1, false, b"bb"),
        fragment(rpc, 2, true, b"c"),
    ];
    for order in [[0, 1, 2], [2, 0, 1], [1, 2, 0]] {
        let mut r = Reassembler::default();
        let mut done = None;
        for (k, &i) in order.iter().enumerate() {
            let out = r.push(&dcerpc::parse(&pieces[i]).unwrap()).unwrap();
            if k < 2 {
                assert!(out.is_none());
                // A repeated fragment changes nothing.
                assert!(r
                    .push(&dcerpc::parse(&pieces[i]).unwrap())
                    .unwrap()
                    .is_none());
            } else {
                done = out;
            }
        }
        let m = done.unwrap();
        assert_eq!(m.body, b"aaabbc");
        assert_eq!(m.fragments, 3);
        assert_eq!(m.header.fragment, 0);
        assert_eq!(r.pending(), 0);
    }
}

#[test]
fn reassembly_is_bounded() {
    let limits = ReassemblyLimits {
        max_message: 5,
        max_fragments: 4,
        max_pending: 2,
    };
    let rpc = Rpc::request(0, Endian::Big);
    let mut r = Reassembler::new(limits);
    r.push(&dcerpc::parse(&fragment(rpc, 0, false, b"abc")).unwrap())
        .unwrap();
    assert!(matches!(
        r.push(&dcerpc::parse(&fragment(rpc, 1, false, b"def")).unwrap()),
        Err(RpcError::TooLarge {
            size: 6,
            limit: 5,
            ..
        })
    ));
    assert_eq!(r.pending(), 0, "the oversized call is dropped");
    assert!(matches!(
        r.push(&dcerpc::parse(&fragment(rpc, 4, true, b"x")).unwrap()),
        Err(RpcError::TooManyFragments { fragment: 4, .. })
    ));
    for seq in 0..3 {
        let p = fragment(
            Rpc {
                sequence: seq,
                ..rpc
            },
            0,
            false,
            b"a",
        );
        r.push(&dcerpc::parse(&p).unwrap()).unwrap();
    }
    assert_eq!((r.pending(), r.dropped()), (2, 1));
}

// ---------------------------------------------------------------- PNIO-CM blocks

fn ar_block_req() -> Vec<u8> {
    let name = b"plc-1";
    block(
        block_type::AR_REQ,
        &Be::default()
            .u16(1)
            .bytes(&AR_UUID)
            .u16(3)
            .bytes(&MAC_A)
            .bytes(&PNIO_DEVICE)
            .u32(0x11)
            .u16(600)
            .u16(0x8892)
            .u16(name.len() as u16)
            .bytes(name)
            .0,
    )
}

fn iocr_block_req(iocr_type: u16, frame_id: u16) -> Vec<u8> {
    block(
        block_type::IOCR_REQ,
        &Be::default()
            .u16(iocr_type)
            .u16(iocr_type)
            .u16(0x8892)
            .u32(2)
            .u16(40)
            .u16(frame_id)
            .u16(32)
            .u16(4)
            .u16(1)
            .u16(0)
            .u32(0xffff_ffff)
            .u16(3)
            .u16(3)
            .u16(0xc000)
            .bytes(&[0; 6])
            .u16(1) // one API
            .u32(0)
            .u16(2) // IODataObjects
            .u16(0)
            .u16(1)
            .u16(0)
            .u16(1)
            .u16(1)
            .u16(1)
            .u16(1) // IOCS
            .u16(1)
            .u16(1)
            .u16(5)
            .0,
    )
}

fn expected_submodules() -> Vec<u8> {
    block(
        block_type::EXPECTED_SUBMODULE_REQ,
        &Be::default()
            .u16(1) // one API entry
            .u32(0)
            .u16(1) // slot
            .u32(0x0000_0042)
            .u16(0)
            .u16(2) // submodules
            .u16(1)
            .u32(0x0000_0101)
            .u16(3) // input and output
            .u16(1)
            .u16(12)
            .u8(1)
            .u8(1)
            .u16(2)
            .u16(10)
            .u8(1)
            .u8(1)
            .u16(2)
            .u32(0x0000_0102)
            .u16(1) // input only
            .u16(1)
            .u16(4)
            .u8(1)
            .u8(1)
            .0,
    )
}

fn alarm_cr_req() -> Vec<u8> {
    block(block_type::ALARM_CR_REQ, &[0; 24])
}

fn connect_request() -> Vec<u8> {
    [
        ar_block_req(),
        iocr_block_req(1, 0x8001),
        iocr_block_req(2, 0xffff),
        alarm_cr_req(),
        expected_submodules(),
    ]
    .concat()
}

#[test]
fn connect_request_blocks() {
    for order in [Endian::Big, Endian::Little] {
        let body = ndr_request(order, &connect_request());
        let m = pnio::decode_body(PacketType::REQUEST, 0, order, &body).unwrap();
        assert_eq!(
            (m.operation, m.direction),
            (Operation::Connect, Direction::Request)
        );
        assert_eq!(m.ndr.args_maximum, Some(4096));
        assert_eq!(m.ndr.args_length as usize, connect_request().len());
        assert_eq!(m.blocks.len(), 5);
        let Block::ArReq(ar) = &m.blocks[0] else {
            panic!()
        };
        assert_eq!(ar.ar_uuid, Uuid(AR_UUID));
        assert_eq!((ar.session_key, ar.activity_timeout_factor), (3, 600));
        assert_eq!(ar.station_name, "plc-1");
        assert_eq!(ar.header.offset, 20);
        let Block::IocrReq(input) = &m.blocks[1] else {
            panic!()
        };
        assert_eq!(
            (input.iocr_type, input.frame_id, input.data_length),
            (1, FrameId(0x8001), 40)
        );
        assert_eq!((input.send_clock_factor, input.reduction_ratio), (32, 4));
        assert_eq!(input.cycle_micros(), 4000);
        assert_eq!(input.rt_class(), 2);
        assert_eq!(input.apis[0].data_objects.len(), 2);
        assert_eq!(input.apis[0].data_objects[1].frame_offset, 1);
        assert_eq!(input.apis[0].iocs[0].frame_offset, 5);
        let Block::Unknown(alarm) = &m.blocks[3] else {
            panic!()
        };
        assert_eq!(alarm.header.block_type, block_type::ALARM_CR_REQ);
        assert_eq!(m.unknown_blocks().count(), 1);
        let Block::ExpectedSubmodules(exp) = &m.blocks[4] else {
            panic!()
        };
        let module = &exp.modules[0];
        assert_eq!((module.slot, module.ident), (1, 0x42));
        let io = &module.submodules[0];
        assert_eq!(io.input.unwrap().data_length, 12);
        assert_eq!(io.output.unwrap().data_length, 10);
        let input_only = &module.submodules[1];
        assert_eq!(input_only.input.unwrap().data_length, 4);
        assert!(input_only.output.is_none());
    }
}

#[test]
fn connect_response_blocks() {
    let blocks = [
        block(
            block_type::AR_RES,
            &Be::default()
                .u16(1)
                .bytes(&AR_UUID)
                .u16(3)
                .bytes(&MAC_B)
                .u16(0x8892)
                .0,
        ),
        block(
            block_type::IOCR_RES,
            &Be::default().u16(2).u16(2).u16(0x8002).0,
        ),
        block(block_type::MODULE_DIFF, &[0, 0]),
    ]
    .concat();
    let body = ndr_response(Endian::Little, [0; 4], &blocks);
    let m = pnio::decode_body(PacketType::RESPONSE, 0, Endian::Little, &body).unwrap();
    assert!(m.ndr.status.unwrap().is_ok());
    let Block::ArRes(ar) = &m.blocks[0] else {
        panic!()
    };
    assert_eq!((ar.responder_mac, ar.udp_rt_port), (MAC_B, 0x8892));
    let Block::IocrRes(iocr) = &m.blocks[1] else {
        panic!()
    };
    assert_eq!(iocr.frame_id, FrameId(0x8002));
    assert_eq!(m.unknown_blocks().next().unwrap().body, vec![0, 0]);

    // A negative response: the PNIOStatus in the NDR header, in the RPC byte order.
    let body = ndr_response(Endian::Little, [0xdb, 0x81, 0x01, 0x04], &[]);
    let m = pnio::decode_body(PacketType::RESPONSE, 0, Endian::Little, &body).unwrap();
    let st = m.ndr.status.unwrap();
    assert_eq!(
        (st.code, st.decode, st.code1, st.code2),
        (0xdb, 0x81, 0x01, 0x04)
    );
    assert_eq!(st.to_string(), "db810104");
    assert!(m.blocks.is_empty());
}

fn record_header(t: u16, index: u16, len: u32, tail: &[u8]) -> Vec<u8> {
    let mut body = Be::default()
        .u16(9) // seq
        .bytes(&AR_UUID)
        .u32(0)
        .u16(1)
        .u16(2)
        .u16(0)
        .u16(index)
        .u32(len)
        .bytes(tail)
        .0;
    while body.len() < 58 {
        body.push(0);
    }
    block(t, &body)
}

#[test]
fn read_and_write_records() {
    // Read request with TargetARUUID; read response with the data after the header.
    let req = record_header(block_type::READ_REQ, 0xaff0, 4096, &AR_UUID);
    let m = pnio::decode_body(
        PacketType::REQUEST,
        2,
        Endian::Big,
        &ndr_request(Endian::Big, &req),
    )
    .unwrap();
    let Block::ReadReq(r) = &m.blocks[0] else {
        panic!()
    };
    assert_eq!(
        (r.index, r.slot, r.subslot, r.record_data_length),
        (0xaff0, 1, 2, 4096)
    );
    assert_eq!(r.target_ar_uuid, Some(Uuid(AR_UUID)));
    assert_eq!(r.header.length, 60);

    let mut res = record_header(
        block_type::READ_RES,
        0xaff0,
        3,
        &Be::default().u16(7).u16(8).0,
    );
    res.extend_from_slice(&[0xa, 0xb, 0xc]);
    let m = pnio::decode_body(
        PacketType::RESPONSE,
        2,
        Endian::Big,
        &ndr_response(Endian::Big, [0; 4], &res),
    )
    .unwrap();
    let Block::ReadRes(r) = &m.blocks[0] else {
        panic!()
    };
    assert_eq!(r.data, vec![0xa, 0xb, 0xc]);
    assert_eq!((r.additional_value1, r.additional_value2), (7, 8));

    // Write request with data; write response with a PNIOStatus in the block.
    let mut req = record_header(block_type::WRITE_REQ, 0x0064, 2, &[]);
    req.extend_from_slice(&[0x12, 0x34]);
    let m = pnio::decode_body(
        PacketType::REQUEST,
        3,
        Endian::Little,
        &ndr_request(Endian::Little, &req),
    )
    .unwrap();
    assert_eq!(m.operation, Operation::Write);
    let Block::WriteReq(w) = &m.blocks[0] else {
        panic!()
    };
    assert_eq!((w.index, w.data.clone()), (0x0064, vec![0x12, 0x34]));

    let res = record_header(
        block_type::WRITE_RES,
        0x0064,
        2,
        &Be::default()
            .u16(0)
            .u16(0)
            .bytes(&[0xdf, 0x80, 0xb0, 0x00])
            .0,
    );
    let m = pnio::decode_body(
        PacketType::RESPONSE,
        3,
        Endian::Little,
        &ndr_response(Endian::Little, [0xdf, 0x80, 0xb0, 0x00], &res),
    )
    .unwrap();
    let Block::WriteRes(w) = &m.blocks[0] else {
        panic!()
    };
    let st = w.status.unwrap();
    assert_eq!((st.code, st.decode, st.code1), (0xdf, 0x80, 0xb0));
    assert!(w.data.is_empty());

    // Declared record data longer than what follows.
    let req = record_header(block_type::WRITE_REQ, 0x0064, 9, &[]);
    assert_eq!(
        pnio::decode_body(
            PacketType::REQUEST,
            3,
            Endian::Big,
            &ndr_request(Endian::Big, &req)
        ),
        Err(PnioError::RecordData {
            offset: 20,
            index: 0x0064,
            declared: 9,
            available: 0
        })
    );
}

fn control(t: u16, command: u16) -> Vec<u8> {
    block(
        t,
        &Be::default()
            .u16(0)
            .bytes(&AR_UUID)
            .u16(3)
            .u16(0)
            .u16(command)
            .u16(0)
            .0,
    )
}

#[test]
fn control_blocks() {
    let cases = [
        (0x0110, ControlKind::PrmEnd, control_command::PRM_END, false),
        (0x8110, ControlKind::PrmEnd, control_command::DONE, true),
        (
            0x0112,
            ControlKind::ApplicationReady,
            control_command::APPLICATION_READY,
            false,
        ),
        (
            0x8112,
            ControlKind::ApplicationReady,
            control_command::DONE,
            true,
        ),
        (
            0x0114,
            ControlKind::Release,
            control_command::RELEASE,
            false,
        ),
        (0x8114, ControlKind::Release, control_command::DONE, true),
        (
            0x0118,
            ControlKind::PrmBegin,
            control_command::PRM_BEGIN,
            false,
        ),
    ];
    for (t, kind, command, response) in cases {
        let body = if response {
            ndr_response(Endian::Big, [0; 4], &control(t, command))
        } else {
            ndr_request(Endian::Big, &control(t, command))
        };
        let ptype = if response {
            PacketType::RESPONSE
        } else {
            PacketType::REQUEST
        };
        let m = pnio::decode_body(ptype, 4, Endian::Big, &body).unwrap();
        let Block::Control(c) = &m.blocks[0] else {
            panic!("{t:#x}")
        };
        assert_eq!(
            (c.kind, c.command, c.response),
            (kind, command, response),
            "{t:#x}"
        );
        assert_eq!((c.ar_uuid, c.session_key), (Uuid(AR_UUID), 3));
    }
}

#[test]
fn block_and_args_length_errors_name_the_offset() {
    let mut blocks = ar_block_req();
    blocks.extend(block(0x0999, &[1, 2, 3]));
    let mut bad = blocks.clone();
    let second = ar_block_req().len();
    bad[second + 2..second + 4].copy_from_slice(&100u16.to_be_bytes());
    assert_eq!(
        pnio::decode_body(
            PacketType::REQUEST,
            0,
            Endian::Big,
            &ndr_request(Endian::Big, &bad)
        ),
        Err(PnioError::BlockLength {
            offset: 20 + second,
            block_type: 0x0999,
            length: 100,
            available: 5
        })
    );
    // A field running past its block is a truncation inside that block.
    let short = block(block_type::IOCR_RES, &[0, 1]);
    let err = pnio::decode_body(
        PacketType::REQUEST,
        0,
        Endian::Big,
        &ndr_request(Endian::Big, &short),
    )
    .unwrap_err();
    assert!(
        matches!(err, PnioError::Truncated { what: "IOCRBlockRes", source } if source.offset == 28),
        "{err:?}"
    );
    let mut body = ndr_request(Endian::Big, &blocks);
    body.truncate(body.len() - 1);
    assert!(matches!(
        pnio::decode_body(PacketType::REQUEST, 0, Endian::Big, &body),
        Err(PnioError::ArgsLength { .. })
    ));
    assert_eq!(
        pnio::decode_body(PacketType::PING, 0, Endian::Big, &body),
        Err(PnioError::NotACall(PacketType::PING))
    );
}

// ---------------------------------------------------------------- decoder and events

fn rpc_frame(rpc_pdu: &[u8], sport: u16, dport: u16) -> Vec<u8> {
    ethernet(
        &[],
        0x0800,
        &ipv4_udp([192, 168, 0, 1], [192, 168, 0, 2], sport, dport, rpc_pdu),
    )
}

#[test]
fn the_decoder_follows_fragmented_calls_and_ephemeral_ports() {
    let order = Endian::Little;
    let body = ndr_request(order, &connect_request());
    let (a, b) = body.split_at(100);
    let rpc = Rpc::request(0, order);
    let mut d = Decoder::default();
    let first = rpc_frame(&fragment(rpc, 0, false, a), 50000, 34964);
    let last = rpc_frame(&fragment(rpc, 1, true, b), 50000, 34964);
    assert!(matches!(
        d.decode(LinkType::ETHERNET, &first),
        Ok(Pdu::Rpc { message: None, .. })
    ));
    let Ok(Pdu::Rpc {
        message: Some(Ok(m)),
        ..
    }) = d.decode(LinkType::ETHERNET, &last)
    else {
        panic!()
    };
    assert_eq!(m.blocks.len(), 5);

    // The answer between two ephemeral ports is recognised by the PNIO interface UUID.
    let res = Rpc::response(0, order).pdu(&ndr_response(order, [0; 4], &[]));
    let frame = rpc_frame(&res, 49152, 50000);
    assert!(matches!(
        d.decode(LinkType::ETHERNET, &frame),
        Ok(Pdu::Rpc {
            message: Some(Ok(_)),
            ..
        })
    ));
    // Other UDP traffic is not PROFINET.
    let dns = rpc_frame(b"not rpc", 53, 53);
    assert!(matches!(
        d.decode(LinkType::ETHERNET, &dns),
        Ok(Pdu::Other { .. })
    ));
    // A damaged PDU on the PNIO port is an error.
    let broken = rpc_frame(&[4, 0, 0], 50000, 34964);
    assert!(d.decode(LinkType::ETHERNET, &broken).is_err());
    // RT_CLASS_UDP.
    let rt_udp = rpc_frame(&cyclic(0xc001, &[1], 1, 0x35), 0x8892, 0x8892);
    assert!(matches!(
        d.decode(LinkType::ETHERNET, &rt_udp),
        Ok(Pdu::Rt { udp: true, .. })
    ));
}

#[test]
fn events_of_a_written_capture() {
    let mut w = PcapNgWriter::new(Vec::new()).unwrap();
    w.add_interface(LinkType::ETHERNET).unwrap();
    let dcp = pad60(ethernet(
        &[],
        0x8892,
        &Be::default().u16(0xfefe).u8(5).u8(0).u32(1).u16(1).u16(0).0,
    ));
    let order = Endian::Big;
    let connect = Rpc::request(0, order).pdu(&ndr_request(order, &connect_request()));
    let frames = [
        dcp,
        rpc_frame(&connect, 50000, 34964),
        ethernet(
            &[(0x8100, 0xc000)],
            0x8892,
            &cyclic(0x8001, &[0x80, 1, 2], 100, 0x35),
        ),
        ethernet(&[], 0x0806, &[0; 28]), // ARP: skipped
        ethernet(&[], 0x8892, &[0x80]),  // RT frame cut inside the FrameID
        rpc_frame(
            &Rpc {
                ptype: 1,
                ..Rpc::request(0, order)
            }
            .pdu(&[]),
            50000,
            34964,
        ),
    ];
    for (i, f) in frames.iter().enumerate() {
        w.write_packet(0, 1_000_000 + i as u64 * 1000, f).unwrap();
    }
    let bytes = w.into_inner().unwrap();
    let mut events = Events::new(CaptureReader::new(&bytes[..]).unwrap());
    let got: Vec<_> = (&mut events).map(Result::unwrap).collect();
    assert_eq!(got.len(), 5);
    assert!(matches!(
        got[0].kind,
        PnEventKind::Acyclic {
            class: FrameClass::DcpIdentifyRequest,
            ..
        }
    ));
    assert_eq!(got[0].record, 1);
    assert_eq!(got[0].time, Some(1_000_000));
    assert!(
        matches!(&got[1].kind, PnEventKind::Cm { message, .. } if message.operation == Operation::Connect)
    );
    let PnEventKind::Cyclic {
        frame_id,
        data,
        apdu,
    } = &got[2].kind
    else {
        panic!()
    };
    assert_eq!(
        (*frame_id, apdu.cycle_counter, &data[..3]),
        (FrameId(0x8001), 100, &[0x80, 1, 2][..])
    );
    assert_eq!(got[2].src, Some(MAC_A));
    assert!(matches!(got[3].kind, PnEventKind::Malformed { .. }));
    assert_eq!(got[3].record, 5);
    assert!(
        matches!(&got[4].kind, PnEventKind::RpcOther { header, .. } if header.ptype == PacketType::PING)
    );
    let c: Counts = events.counts();
    assert_eq!(
        (
            c.records,
            c.dcp,
            c.rt_cyclic,
            c.pnio_cm,
            c.cm_messages,
            c.other,
            c.errors
        ),
        (6, 1, 1, 2, 1, 1, 1)
    );
}

// ---------------------------------------------------------------- no panic

proptest! {
    #[test]
    fn frame_parsers_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..300)) {
        for link in [LinkType::ETHERNET, LinkType::LINUX_SLL, LinkType::LINUX_SLL2, LinkType::RAW] {
            let _ = parse_link(link, &bytes);
            let _ = Decoder::default().decode(link, &bytes);
        }
        let _ = parse_ipv4_udp(&bytes);
        if let Ok(f) = RtFrame::parse(&bytes) {
            let _ = f.cyclic().map(|c| c.c_sdu(bytes.len() / 2));
            let _ = f.dcp();
            let _ = f.alarm();
            let _ = f.fragment();
        }
        let _ = dcerpc::parse(&bytes);
        for order in [Endian::Big, Endian::Little] {
            let _ = pnio::decode_body(PacketType::REQUEST, 0, order, &bytes);
            let _ = pnio::decode_body(PacketType::RESPONSE, 2, order, &bytes);
        }
        let _ = pnio::decode_blocks(&bytes, 0);
    }

    #[test]
    fn mutated_pnio_bodies_never_panic(flips in proptest::collection::vec((any::<usize>(), any::<u8>()), 1..6)) {
        let mut body = ndr_request(Endian::Big, &connect_request());
        let n = body.len();
        for (at, v) in flips {
            body[at % n] = v;
        }
        let _ = pnio::decode_body(PacketType::REQUEST, 0, Endian::Big, &body);
        let mut frame = rpc_frame(&Rpc::request(0, Endian::Big).pdu(&body), 50000, 34964);
        let m = frame.len();
        frame[m / 2] ^= 0x55;
        let _ = Decoder::default().decode(LinkType::ETHERNET, &frame);
    }

    #[test]
    fn any_fragment_sequence_is_bounded(
        frags in proptest::collection::vec((0u16..8, any::<bool>(), 0u32..3, proptest::collection::vec(any::<u8>(), 0..40)), 0..40),
    ) {
        let limits = ReassemblyLimits { max_message: 100, max_fragments: 6, max_pending: 2 };
        let mut r = Reassembler::new(limits);
        for (n, last, seq, body) in frags {
            let pdu = fragment(Rpc { sequence: seq, ..Rpc::request(0, Endian::Little) }, n, last, &body);
            if let Ok(Some(m)) = r.push(&dcerpc::parse(&pdu).unwrap()) {
                prop_assert!(m.body.len() <= 100);
            }
            prop_assert!(r.pending() <= 2);
        }
    }
}
