//! PNIO-CM call bodies (IEC 61158-6-10 "RPC" and "Block coding"): the NDR header, then
//! blocks `BlockType | BlockLength | BlockVersionHigh | BlockVersionLow | body`, big-endian;
//! decoding is `drivespec_capture::pnio`. Encoders take the decoder's types, so
//! `decode(encode(x)) == x` up to the header fields the encoder computes (length, offset).

use crate::buf::{len16, Buf};
use drivespec_capture::dcerpc::Uuid;
use drivespec_capture::pnio::{
    block_type, AlarmCrBlockReq, AlarmCrBlockRes, ArBlockReq, ArBlockRes, ControlBlock,
    ControlKind, ExpectedSubmoduleBlockReq, IocrBlockReq, IocrBlockRes, ModuleDiff, PnioStatus,
    RecordRequest, RecordResponse,
};
use drivespec_capture::Endian;

/// BlockType of the I&M0 record (IEC 61158-6-10 "I&M0": 0x0020).
pub const IM0_BLOCK: u16 = 0x0020;

/// The four PNIOStatus bytes as one number (ErrorCode first).
pub fn status_u32(s: PnioStatus) -> u32 {
    u32::from_be_bytes([s.code, s.decode, s.code1, s.code2])
}

/// The NDR header and blocks of a request (IEC 61158-6-10 "IODConnectReq" …): ArgsMaximum,
/// ArgsLength and the conformant array header, in the RPC data representation `order`.
pub fn request(args_maximum: u32, blocks: &[u8], order: Endian) -> Vec<u8> {
    ndr(args_maximum, blocks, order)
}

/// The NDR header and blocks of a response (IEC 61158-6-10 "IODConnectRes" …): PNIOStatus,
/// ArgsLength and the conformant array header, in the RPC data representation `order`.
pub fn response(status: PnioStatus, blocks: &[u8], order: Endian) -> Vec<u8> {
    ndr(status_u32(status), blocks, order)
}

fn ndr(first: u32, blocks: &[u8], order: Endian) -> Vec<u8> {
    let n = u32::try_from(blocks.len()).unwrap_or(u32::MAX);
    let mut b = Buf::default();
    b.u32(first, order)
        .u32(n, order)
        .u32(n, order)
        .u32(0, order)
        .u32(n, order)
        .bytes(blocks);
    b.0
}

fn uuid(b: &mut Buf, u: Uuid) {
    b.bytes(&u.0);
}

/// A sequence of blocks being encoded (IEC 61158-6-10 "Block coding").
#[derive(Debug, Default, Clone)]
pub struct Blocks(Buf);

impl Blocks {
    /// No blocks yet.
    pub fn new() -> Blocks {
        Blocks::default()
    }

    /// The encoded blocks.
    pub fn into_bytes(self) -> Vec<u8> {
        self.0 .0
    }

    /// A block of `block_type`, version 1.0, with the body `body` writes; BlockLength is set
    /// from what it wrote.
    fn block(&mut self, block_type: u16, body: impl FnOnce(&mut Buf)) -> &mut Blocks {
        let start = self.0.len();
        self.0.be16(block_type).be16(0).u8(1).u8(0);
        body(&mut self.0);
        let len = len16(self.0.len() - start - 4);
        self.0.patch16(start + 2, len);
        self
    }

    /// Raw bytes after the last block (record data).
    pub fn raw(&mut self, data: &[u8]) -> &mut Blocks {
        self.0.bytes(data);
        self
    }

    /// ARBlockReq.
    pub fn ar_req(&mut self, a: &ArBlockReq) -> &mut Blocks {
        self.block(block_type::AR_REQ, |b| {
            b.be16(a.ar_type);
            uuid(b, a.ar_uuid);
            b.be16(a.session_key).bytes(&a.initiator_mac);
            uuid(b, a.initiator_object);
            b.be32(a.properties)
                .be16(a.activity_timeout_factor)
                .be16(a.udp_rt_port)
                .be16(len16(a.station_name.len()))
                .bytes(a.station_name.as_bytes());
        })
    }

    /// ARBlockRes.
    pub fn ar_res(&mut self, a: &ArBlockRes) -> &mut Blocks {
        self.block(block_type::AR_RES, |b| {
            b.be16(a.ar_type);
            uuid(b, a.ar_uuid);
            b.be16(a.session_key)
                .bytes(&a.responder_mac)
                .be16(a.udp_rt_port);
        })
    }

