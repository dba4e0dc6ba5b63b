//! Every encoder's output reads back through the `drivespec-capture` decoders with the same
//! values (`decode(encode(x)) == x`), for hand-picked and generated inputs.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_capture::dcerpc::{self, flags1, DataRep, Header, PacketType, Uuid};
use drivespec_capture::ip::parse_ipv4_udp;
use drivespec_capture::link::{ethertype, parse_ethernet};
use drivespec_capture::pnio::{
    self, alarm_cr_req, alarm_cr_res, module_diff, AlarmCrBlockReq, AlarmCrBlockRes, ArBlockReq,
    ArBlockRes, Block, BlockHeader, ControlBlock, ControlKind, DataDescription, DiffModule,
    DiffSubmodule, ExpectedModule, ExpectedSubmodule, ExpectedSubmoduleBlockReq, FrameOffset,
    IocrApi, IocrBlockReq, IocrBlockRes, ModuleDiff, PnioStatus, RecordRequest, RecordResponse,
};
use drivespec_capture::rt::{FrameId, RtFrame};
use drivespec_capture::Endian;
use drivespec_profinet::cm::{self, Blocks};
use drivespec_profinet::dcp::{self, opt, DcpBlocks};
use drivespec_profinet::udp::Endpoints;
use drivespec_profinet::{eth, rpc, rt, udp, Identity};
use drivespec_spec::Spec;
use proptest::prelude::*;

fn hdr(t: u16) -> BlockHeader {
    BlockHeader {
        block_type: t,
        length: 0,
        version_high: 1,
        version_low: 0,
        offset: 0,
    }
}

/// Blocks with the header fields the encoder computes (length, offset) cleared.
fn normalised(mut blocks: Vec<Block>) -> Vec<Block> {
    for b in &mut blocks {
        let h = match b {
            Block::ArReq(x) => &mut x.header,
            Block::ArRes(x) => &mut x.header,
            Block::IocrReq(x) => &mut x.header,
            Block::IocrRes(x) => &mut x.header,
            Block::ExpectedSubmodules(x) => &mut x.header,
            Block::ReadReq(x) | Block::WriteReq(x) => &mut x.header,
            Block::ReadRes(x) | Block::WriteRes(x) => &mut x.header,
            Block::Control(x) => &mut x.header,
            Block::Unknown(x) => &mut x.header,
            _ => continue,
        };
        h.length = 0;
        h.offset = 0;
    }
    blocks
}

fn decode_request(order: Endian, blocks: &[u8]) -> Vec<Block> {
    let body = cm::request(4096, blocks, order);
    let m = pnio::decode_body(PacketType::REQUEST, 0, order, &body).unwrap();
    assert_eq!(m.ndr.args_maximum, Some(4096));
    assert_eq!(m.ndr.args_length as usize, blocks.len());
    normalised(m.blocks)
}

#[test]
fn ethernet_frames_are_padded_and_tagged() {
    let f = eth::frame(
        [1; 6],
        [2; 6],
        Some(0xC000),
        ethertype::PROFINET,
        &[0xAB; 4],
    );
    assert_eq!(f.len(), eth::MIN_FRAME);
    let l = parse_ethernet(&f).unwrap();
    assert_eq!((l.dst, l.src), (Some([1; 6]), Some([2; 6])));
    assert_eq!(l.ethertype, ethertype::PROFINET);
    assert_eq!(l.tags.as_slice()[0].pcp, 6);
    assert_eq!(&l.payload[..4], &[0xAB; 4]);
    let long = eth::frame([1; 6], [2; 6], None, ethertype::IPV4, &[7; 100]);
    assert_eq!(long.len(), 114);
}

#[test]
fn ipv4_udp_checksums_verify() {
    let ep = Endpoints {
        src: [192, 168, 0, 1],
        src_port: 49153,
        dst: [192, 168, 0, 2],
        dst_port: 34964,
    };
    let p = udp::ipv4_udp(ep, 7, b"hello");
    let d = parse_ipv4_udp(&p).unwrap();
    assert_eq!(
        (d.src, d.dst, d.src_port, d.dst_port),
        (ep.src, ep.dst, 49153, 34964)
    );
    assert_eq!(d.payload, b"hello");
    // The one's-complement sum over a header with its checksum is 0xFFFF.
    let sum: u32 = p[..20]
        .chunks(2)
        .map(|c| u32::from(u16::from_be_bytes([c[0], c[1]])))
        .sum();
    assert_eq!((sum & 0xFFFF) + (sum >> 16), 0xFFFF);
}

fn uuid() -> impl Strategy<Value = Uuid> {
    any::<[u8; 16]>().prop_map(Uuid)
}

prop_compose! {
    fn rpc_header()(
        little in any::<bool>(), ptype in 0u8..11, f1 in any::<u8>(), f2 in any::<u8>(),
        serial in any::<u16>(), object in uuid(), interface in uuid(), activity in uuid(),
        boot in any::<u32>(), iv in any::<u32>(), seq in any::<u32>(), opnum in any::<u16>(),
        ih in any::<u16>(), ah in any::<u16>(), frag in any::<u16>(), auth in any::<u8>(),
    ) -> Header {
        Header {
            version: 4, ptype: PacketType(ptype), flags1: f1, flags2: f2,
            drep: DataRep { integer: if little { Endian::Little } else { Endian::Big }, character: 0, float: 0 },
            serial, object, interface, activity, server_boot: boot, interface_version: iv,
            sequence: seq, opnum, interface_hint: ih, activity_hint: ah, body_len: 0,
            fragment: frag, auth_proto: auth,
        }
    }
}