    /// IOCRBlockReq.
    pub fn iocr_req(&mut self, c: &IocrBlockReq) -> &mut Blocks {
        self.block(block_type::IOCR_REQ, |b| {
            b.be16(c.iocr_type)
                .be16(c.reference)
                .be16(c.lt)
                .be32(c.properties)
                .be16(c.data_length)
                .be16(c.frame_id.0)
                .be16(c.send_clock_factor)
                .be16(c.reduction_ratio)
                .be16(c.phase)
                .be16(c.sequence)
                .be32(c.frame_send_offset)
                .be16(c.watchdog_factor)
                .be16(c.data_hold_factor)
                .be16(c.tag_header)
                .bytes(&c.multicast_mac)
                .be16(len16(c.apis.len()));
            for api in &c.apis {
                b.be32(api.api).be16(len16(api.data_objects.len()));
                for o in &api.data_objects {
                    b.be16(o.slot).be16(o.subslot).be16(o.frame_offset);
                }
                b.be16(len16(api.iocs.len()));
                for o in &api.iocs {
                    b.be16(o.slot).be16(o.subslot).be16(o.frame_offset);
                }
            }
        })
    }

    /// IOCRBlockRes.
    pub fn iocr_res(&mut self, c: &IocrBlockRes) -> &mut Blocks {
        self.block(block_type::IOCR_RES, |b| {
            b.be16(c.iocr_type).be16(c.reference).be16(c.frame_id.0);
        })
    }

    /// AlarmCRBlockReq.
    pub fn alarm_cr_req(&mut self, a: &AlarmCrBlockReq) -> &mut Blocks {
        self.block(block_type::ALARM_CR_REQ, |b| {
            b.be16(a.alarm_cr_type)
                .be16(a.lt)
                .be32(a.properties)
                .be16(a.rta_timeout_factor)
                .be16(a.rta_retries)
                .be16(a.local_alarm_reference)
                .be16(a.max_alarm_data_length)
                .be16(a.tag_header_high)
                .be16(a.tag_header_low);
        })
    }

    /// AlarmCRBlockRes.
    pub fn alarm_cr_res(&mut self, a: &AlarmCrBlockRes) -> &mut Blocks {
        self.block(block_type::ALARM_CR_RES, |b| {
            b.be16(a.alarm_cr_type)
                .be16(a.local_alarm_reference)
                .be16(a.max_alarm_data_length);
        })
    }

    /// ExpectedSubmoduleBlockReq (one entry per module; the DataDescriptions follow the
    /// submodule type: one for none/input/output, input then output for both).
    pub fn expected(&mut self, e: &ExpectedSubmoduleBlockReq) -> &mut Blocks {
        self.block(block_type::EXPECTED_SUBMODULE_REQ, |b| {
            b.be16(len16(e.modules.len()));
            for m in &e.modules {
                b.be32(m.api)
                    .be16(m.slot)
                    .be32(m.ident)
                    .be16(m.properties)
                    .be16(len16(m.submodules.len()));
                for s in &m.submodules {
                    b.be16(s.subslot).be32(s.ident).be16(s.properties);
                    let descriptions = match s.properties & 0x3 {
                        1 => vec![(1, s.input)],
                        2 => vec![(2, s.output)],
                        3 => vec![(1, s.input), (2, s.output)],
                        _ => vec![(1, s.input)],
                    };
                    for (kind, d) in descriptions {
                        let d = d.unwrap_or(drivespec_capture::pnio::DataDescription {
                            data_length: 0,
                            iops_length: 1,
                            iocs_length: 1,
                        });
                        b.be16(kind)
                            .be16(d.data_length)
                            .u8(d.iops_length)
                            .u8(d.iocs_length);
                    }
                }
            }
        })
    }