proptest! {
    #[test]
    fn rpc_headers_round_trip(h in rpc_header(), body in proptest::collection::vec(any::<u8>(), 0..64)) {
        let bytes = rpc::encode(&h, &body);
        let p = dcerpc::parse(&bytes).unwrap();
        prop_assert_eq!(p.header, Header { body_len: body.len() as u16, ..h });
        prop_assert_eq!(p.body, &body[..]);
    }

    #[test]
    fn ar_and_iocr_blocks_round_trip(
        ar_uuid in uuid(), object in uuid(), key in any::<u16>(), mac in any::<[u8; 6]>(),
        props in any::<u32>(), name in "[a-z0-9-]{0,30}", scf in any::<u16>(), rr in any::<u16>(),
        dhf in any::<u16>(), len in any::<u16>(), fid in any::<u16>(),
        objects in proptest::collection::vec((any::<u16>(), any::<u16>(), any::<u16>()), 0..6),
        little in any::<bool>(),
    ) {
        let ar = ArBlockReq {
            header: hdr(pnio::block_type::AR_REQ), ar_type: 1, ar_uuid, session_key: key,
            initiator_mac: mac, initiator_object: object, properties: props,
            activity_timeout_factor: 100, udp_rt_port: 0x8892, station_name: name,
        };
        let fo = |v: &[(u16, u16, u16)]| v.iter().map(|&(slot, subslot, frame_offset)| FrameOffset { slot, subslot, frame_offset }).collect::<Vec<_>>();
        let iocr = IocrBlockReq {
            header: hdr(pnio::block_type::IOCR_REQ), iocr_type: 2, reference: 2, lt: 0x8892,
            properties: 1, data_length: len, frame_id: FrameId(fid), send_clock_factor: scf,
            reduction_ratio: rr, phase: 1, sequence: 0, frame_send_offset: 0xFFFF_FFFF,
            watchdog_factor: dhf, data_hold_factor: dhf, tag_header: 0xC000, multicast_mac: [0; 6],
            apis: vec![IocrApi { api: 0, data_objects: fo(&objects), iocs: fo(&objects) }],
        };
        let mut b = Blocks::new();
        b.ar_req(&ar).iocr_req(&iocr);
        let order = if little { Endian::Little } else { Endian::Big };
        let got = decode_request(order, &b.into_bytes());
        prop_assert_eq!(got, vec![Block::ArReq(ar), Block::IocrReq(iocr)]);
    }

    #[test]
    fn record_blocks_round_trip(
        ar in uuid(), seq in any::<u16>(), slot in any::<u16>(), subslot in any::<u16>(),
        index in any::<u16>(), data in proptest::collection::vec(any::<u8>(), 0..40),
        st in any::<[u8; 4]>(),
    ) {
        let req = RecordRequest {
            header: hdr(pnio::block_type::WRITE_REQ), sequence: seq, ar_uuid: ar, api: 0, slot,
            subslot, index, record_data_length: data.len() as u32, target_ar_uuid: None,
            data: data.clone(),
        };
        let read = RecordRequest {
            header: hdr(pnio::block_type::READ_REQ), record_data_length: 4096,
            target_ar_uuid: Some(Uuid::default()), data: Vec::new(), ..req.clone()
        };
        let mut b = Blocks::new();
        b.write_req(&req).read_req(&read);
        prop_assert_eq!(decode_request(Endian::Little, &b.into_bytes()), vec![Block::WriteReq(req), Block::ReadReq(read)]);
        let status = PnioStatus { code: st[0], decode: st[1], code1: st[2], code2: st[3] };
        let res = RecordResponse {
            header: hdr(pnio::block_type::READ_RES), sequence: seq, ar_uuid: ar, api: 0, slot,
            subslot, index, record_data_length: data.len() as u32, additional_value1: 0,
            additional_value2: 0, status: None, data: data.clone(),
        };
        let wres = RecordResponse {
            header: hdr(pnio::block_type::WRITE_RES), status: Some(status), data: Vec::new(), ..res.clone()
        };
        let mut b = Blocks::new();
        b.read_res(&res).write_res(&wres);
        let body = cm::response(status, &b.into_bytes(), Endian::Little);
        let m = pnio::decode_body(PacketType::RESPONSE, 2, Endian::Little, &body).unwrap();
        prop_assert_eq!(m.ndr.status, Some(status));
        prop_assert_eq!(normalised(m.blocks), vec![Block::ReadRes(res), Block::WriteRes(wres)]);
    }

    #[test]
    fn dcp_blocks_round_trip(
        name in "[a-z0-9.-]{0,40}", ip in any::<[u8; 4]>(), xid in any::<u32>(), info in any::<u16>(),
    ) {
        let mut b = DcpBlocks::new();
        b.with_info(opt::NAME_OF_STATION, info, name.as_bytes())
            .with_info(opt::IP_PARAMETER, 1, &dcp::ip_parameter(ip, [255, 255, 255, 0], [0; 4]))
            .plain(opt::CONTROL_RESPONSE, &[2, 2, 0]);
        let pdu = dcp::pdu(FrameId::DCP_IDENTIFY_RES, 5, 1, xid, 0, &b.into_bytes());
        let f = eth::frame([1; 6], [2; 6], None, ethertype::PROFINET, &pdu);
        let l = parse_ethernet(&f).unwrap();
        let h = RtFrame::parse(l.payload).unwrap().dcp().unwrap();
        prop_assert_eq!((h.service_id, h.service_type, h.xid), (5, 1, xid));
        let blocks: Vec<_> = h.iter_blocks().map(Result::unwrap).collect();
        prop_assert_eq!(blocks.len(), 3);
        prop_assert_eq!((blocks[0].option, blocks[0].suboption), opt::NAME_OF_STATION);
        prop_assert_eq!(&blocks[0].data[2..], name.as_bytes());
        prop_assert_eq!(&blocks[1].data[2..6], &ip[..]);
        prop_assert_eq!(blocks[2].data, &[2, 2, 0][..]);
    }

    #[test]
    fn cyclic_frames_round_trip(data in proptest::collection::vec(any::<u8>(), 0..100), counter in any::<u16>(), ds in any::<u8>(), fid in 0xC000u16..0xF800) {
        let pdu = rt::cyclic(FrameId(fid), &data, counter, ds);
        let f = eth::frame([1; 6], [2; 6], None, ethertype::PROFINET, &pdu);
        let l = parse_ethernet(&f).unwrap();
        let c = RtFrame::parse(l.payload).unwrap().cyclic().unwrap();
        prop_assert_eq!(c.frame_id, FrameId(fid));
        prop_assert_eq!(c.apdu.cycle_counter, counter);
        prop_assert_eq!(c.apdu.data_status.0, ds);
        prop_assert_eq!(&c.data[..data.len()], &data[..]);
        prop_assert_eq!(c.data.len(), data.len().max(rt::MIN_C_SDU));
    }
}

#[test]
fn connect_blocks_round_trip() {
    let id = Identity::from_spec(&Spec::builtin().unwrap()).unwrap();
    let expected = id.expected_submodules();
    let alarm = AlarmCrBlockReq {
        alarm_cr_type: 1,
        lt: 0x8892,
        properties: 0,
        rta_timeout_factor: 1,
        rta_retries: 3,
        local_alarm_reference: 3,
        max_alarm_data_length: 200,
        tag_header_high: 0xC000,
        tag_header_low: 0xA000,
    };
    let mut b = Blocks::new();
    b.alarm_cr_req(&alarm).expected(&expected);
    let got = decode_request(Endian::Little, &b.into_bytes());
    let Block::Unknown(u) = &got[0] else { panic!() };
    assert_eq!(alarm_cr_req(u).unwrap().unwrap(), alarm);
    assert_eq!(got[1], Block::ExpectedSubmodules(expected.clone()));
    let Block::ExpectedSubmodules(e) = &got[1] else {
        panic!()
    };
    let out = e.modules.iter().find(|m| m.slot == id.output.slot).unwrap();
    assert_eq!(out.submodules[0].output.unwrap().data_length, 14);
    let inp = e.modules.iter().find(|m| m.slot == id.input.slot).unwrap();
    assert_eq!(inp.submodules[0].input.unwrap().data_length, 16);

    let diff = ModuleDiff {
        modules: vec![DiffModule {
            api: 0,
            slot: 1,
            ident: 0x101,
            state: 1,
            submodules: vec![DiffSubmodule {
                subslot: 1,
                ident: 1,
                state: 0x9000,
            }],
        }],
    };
    let res_alarm = AlarmCrBlockRes {
        alarm_cr_type: 1,
        local_alarm_reference: 1,
        max_alarm_data_length: 200,
    };
    let ar_res = ArBlockRes {
        header: hdr(pnio::block_type::AR_RES),
        ar_type: 1,
        ar_uuid: Uuid([9; 16]),
        session_key: 1,
        responder_mac: [3; 6],
        udp_rt_port: 0x8892,
    };
    let iocr_res = IocrBlockRes {
        header: hdr(pnio::block_type::IOCR_RES),
        iocr_type: 2,
        reference: 2,
        frame_id: FrameId(0xC100),
    };
    let mut b = Blocks::new();
    b.ar_res(&ar_res)
        .iocr_res(&iocr_res)
        .alarm_cr_res(&res_alarm)
        .module_diff(&diff);
    let body = cm::response(PnioStatus::default(), &b.into_bytes(), Endian::Big);
    let m = pnio::decode_body(PacketType::RESPONSE, 0, Endian::Big, &body).unwrap();
    let blocks = normalised(m.blocks);
    assert_eq!(blocks[0], Block::ArRes(ar_res));
    assert_eq!(blocks[1], Block::IocrRes(iocr_res));
    let Block::Unknown(a) = &blocks[2] else {
        panic!()
    };
    assert_eq!(alarm_cr_res(a).unwrap().unwrap(), res_alarm);
    let Block::Unknown(d) = &blocks[3] else {
        panic!()
    };
    assert_eq!(module_diff(d).unwrap().unwrap(), diff);
}