    /// ModuleDiffBlock (one API entry per module, in order).
    pub fn module_diff(&mut self, d: &ModuleDiff) -> &mut Blocks {
        self.block(block_type::MODULE_DIFF, |b| {
            let mut apis: Vec<u32> = d.modules.iter().map(|m| m.api).collect();
            apis.dedup();
            b.be16(len16(apis.len()));
            for api in apis {
                let modules: Vec<_> = d.modules.iter().filter(|m| m.api == api).collect();
                b.be32(api).be16(len16(modules.len()));
                for m in modules {
                    b.be16(m.slot)
                        .be32(m.ident)
                        .be16(m.state)
                        .be16(len16(m.submodules.len()));
                    for s in &m.submodules {
                        b.be16(s.subslot).be32(s.ident).be16(s.state);
                    }
                }
            }
        })
    }

    fn record_header(b: &mut Buf, sequence: u16, ar: Uuid, api: u32, slot: u16, subslot: u16) {
        b.be16(sequence);
        uuid(b, ar);
        b.be32(api).be16(slot).be16(subslot).be16(0);
    }

    /// IODReadReqHeader (RecordDataLength: the most bytes wanted; TargetARUUID or zeros).
    pub fn read_req(&mut self, r: &RecordRequest) -> &mut Blocks {
        self.block(block_type::READ_REQ, |b| {
            Blocks::record_header(b, r.sequence, r.ar_uuid, r.api, r.slot, r.subslot);
            b.be16(r.index).be32(r.record_data_length);
            uuid(b, r.target_ar_uuid.unwrap_or_default());
            b.bytes(&[0; 8]);
        })
    }

    /// IODWriteReqHeader followed by the record data (RecordDataLength from the data).
    pub fn write_req(&mut self, r: &RecordRequest) -> &mut Blocks {
        let n = u32::try_from(r.data.len()).unwrap_or(u32::MAX);
        self.block(block_type::WRITE_REQ, |b| {
            Blocks::record_header(b, r.sequence, r.ar_uuid, r.api, r.slot, r.subslot);
            b.be16(r.index).be32(n).bytes(&[0; 24]);
        });
        self.raw(&r.data)
    }

    /// IODReadResHeader followed by the record data (RecordDataLength from the data).
    pub fn read_res(&mut self, r: &RecordResponse) -> &mut Blocks {
        let n = u32::try_from(r.data.len()).unwrap_or(u32::MAX);
        self.block(block_type::READ_RES, |b| {
            Blocks::record_header(b, r.sequence, r.ar_uuid, r.api, r.slot, r.subslot);
            b.be16(r.index)
                .be32(n)
                .be16(r.additional_value1)
                .be16(r.additional_value2)
                .bytes(&[0; 20]);
        });
        self.raw(&r.data)
    }

    /// IODWriteResHeader with its PNIOStatus.
    pub fn write_res(&mut self, r: &RecordResponse) -> &mut Blocks {
        self.block(block_type::WRITE_RES, |b| {
            Blocks::record_header(b, r.sequence, r.ar_uuid, r.api, r.slot, r.subslot);
            b.be16(r.index)
                .be32(r.record_data_length)
                .be16(r.additional_value1)
                .be16(r.additional_value2)
                .be32(status_u32(r.status.unwrap_or_default()))
                .bytes(&[0; 16]);
        })
    }

    /// A control block: IODControlReq/Res, IOXControlReq/Res, IODReleaseReq/Res.
    pub fn control(&mut self, c: &ControlBlock) -> &mut Blocks {
        let t = control_block_type(c.kind) | if c.response { 0x8000 } else { 0 };
        self.block(t, |b| {
            b.be16(0);
            uuid(b, c.ar_uuid);
            b.be16(c.session_key)
                .be16(0)
                .be16(c.command)
                .be16(c.properties);
        })
    }

    /// A block of any type with a raw body (version 1.0).
    pub fn other(&mut self, block_type: u16, body: &[u8]) -> &mut Blocks {
        self.block(block_type, |b| {
            b.bytes(body);
        })
    }
}

/// The request BlockType of a control block (IEC 61158-6-10 "BlockType" 0x0110–0x0118).
pub fn control_block_type(kind: ControlKind) -> u16 {
    match kind {
        ControlKind::PrmEnd => 0x0110,
        ControlKind::PlugPrmEnd => 0x0111,
        ControlKind::ApplicationReady => 0x0112,
        ControlKind::PlugApplicationReady => 0x0113,
        ControlKind::Release => 0x0114,
        ControlKind::ReadyForCompanion => 0x0116,
        ControlKind::ReadyForRtc3 => 0x0117,
        ControlKind::PrmBegin => 0x0118,
    }
}