#[test]
fn control_blocks_round_trip() {
    for (kind, response) in [
        (ControlKind::PrmEnd, false),
        (ControlKind::PrmEnd, true),
        (ControlKind::ApplicationReady, false),
        (ControlKind::Release, true),
    ] {
        let c = ControlBlock {
            header: hdr(cm::control_block_type(kind) | if response { 0x8000 } else { 0 }),
            kind,
            response,
            ar_uuid: Uuid([5; 16]),
            session_key: 7,
            command: 8,
            properties: 0,
        };
        let mut b = Blocks::new();
        b.control(&c);
        assert_eq!(
            decode_request(Endian::Little, &b.into_bytes()),
            vec![Block::Control(c)]
        );
    }
}

#[test]
fn alarm_frames_round_trip() {
    let st = PnioStatus {
        code: 0xCF,
        decode: 0x81,
        code1: 0xFD,
        code2: 0x05,
    };
    let pdu = rt::abort(3, 1, st);
    let a = RtFrame::parse(&pdu).unwrap().alarm().unwrap();
    assert_eq!(
        (a.dst_endpoint, a.src_endpoint, a.pdu_type),
        (3, 1, rt::pdu_type::ERR)
    );
    assert_eq!(a.var_part, &[0xCF, 0x81, 0xFD, 0x05]);
}

#[test]
fn response_headers_answer_their_request() {
    let req = rpc::request_header(Uuid([1; 16]), Uuid::PNIO_DEVICE, Uuid([2; 16]), 5, 2);
    let res = rpc::response_header(&req, 9);
    assert_eq!(res.ptype, PacketType::RESPONSE);
    assert_eq!(
        (res.activity, res.sequence, res.opnum),
        (req.activity, 5, 2)
    );
    assert_eq!(res.flags1, flags1::LAST_FRAG | flags1::NO_FACK);
}

#[test]
fn the_i_and_m0_record_has_its_fixed_layout() {
    let id = Identity::from_spec(&Spec::builtin().unwrap()).unwrap();
    let r = id.im0_record("PSD426", "12345");
    assert_eq!(r.len(), 60);
    assert_eq!(&r[..6], &[0x00, 0x20, 0x00, 0x38, 1, 0]);
    assert_eq!(u16::from_be_bytes([r[6], r[7]]), id.vendor_id);
    assert_eq!(&r[8..28], b"PSD426              ");
    assert_eq!(&r[28..44], b"12345           ");
    assert_eq!(r[46], b'V');
    // The object UUID ends in instance, DeviceID, VendorID.
    let u = id.object_uuid();
    assert_eq!(&u.0[10..], &[0, 1, 0x04, 0x26, 0x01, 0x30]);
}

#[test]
fn station_names_follow_the_naming_rules() {
    assert!(dcp::valid_station_name(b"psd-01"));
    assert!(dcp::valid_station_name(b"line-4.axis-x"));
    for bad in [
        &b""[..],
        b"-a",
        b"a-",
        b"A",
        b"1.2.3.4",
        b"port-001",
        b"a..b",
    ] {
        assert!(
            !dcp::valid_station_name(bad),
            "{:?}",
            String::from_utf8_lossy(bad)
        );
    }
}

#[test]
fn expected_modules_hold_no_other_descriptions() {
    // A submodule with input and output data carries two DataDescriptions.
    let both = ExpectedSubmoduleBlockReq {
        header: hdr(pnio::block_type::EXPECTED_SUBMODULE_REQ),
        modules: vec![ExpectedModule {
            api: 0,
            slot: 3,
            ident: 0x42,
            properties: 0,
            submodules: vec![ExpectedSubmodule {
                subslot: 1,
                ident: 7,
                properties: 3,
                input: Some(DataDescription {
                    data_length: 4,
                    iops_length: 1,
                    iocs_length: 1,
                }),
                output: Some(DataDescription {
                    data_length: 2,
                    iops_length: 1,
                    iocs_length: 1,
                }),
            }],
        }],
    };
    let mut b = Blocks::new();
    b.expected(&both);
    assert_eq!(
        decode_request(Endian::Big, &b.into_bytes()),
        vec![Block::ExpectedSubmodules(both)]
    );
}
